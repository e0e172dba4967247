//! Checks the board support on the emulator and measures the clock, then exits QEMU with
//! success or failure (semihosting):
//!
//! - the LED register reads back what the pins wrote;
//! - `now_ticks` never goes back, across SysTick wraps with interrupts on and with them masked;
//! - instructions per tick, from two busy loops of known length (exactly 40 under
//!   `-icount shift=0`; without it the figure follows the host's speed);
//! - `DelayNs` waits at least what it is asked (how much longer is printed, not checked:
//!   without `-icount` the host's scheduling adds to it).
//!
//! `cargo run --release --bin selftest` (add `DIGITEYES_ICOUNT=1` for exact counts).
#![no_std]
#![no_main]
#![deny(unsafe_code)]

use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use digiteyes_board_qemu_m7::{
    clock::{now_ticks, Clock, INSTRUCTIONS_PER_TICK_ICOUNT0, RELOAD, TICK_HZ},
    uart::{self, Uart},
    Peripherals,
};
use embedded_hal::{
    delay::DelayNs,
    digital::{OutputPin, StatefulOutputPin},
};
use embedded_io::{ReadReady, WriteReady};

const PERIOD: u64 = RELOAD as u64 + 1;

/// Instructions executed by `cortex_m::asm::delay(n)`: `n + 1` turns of `subs; bne`.
fn delay_instructions(n: u32) -> u64 {
    2 * (u64::from(n) + 1)
}

/// Ticks taken by `cortex_m::asm::delay(n)`.
fn time_delay_loop(n: u32) -> u64 {
    let start = now_ticks();
    cortex_m::asm::delay(n);
    now_ticks() - start
}

/// Ticks either side of a wrap that `across_next_wrap` samples (4 ms at 25 MHz).
const WRAP_MARGIN: u64 = 100_000;

/// Skips cheaply to just before the next SysTick wrap, then samples `now_ticks` densely
/// until just after it (with interrupts masked if `masked`), failing if it ever goes back.
/// Returns the first and last sample. (Busy loops, not samples, cover the rest of the period:
/// under `-icount` QEMU ends its translated block at every register read, so sampling whole
/// periods takes most of a minute.)
fn across_next_wrap(masked: bool) -> Result<(u64, u64), (u64, u64)> {
    loop {
        let wrap = (now_ticks() / PERIOD + 1) * PERIOD;
        while now_ticks() + 2 * WRAP_MARGIN < wrap {
            cortex_m::asm::delay(100_000); // 200k instructions: 5000 ticks under -icount
        }
        let sample = || {
            let first = now_ticks();
            let mut prev = first;
            while prev < wrap + WRAP_MARGIN {
                let t = now_ticks();
                if t < prev {
                    return Err((prev, t));
                }
                prev = t;
            }
            Ok((first, prev))
        };
        let result = if masked {
            cortex_m::interrupt::free(|_| sample())
        } else {
            sample()
        };
        // A stalled host may have carried us past the wrap before sampling began: try again.
        match result {
            Ok((first, _)) if first >= wrap => continue,
            other => return other,
        }
    }
}

#[entry]
fn main() -> ! {
    let (Some(core), Some(board)) = (cortex_m::Peripherals::take(), Peripherals::take()) else {
        panic!("peripherals taken twice");
    };
    let clock = Clock::start(core.SYST);
    let mut serial = Uart::new(board.uart0, uart::Config::default());
    let (mut led0, mut led1) = board.fpgaio.leds();
    let mut failures = 0u32;
    let mut check = |ok: bool, what: &str| {
        hprintln!("selftest: {} {}", if ok { "ok  " } else { "FAIL" }, what);
        if !ok {
            failures += 1;
        }
    };

    // LEDs: the FPGAIO register keeps what was written, one bit per LED.
    let Ok(()) = led0.set_high();
    let Ok(()) = led1.set_low();
    let (Ok(h0), Ok(l1)) = (led0.is_set_high(), led1.is_set_low());
    let Ok(()) = led1.set_high();
    let Ok(()) = led0.set_low();
    let (Ok(l0), Ok(h1)) = (led0.is_set_low(), led1.is_set_high());
    let Ok(()) = led1.set_low();
    check(h0 && l1 && l0 && h1, "LED0/LED1 read back as set");

    // UART0 after reset: free to send, nothing received (no byte is sent here).
    let (Ok(tx_free), Ok(rx_waiting)) = (serial.write_ready(), serial.read_ready());
    check(tx_free, "UART0 transmit register free");
    hprintln!("selftest: UART0 read_ready = {rx_waiting} (true only if the host sent something)");

    // Instructions per tick, from the difference of two loops so call overheads cancel.
    let (short, long) = (5_000_000, 10_000_000);
    let t_short = time_delay_loop(short);
    let t_long = time_delay_loop(long);
    let instructions = delay_instructions(long) - delay_instructions(short);
    let ticks = t_long.saturating_sub(t_short).max(1);
    let milli = instructions * 1000 / ticks;
    hprintln!(
        "selftest: {instructions} instructions took {ticks} ticks: {}.{:03} instructions per tick \
         ({} under -icount shift=0; loops {t_short} and {t_long} ticks)",
        milli / 1000,
        milli % 1000,
        INSTRUCTIONS_PER_TICK_ICOUNT0
    );

    // The cost of reading the clock itself.
    let calls = 10_000u64;
    let t0 = now_ticks();
    for _ in 0..calls {
        core::hint::black_box(now_ticks());
    }
    let ticks = now_ticks() - t0;
    let per_call = ticks * u64::from(INSTRUCTIONS_PER_TICK_ICOUNT0) / calls;
    hprintln!(
        "selftest: {calls} calls of now_ticks took {ticks} ticks \
         (~{per_call} instructions per call under -icount shift=0)"
    );

    // Monotonic through SysTick wraps: with interrupts on, then with them masked (the
    // exception then stays pending across the wrap and the count must still move on).
    for (masked, what) in [
        (false, "monotonic across a wrap, interrupts on"),
        (true, "monotonic across a wrap, interrupts masked"),
    ] {
        match across_next_wrap(masked) {
            Ok((from, to)) => {
                hprintln!("selftest: sampled now_ticks from {from} to {to}");
                check(true, what);
            }
            Err((a, b)) => {
                hprintln!("selftest: now_ticks went back from {a} to {b}");
                check(false, what);
            }
        }
    }

    // DelayNs: at least the time asked, at most a little more.
    let mut delay = clock.delay();
    let mut delay_ok = true;
    for (ask_ns, label) in [
        (1_000u32, "1 us"),
        (1_000_000, "1 ms"),
        (50_000_000, "50 ms"),
    ] {
        let want = u64::from(ask_ns) * u64::from(TICK_HZ) / 1_000_000_000;
        let t0 = now_ticks();
        delay.delay_ns(ask_ns);
        let took = now_ticks() - t0;
        // Only the lower bound is a check: without -icount the host's scheduling adds time.
        hprintln!("selftest: delay_ns({label}) took {took} ticks (asked {want})");
        delay_ok &= took >= want;
    }
    let t0 = now_ticks();
    delay.delay_ms(20);
    let took_ms = now_ticks() - t0;
    delay_ok &= took_ms >= 20 * u64::from(TICK_HZ / 1000);
    check(delay_ok, "DelayNs waits at least the time asked");

    hprintln!("selftest: done at tick {}, {failures} failed", now_ticks());
    debug::exit(if failures == 0 {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::wfi();
    }
}
