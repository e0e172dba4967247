//! The score a hypothesis is ranked by: this frame's likelihood, or its running mean over
//! the frames it was scored on ([`HypothesesConfig::score_memory`](super::HypothesesConfig)).

/// The ranked score after a frame scoring `score`: `memory × past + (1 − memory) × score`
/// with `memory` clamped to 0..=1, or `score` alone for a hypothesis not scored before
/// (`past` is `None`) or without memory (0, or not a number).
pub(crate) fn ranked_score(past: Option<f32>, score: f32, memory: f32) -> f32 {
    let memory = memory.clamp(0.0, 1.0);
    match past {
        Some(past) if memory > 0.0 => memory * past + (1.0 - memory) * score,
        _ => score,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_memory_or_past_the_frame_decides() {
        assert_eq!(ranked_score(Some(0.5), 0.9, 0.0), 0.9);
        assert_eq!(ranked_score(None, 0.9, 0.6), 0.9);
        assert_eq!(ranked_score(Some(0.5), 0.9, f32::NAN), 0.9);
        assert_eq!(ranked_score(Some(0.5), 0.9, -1.0), 0.9);
        assert_eq!(ranked_score(Some(0.5), 0.9, 2.0), 0.5);
        assert!((ranked_score(Some(0.5), 1.0, 0.6) - 0.7).abs() < 1e-6);
    }

    /// Seed 1731 of the stereo sweep, the confirm phase after its acquisition: the right
    /// reading (5.8 px) and a wrong one (12.9 px) as the likelihood scored them frame by
    /// frame. On the last frame the wrong one scores more; over the five, the right one.
    #[test]
    fn a_reading_better_over_several_frames_outranks_one_frames_noise() {
        let right = [0.970f32, 0.970, 0.967, 0.967, 0.960];
        let wrong = [0.964f32, 0.965, 0.960, 0.966, 0.965];
        let run = |scores: &[f32], memory: f32| {
            scores
                .iter()
                .fold(None, |past, &s| Some(ranked_score(past, s, memory)))
                .unwrap_or(0.0)
        };
        assert!(run(&right, 0.0) < run(&wrong, 0.0));
        assert!(run(&right, 0.6) > run(&wrong, 0.6));
    }
}
