//! How deep the stack has been: cortex-m-rt's `paint-stack` feature (on in `Cargo.toml`) fills
//! the RAM between the end of `.bss` (`_stack_end`) and the top of the stack (`_stack_start`)
//! with [`PAINT`] before `main`; every word the stack has used since holds something else.
//! [`high_water`] finds the lowest word that lost its paint; [`take_high_water`] also paints
//! the used part again, so the next call measures only what ran in between (e.g. one frame).
//!
//! A word that happens to be written with `0xCCCC_CCCC` itself would look unused, so the mark
//! can read a few words low, never more than the deepest such run at the very bottom of the
//! used stack. Good enough for a budget; not a guard (the Cortex-M7 has no stack limit
//! register, and nothing lies below the stack here but unused RAM down to `.bss`).

use core::ptr;

/// Words just below the stack pointer that [`take_high_water`] leaves alone.
const REPAINT_MARGIN: usize = 64;

/// The value cortex-m-rt paints the stack with (`cortex_m_rt::STACK_PAINT_VALUE`).
pub const PAINT: u32 = cortex_m_rt::STACK_PAINT_VALUE;

extern "C" {
    // Linker symbols of cortex-m-rt's `link.x`: only their addresses mean anything.
    static _stack_start: u32;
    static _stack_end: u32;
}

/// The stack's region: (lowest address, one past the highest), i.e. (`_stack_end`,
/// `_stack_start`).
fn region() -> (usize, usize) {
    (
        ptr::addr_of!(_stack_end) as usize,
        ptr::addr_of!(_stack_start) as usize,
    )
}

/// Bytes the stack may grow to: from its top down to the end of `.bss`.
pub fn capacity() -> usize {
    let (bottom, top) = region();
    top - bottom
}

/// The most stack ever used since reset, in bytes: from the top of the stack down to the
/// lowest word no longer holding [`PAINT`]. Scans up from the bottom of the region, so it
/// takes one load per unused word (a few ms for the ~3.4 MB of this board): call it between
/// frames, not in a loop.
pub fn high_water() -> usize {
    let (_, top) = region();
    top - lowest_used()
}

/// [`high_water`], then paints the stack below the current stack pointer again, so the next
/// call reports the most used since this one. Its report includes what the caller itself
/// holds on the stack (the frames between `main` and here).
pub fn take_high_water() -> usize {
    let (_, top) = region();
    let lowest = lowest_used();
    let sp = cortex_m::register::msp::read() as usize;
    let end = sp.saturating_sub(REPAINT_MARGIN) & !3;
    let mut addr = lowest;
    while addr < end {
        #[allow(unsafe_code)]
        // SAFETY: `addr` is 4-byte aligned and lies between the lowest word the stack has
        // used and 64 bytes below the current stack pointer (thread mode runs on MSP): RAM
        // that no live frame occupies (the AAPCS has no red zone below SP). An exception
        // taken meanwhile pushes its frame there, but it runs to completion before this loop
        // continues, so nothing live is ever overwritten.
        unsafe {
            ptr::write_volatile(addr as *mut u32, PAINT)
        };
        addr += 4;
    }
    top - lowest
}

/// The lowest address in the stack's region whose word has lost its paint (the region's top
/// if none has).
fn lowest_used() -> usize {
    let (bottom, top) = region();
    let mut addr = bottom;
    while addr < top {
        #[allow(unsafe_code)]
        // SAFETY: `addr` is 4-byte aligned (cortex-m-rt aligns `_stack_end`) and lies in the
        // stack's region of RAM, mapped and readable. Below the stack pointer nothing is live,
        // and above it the words belong to frames of this very thread (or to an interrupt
        // handler that preempted it and is finished), so no Rust reference is writing them
        // while this volatile load reads one.
        let word = unsafe { ptr::read_volatile(addr as *const u32) };
        if word != PAINT {
            break;
        }
        addr += 4;
    }
    addr
}
