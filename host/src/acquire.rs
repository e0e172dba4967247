//! The host's tracker that finds the hand itself: [`digiteyes_core::auto_tracker`] with its
//! edge-map buffers owned here (a board keeps them in static memory instead).

use anyhow::{anyhow, Result};
use digiteyes_core::acquire::{AcceptConfig, AcquireConfig, FinderConfig};
use digiteyes_core::auto_tracker::AutoTracker as CoreAutoTracker;
pub use digiteyes_core::auto_tracker::{
    AutoReport, Recovery, Status, FALLBACK_DEPTH_MM, LOCAL_REFINE_PASSES, LOCAL_SEARCH_FRAMES,
    LOCAL_WINDOW, LOST_FRAMES_BEFORE_SEARCH,
};
use digiteyes_core::camera::Camera;
use digiteyes_core::estimator::FreeMask;
use digiteyes_core::frame::FrameView;
use digiteyes_core::hypotheses::HypothesesConfig;
use digiteyes_core::model::Model;
use digiteyes_core::tracker::{Tracker, TrackerConfig};
use digiteyes_core::watch::WatchConfig;

/// A tracker that finds the hand, tracks it, and finds it again, with its buffers.
pub struct AutoTracker {
    inner: CoreAutoTracker,
    edge_buffers: Vec<Vec<u8>>,
}

impl AutoTracker {
    /// A tracker for `model` seen by `cameras`, starting by searching: the states in `free`
    /// are searched for, the others kept at `base`.
    pub fn new(
        model: Model,
        cameras: &[Camera],
        base: &[f32],
        free: FreeMask,
        config: TrackerConfig,
        acquire: AcquireConfig,
    ) -> Result<Self> {
        let inner = CoreAutoTracker::new(model, cameras, base, free, config, acquire)
            .map_err(|e| anyhow!("cannot start the tracker: {e}"))?;
        Ok(Self::with_buffers(inner, cameras, &acquire))
    }

    /// A tracker for `model` seen by `cameras` that starts by tracking from `initial` (the
    /// state of the first frame), and searches only once the hand is lost.
    pub fn tracking(
        model: Model,
        cameras: &[Camera],
        initial: &[f32],
        free: FreeMask,
        config: TrackerConfig,
        acquire: AcquireConfig,
    ) -> Result<Self> {
        let inner = CoreAutoTracker::tracking(model, cameras, initial, free, config, acquire)
            .map_err(|e| anyhow!("cannot start the tracker: {e}"))?;
        Ok(Self::with_buffers(inner, cameras, &acquire))
    }

    fn with_buffers(inner: CoreAutoTracker, cameras: &[Camera], acquire: &AcquireConfig) -> Self {
        let edge_buffers = cameras
            .iter()
            .map(|c| vec![0u8; CoreAutoTracker::edge_bytes_needed(c, acquire)])
            .collect();
        AutoTracker {
            inner,
            edge_buffers,
        }
    }

    /// Sets what happens once the hand is lost for [`LOST_FRAMES_BEFORE_SEARCH`] frames.
    pub fn set_recovery(&mut self, recovery: Recovery) {
        self.inner.set_recovery(recovery);
    }

    /// Sets the thresholds a refined leaf needs to be accepted.
    pub fn set_accept(&mut self, accept: AcceptConfig) {
        self.inner.set_accept(accept);
    }

    /// Sets how the search's leaves (and the local re-acquisition's starts) are refined and
    /// judged, the acceptance included.
    pub fn set_finder(&mut self, config: FinderConfig) {
        self.inner.set_finder(config);
    }

    /// Sets how the image checks the track (`every_frames` 0: never).
    pub fn set_watch(&mut self, config: WatchConfig) {
        self.inner.set_watch(config);
    }

    /// Sets how many hypotheses are tracked (one: the single tracker, bit for bit).
    pub fn set_hypotheses(&mut self, config: HypothesesConfig) {
        self.inner.set_hypotheses(config);
    }

    /// The current state (the last tracked one, or the base while searching).
    pub fn state(&self) -> &[f32] {
        self.inner.state()
    }

    /// The status after the last frame.
    pub fn status(&self) -> Status {
        self.inner.status()
    }

    /// The tracker (its model, cameras, free states).
    pub fn tracker(&self) -> &Tracker {
        self.inner.tracker()
    }

    /// The core status machine.
    pub fn inner(&self) -> &CoreAutoTracker {
        &self.inner
    }

    /// One instant: `frames[i]` is camera `i`'s.
    pub fn step(&mut self, frames: &[FrameView<'_>]) -> Result<AutoReport> {
        let mut buffers: Vec<&mut [u8]> = self
            .edge_buffers
            .iter_mut()
            .map(|b| b.as_mut_slice())
            .collect();
        self.inner
            .step(frames, &mut buffers)
            .map_err(|e| anyhow!("frame not usable: {e}"))
    }
}
