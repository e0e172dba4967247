//! Line noise for robustness tests: bit flips in a fraction of the bytes, in both directions,
//! during a window.

use std::ops::Range;
use std::time::Duration;

/// When the line is noisy.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Window {
    /// All the time.
    Always,
    /// While frames with these numbers are uploaded: inbound, the bytes of `FrameChunk`s of
    /// these frames (and any other message sent meanwhile); outbound, every byte the board
    /// sends while the last frame it received is one of these.
    Frames(Range<u32>),
    /// For these bytes of each direction, counted from 0 since the simulator started.
    Bytes(Range<u64>),
    /// For this span of time since the simulator started.
    Time(Range<Duration>),
}

/// Flip one random bit in a fraction `rate` of the bytes crossing the line during `window`.
#[derive(Debug, Clone, PartialEq)]
pub struct Corruption {
    /// Fraction of the bytes hit (0–1), in each direction.
    pub rate: f64,
    /// When.
    pub window: Window,
    /// Seed of the noise, so a failing run can be repeated.
    pub seed: u64,
}

impl Corruption {
    /// `rate` of the bytes, all the time, seed 1.
    pub fn always(rate: f64) -> Self {
        Corruption {
            rate,
            window: Window::Always,
            seed: 1,
        }
    }
}

/// Where on the line a byte is, for deciding whether the window is open.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Position {
    /// The byte's index in its direction.
    pub byte: u64,
    /// The frame the window test should use (see [`Window::Frames`]).
    pub frame: Option<u32>,
    /// Time since the simulator started.
    pub elapsed: Duration,
}

impl Window {
    pub(crate) fn contains(&self, at: Position) -> bool {
        match self {
            Window::Always => true,
            Window::Frames(frames) => at.frame.is_some_and(|f| frames.contains(&f)),
            Window::Bytes(bytes) => bytes.contains(&at.byte),
            Window::Time(span) => span.contains(&at.elapsed),
        }
    }
}

/// The noise source: SplitMix64, so runs repeat exactly from a seed.
#[derive(Debug, Clone)]
pub(crate) struct Noise {
    state: u64,
    threshold: u64,
}

impl Noise {
    pub(crate) fn new(seed: u64, rate: f64) -> Self {
        let rate = if rate.is_finite() {
            rate.clamp(0.0, 1.0)
        } else {
            0.0
        };
        // rate 1.0 saturates to u64::MAX: every byte but one in 2^64.
        let threshold = (rate * u64::MAX as f64) as u64;
        Noise {
            state: seed,
            threshold,
        }
    }

    fn next(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Flips one bit of `byte` with the configured probability; says whether it did.
    pub(crate) fn hit(&mut self, byte: &mut u8) -> bool {
        let draw = self.next();
        if draw >= self.threshold {
            return false;
        }
        *byte ^= 1 << (self.next() % 8);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rate_is_the_fraction_of_bytes_hit() {
        let mut noise = Noise::new(7, 0.01);
        let mut hits = 0;
        for _ in 0..200_000 {
            let mut b = 0u8;
            if noise.hit(&mut b) {
                assert_eq!(b.count_ones(), 1, "one bit flipped");
                hits += 1;
            }
        }
        assert!((1800..2200).contains(&hits), "{hits} of 200000 at 1%");
        let mut never = Noise::new(7, 0.0);
        assert!((0..10_000).all(|_| !never.hit(&mut 0)));
    }

    #[test]
    fn windows() {
        let at = |byte, frame, ms| Position {
            byte,
            frame,
            elapsed: Duration::from_millis(ms),
        };
        assert!(Window::Frames(3..5).contains(at(0, Some(4), 0)));
        assert!(!Window::Frames(3..5).contains(at(0, Some(5), 0)));
        assert!(!Window::Frames(3..5).contains(at(0, None, 0)));
        assert!(Window::Bytes(10..20).contains(at(10, None, 0)));
        assert!(!Window::Bytes(10..20).contains(at(20, None, 0)));
        let span = Duration::from_millis(100)..Duration::from_millis(200);
        assert!(Window::Time(span.clone()).contains(at(0, None, 150)));
        assert!(!Window::Time(span).contains(at(0, None, 250)));
    }
}
