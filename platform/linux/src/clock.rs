//! The board clock: the monotonic system clock in microseconds.

use std::time::Instant;

use digiteyes_firmware::Clock;

/// Microseconds since the board started (`Instant`, monotonic), at 1 MHz.
#[derive(Debug, Clone, Copy)]
pub struct MonotonicClock {
    start: Instant,
}

impl MonotonicClock {
    /// Ticks per second.
    pub const HZ: u32 = 1_000_000;

    /// A clock that reads 0 now.
    pub fn new() -> Self {
        MonotonicClock {
            start: Instant::now(),
        }
    }
}

impl Default for MonotonicClock {
    fn default() -> Self {
        Self::new()
    }
}

impl Clock for MonotonicClock {
    fn ticks(&mut self) -> u64 {
        u64::try_from(self.start.elapsed().as_micros()).unwrap_or(u64::MAX)
    }

    fn hz(&self) -> u32 {
        Self::HZ
    }
}
