//! The search windows whose edge the direction test ([`edge_runs_along`](super::edge_runs_along))
//! refused earlier in the current frame. A refusal holds for the rest of the frame, so the
//! set of edges a frame's iterations see only shrinks: an edge cannot come and go from one
//! iteration to the next, and a frame converges as it does with the test off.

/// Bit `2k` is slice `k`'s window on side +1, bit `2k + 1` its window on side −1, and bit
/// [`RefusedWindows::TIP`] the window beyond the tip, of one link or palm hull edge.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RefusedWindows(u64);

impl RefusedWindows {
    /// No window refused: a new frame.
    pub const NONE: RefusedWindows = RefusedWindows(0);
    /// The bit of the window beyond a fingertip (slices use bits 0..32).
    pub const TIP: u32 = 2 * crate::config::MAX_SLICES_PER_LINK as u32;

    /// The bit of slice `k`'s window on `side` (+1 or −1).
    pub fn slice(k: usize, side: i8) -> u32 {
        2 * k as u32 + u32::from(side < 0)
    }

    /// Whether window `bit` was refused this frame.
    pub fn contains(&self, bit: u32) -> bool {
        bit < 64 && self.0 & (1 << bit) != 0
    }

    /// Records that window `bit` was refused (bits ≥ 64 are ignored).
    pub fn insert(&mut self, bit: u32) {
        if bit < 64 {
            self.0 |= 1 << bit;
        }
    }

    /// How many windows were refused.
    pub fn count(&self) -> u32 {
        self.0.count_ones()
    }
}

#[cfg(test)]
mod tests {
    use super::RefusedWindows;
    use crate::config::MAX_SLICES_PER_LINK;

    #[test]
    fn every_window_has_its_own_bit() {
        let mut bits: [u32; 2 * MAX_SLICES_PER_LINK + 1] = [0; 2 * MAX_SLICES_PER_LINK + 1];
        for k in 0..MAX_SLICES_PER_LINK {
            bits[2 * k] = RefusedWindows::slice(k, 1);
            bits[2 * k + 1] = RefusedWindows::slice(k, -1);
        }
        bits[2 * MAX_SLICES_PER_LINK] = RefusedWindows::TIP;
        let mut set = RefusedWindows::NONE;
        for (n, bit) in bits.iter().enumerate() {
            assert!(!set.contains(*bit), "bit {bit} given twice");
            set.insert(*bit);
            assert!(set.contains(*bit));
            assert_eq!(set.count() as usize, n + 1);
        }
    }

    #[test]
    fn bits_beyond_the_set_are_ignored() {
        let mut set = RefusedWindows::NONE;
        for bit in [64, u32::MAX] {
            set.insert(bit);
            assert!(!set.contains(bit));
        }
        assert_eq!(set, RefusedWindows::NONE);
    }
}
