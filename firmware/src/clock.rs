//! The board's monotonic clock.

/// A monotonic counter of board clock ticks, for timestamps and work measurements.
pub trait Clock {
    /// Ticks since an arbitrary start; never decreases.
    fn ticks(&mut self) -> u64;
    /// Ticks per second.
    fn hz(&self) -> u32;
}
