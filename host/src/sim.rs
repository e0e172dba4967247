//! `digiteyes sim`: a simulated Linux board on a pseudo-terminal, for a host to connect to.

use std::ops::Range;
use std::time::Duration;

use anyhow::{bail, Context, Result};
use digiteyes_board_linux::{Corruption, SimBoard, SimOptions, Window};

/// Line noise from the command line: `rate` of the bytes, in `frames` (all when `None`).
pub fn corruption(rate: f64, frames: Option<Range<u32>>, seed: u64) -> Result<Corruption> {
    if !(0.0..=1.0).contains(&rate) {
        bail!("--corrupt {rate}: the rate is a fraction of the bytes, 0 to 1 (0.01 = 1%)");
    }
    Ok(Corruption {
        rate,
        window: frames.map_or(Window::Always, Window::Frames),
        seed,
    })
}

/// Parses `A..B` (frames A to B-1).
pub fn parse_range(text: &str) -> Result<Range<u32>, String> {
    let (a, b) = text
        .split_once("..")
        .ok_or_else(|| format!("`{text}` is not a range A..B, e.g. 10..20"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| format!("`{s}` is not a frame number"))
    };
    let (a, b) = (parse(a)?, parse(b)?);
    if a >= b {
        return Err(format!("`{text}` is empty: A must be below B"));
    }
    Ok(a..b)
}

/// Starts the simulated board and returns it (its [`SimBoard::path`] is the device to
/// connect to).
pub fn start(options: SimOptions) -> Result<SimBoard> {
    SimBoard::start(options).context("cannot start the simulated board on a pseudo-terminal")
}

/// Runs `board` until the process is interrupted, printing its line's figures every
/// `every` (never when `None`).
pub fn serve(board: SimBoard, every: Option<Duration>) -> Result<()> {
    match every {
        None => {
            board.wait().context("the simulated board stopped")?;
        }
        Some(every) => loop {
            std::thread::sleep(every);
            if !board.is_running() {
                board.wait().context("the simulated board stopped")?;
                break;
            }
            eprintln!("{}", board.report());
        },
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_and_rates() {
        assert_eq!(parse_range("3..7").unwrap(), 3..7);
        assert!(parse_range("7..3").is_err());
        assert!(parse_range("3-7").is_err());
        assert!(corruption(1.5, None, 1).is_err());
        assert_eq!(
            corruption(0.01, Some(2..4), 9).unwrap().window,
            Window::Frames(2..4)
        );
    }
}
