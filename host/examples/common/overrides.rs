//! Tracker settings a probe can override from its command line, each defaulting to the
//! tracker's own: one `#[command(flatten)]` for every example that costs or measures them.

use digiteyes_core::tracker::TrackerConfig;

#[derive(clap::Args, Debug, Clone, Copy, Default)]
pub struct TrackerOverrides {
    /// The slice search's window in a frame's first iteration (px; default: the tracker's):
    /// to scan seeds under another window before it is the default.
    #[arg(long)]
    pub window_px: Option<u8>,
    /// The slice search's outermost-edge share (0: the strongest edge; default: the
    /// tracker's).
    #[arg(long)]
    pub outermost_share: Option<f32>,
    /// Whether the tip search also runs beyond knuckles where the outline ends (default: the
    /// tracker's).
    #[arg(long)]
    pub knuckle_tips: Option<bool>,
    /// The weight of the region rows (0: none; default: the tracker's).
    #[arg(long)]
    pub fill_weight: Option<f32>,
    /// The region rows' class margin (share of the contrast; default: the tracker's).
    #[arg(long)]
    pub fill_margin: Option<f32>,
    /// The region rows' full-weight length in widths (0: every link at full weight;
    /// default: the tracker's).
    #[arg(long)]
    pub fill_full_length: Option<f32>,
    /// Whether each step holds the joints it would carry out of their ranges at their bounds
    /// (default: the tracker's).
    #[arg(long)]
    pub bounded_step: Option<bool>,
    /// The prior toward the predicted state: its translation weight (per mm², against px²
    /// residuals; default: the tracker's).
    #[arg(long)]
    pub prior_translation: Option<f32>,
    /// The same prior's joint weight (per rad²; default: the tracker's).
    #[arg(long)]
    pub prior_joint: Option<f32>,
}

impl TrackerOverrides {
    /// `config` with every setting given here in place of its own.
    pub fn apply(&self, config: &mut TrackerConfig) {
        let (features, fill) = (&mut config.features, &mut config.fill);
        features.window_px = self.window_px.unwrap_or(features.window_px);
        features.outermost_share = self.outermost_share.unwrap_or(features.outermost_share);
        features.knuckle_tips = self.knuckle_tips.unwrap_or(features.knuckle_tips);
        fill.weight = self.fill_weight.unwrap_or(fill.weight);
        fill.class_margin = self.fill_margin.unwrap_or(fill.class_margin);
        fill.full_length_widths = self.fill_full_length.unwrap_or(fill.full_length_widths);
        let estimator = &mut config.estimator;
        estimator.bounded_step = self.bounded_step.unwrap_or(estimator.bounded_step);
        let prior = &mut config.motion.prior;
        prior.translation = self.prior_translation.unwrap_or(prior.translation);
        prior.joint = self.prior_joint.unwrap_or(prior.joint);
    }
}
