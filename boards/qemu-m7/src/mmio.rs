//! The one place that touches device registers: a 32-bit memory-mapped register at a fixed
//! address of this board.

use core::ptr;

/// A 32-bit device register at a fixed address of the mps2-an500 memory map.
///
/// Only this crate makes them, and only at the addresses of devices QEMU's mps2-an500 maps
/// (QEMU's `info mtree`), which is what makes the volatile accesses below sound.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Reg {
    addr: usize,
}

impl Reg {
    /// The register at `addr`, which must be a 4-byte-aligned register of a device mapped on
    /// this board (callers pass the constants of `uart` and `led`).
    pub(crate) const fn at(addr: usize) -> Self {
        Self { addr }
    }

    /// Reads the register (one 32-bit load, never merged, split or elided).
    #[inline(always)]
    pub(crate) fn read(self) -> u32 {
        #[allow(unsafe_code)]
        // SAFETY: `addr` is an aligned 32-bit register of a device mapped on this board (see
        // `Reg::at`); device registers are not Rust-managed memory, so no reference aliases
        // them, and a volatile read is how MMIO is accessed.
        unsafe {
            ptr::read_volatile(self.addr as *const u32)
        }
    }

    /// Writes the register (one 32-bit store, never merged, split or elided).
    #[inline(always)]
    pub(crate) fn write(self, value: u32) {
        #[allow(unsafe_code)]
        // SAFETY: as in `read`: an aligned, mapped device register that no Rust reference
        // points at; the store's only effect is the device's.
        unsafe {
            ptr::write_volatile(self.addr as *mut u32, value)
        }
    }
}
