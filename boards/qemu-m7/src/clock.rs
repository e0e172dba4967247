//! A monotonic 64-bit tick counter from SysTick, and a busy-wait [`Delay`] on it.
//!
//! SysTick runs from the core clock (`CLKSOURCE` = processor clock), which QEMU's mps2-an500
//! gives 25 MHz ([`TICK_HZ`]); its other source, the reference clock, is 1 MHz on this board
//! and is not used. SysTick counts down 24 bits from [`RELOAD`]; every time it reaches zero
//! the `SysTick` exception adds one to a wrap counter, and [`now_ticks`] joins the two.
//!
//! Under QEMU's `-icount shift=0` (one instruction per nanosecond of virtual time) one tick is
//! exactly [`INSTRUCTIONS_PER_TICK_ICOUNT0`] = 40 instructions, independent of the host's load;
//! without `-icount` ticks follow the host's clock at 25 MHz.
//!
//! Interrupts must not stay masked for a whole wrap period (2^24 ticks, 0.67 s): a second wrap
//! while the first is still pending would be lost.

use core::sync::atomic::{compiler_fence, AtomicBool, AtomicU32, Ordering};

use cortex_m::peripheral::{syst::SystClkSource, SCB, SYST};
use cortex_m_rt::exception;
use embedded_hal::delay::DelayNs;

/// Ticks per second of [`now_ticks`]: the core clock of mps2-an500, Hz.
pub const TICK_HZ: u32 = 25_000_000;

/// Instructions per tick when QEMU runs with `-icount shift=0` (each instruction then takes
/// 1 ns of virtual time, and a tick is 1/25 MHz = 40 ns). Measured by `src/bin/selftest.rs`.
pub const INSTRUCTIONS_PER_TICK_ICOUNT0: u32 = 1_000_000_000 / TICK_HZ;

/// SysTick reload value: the full 24 bits, so a wrap every 2^24 ticks.
pub const RELOAD: u32 = 0x00FF_FFFF;

/// Ticks per SysTick wrap.
const PERIOD: u64 = RELOAD as u64 + 1;

/// Wraps of SysTick since [`Clock::start`], counted by the `SysTick` exception.
static WRAPS: AtomicU32 = AtomicU32::new(0);
static STARTED: AtomicBool = AtomicBool::new(false);

/// Proof that SysTick runs as this module's tick counter: a copyable handle to the clock.
#[derive(Debug, Clone, Copy)]
pub struct Clock {
    _private: (),
}

impl Clock {
    /// Takes SysTick and starts it from the core clock with the full 24-bit reload and its
    /// exception enabled; ticks count from zero.
    pub fn start(mut syst: SYST) -> Self {
        syst.disable_counter();
        syst.disable_interrupt();
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(RELOAD);
        syst.clear_current();
        WRAPS.store(0, Ordering::SeqCst);
        syst.enable_interrupt();
        syst.enable_counter();
        STARTED.store(true, Ordering::SeqCst);
        Self { _private: () }
    }

    /// Ticks ([`TICK_HZ`]) since [`Clock::start`].
    #[inline]
    pub fn now_ticks(&self) -> u64 {
        now_ticks()
    }

    /// A busy-wait delay on this clock.
    pub fn delay(&self) -> Delay {
        Delay { _clock: *self }
    }
}

/// Ticks ([`TICK_HZ`]) since [`Clock::start`]; 0 before it. Monotonic (its 32-bit wrap count
/// lasts 2^56 ticks, 91 years).
pub fn now_ticks() -> u64 {
    if !STARTED.load(Ordering::Relaxed) {
        return 0;
    }
    loop {
        // The SysTick exception may run anywhere in here, or be pending (masked interrupts, or
        // a wrap between the reads): take the count only from a stable snapshot. Single core,
        // so the fences only keep the compiler from reordering the reads.
        let wraps_before = WRAPS.load(Ordering::Relaxed);
        compiler_fence(Ordering::SeqCst);
        let pending_before = SCB::is_pendst_pending();
        let current = SYST::get_current();
        let pending_after = SCB::is_pendst_pending();
        compiler_fence(Ordering::SeqCst);
        let wraps_after = WRAPS.load(Ordering::Relaxed);

        // CVR reads 0 from the moment it reaches zero until it reloads, which may fall on
        // either side of the exception being pended (on QEMU it reads 0 from the deadline
        // until its timer callback runs): skip that one tick instead of guessing.
        if current == 0 || wraps_before != wraps_after || pending_before != pending_after {
            core::hint::spin_loop();
            continue;
        }
        let wraps = u64::from(wraps_before) + u64::from(pending_before);
        // CVR counts RELOAD..=1 through a period: elapsed ticks 1..=RELOAD.
        return wraps * PERIOD + (PERIOD - u64::from(current));
    }
}

/// The tracker board's clock: its ticks time-stamp each `State` and measure `track_ticks`
/// (exactly 40 instructions per tick under `-icount shift=0`).
impl digiteyes_firmware::Clock for Clock {
    fn ticks(&mut self) -> u64 {
        now_ticks()
    }

    fn hz(&self) -> u32 {
        TICK_HZ
    }
}

#[exception]
fn SysTick() {
    WRAPS.fetch_add(1, Ordering::Relaxed);
}

/// A busy-wait `embedded-hal` delay on the SysTick clock: waits at least the asked time, at
/// most about one tick (40 ns) longer, plus the time taken by interrupts.
#[derive(Debug, Clone, Copy)]
pub struct Delay {
    _clock: Clock,
}

impl Delay {
    fn wait_ticks(ticks: u64) {
        if ticks == 0 {
            return;
        }
        let start = now_ticks();
        // `start` may fall anywhere within its tick: wait for one boundary more.
        while now_ticks().wrapping_sub(start) <= ticks {
            core::hint::spin_loop();
        }
    }
}

impl DelayNs for Delay {
    fn delay_ns(&mut self, ns: u32) {
        Self::wait_ticks((u64::from(ns) * u64::from(TICK_HZ)).div_ceil(1_000_000_000));
    }

    fn delay_us(&mut self, us: u32) {
        Self::wait_ticks((u64::from(us) * u64::from(TICK_HZ)).div_ceil(1_000_000));
    }

    fn delay_ms(&mut self, ms: u32) {
        Self::wait_ticks(u64::from(ms) * u64::from(TICK_HZ / 1_000));
    }
}
