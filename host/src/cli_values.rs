//! Checked option values for the command line: every duration, rate, size and level the
//! `digiteyes` command takes goes through one of these `clap` value parsers, so a value out
//! of range is refused with the option's own name (clap adds it) and the accepted range,
//! and nothing downstream can panic on it (`Duration::from_secs_f64` panics on NaN,
//! infinities and values past `u64::MAX` seconds).

use std::time::Duration;

use crate::text::quote_value;

/// The longest duration any option takes (s): one week.
pub const MAX_SECONDS: f64 = 7.0 * 24.0 * 3600.0;
/// The shortest reply timeout (s); shorter cannot even carry one frame's bytes.
pub const MIN_REPLY_SECONDS: f64 = 1e-3;
/// Frame rates (frames/s) accepted for a replay.
pub const FPS_RANGE: (f64, f64) = (0.01, 1000.0);
/// The largest noise standard deviation `render` takes (grey levels): beyond it the frame is
/// noise.
pub const MAX_NOISE_SIGMA: f32 = 128.0;
/// The largest blur standard deviation `render` takes (px): beyond it the hand is a smear,
/// and the blur's cost grows with it.
pub const MAX_BLUR_SIGMA: f32 = 20.0;
/// The most frames `render` and `demo` make.
pub const MAX_FRAMES: usize = 100_000;

fn number(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("{} is not a number", quote_value(text)))?;
    if !value.is_finite() {
        return Err(format!("{} is not a finite number", quote_value(text)));
    }
    Ok(value)
}

/// Seconds, strictly positive and at most [`MAX_SECONDS`] (`--seconds`, `--reply-timeout`).
pub fn positive_seconds(text: &str) -> Result<f64, String> {
    let s = number(text)?;
    if !(MIN_REPLY_SECONDS..=MAX_SECONDS).contains(&s) {
        return Err(format!(
            "{s} s is out of range: give {MIN_REPLY_SECONDS} to {MAX_SECONDS} seconds (a week)"
        ));
    }
    Ok(s)
}

/// Seconds where 0 means "never" or "not at all", else as [`positive_seconds`]
/// (`--report-every`, `--ui-seconds`).
pub fn seconds_or_zero(text: &str) -> Result<f64, String> {
    if number(text)? == 0.0 {
        return Ok(0.0);
    }
    positive_seconds(text).map_err(|e| format!("{e}, or 0"))
}

/// A frame rate within [`FPS_RANGE`] (frames/s).
pub fn fps(text: &str) -> Result<f64, String> {
    let f = number(text)?;
    check_fps(f)?;
    Ok(f)
}

/// `Ok` when `fps` is within [`FPS_RANGE`]; also for rates read from files.
pub fn check_fps(fps: f64) -> Result<(), String> {
    let (lo, hi) = FPS_RANGE;
    if fps.is_finite() && (lo..=hi).contains(&fps) {
        Ok(())
    } else {
        Err(format!("{fps} frames/s is out of range: give {lo} to {hi}"))
    }
}

/// The time between frames at `fps`, which [`check_fps`] accepted.
pub fn frame_period(fps: f64) -> Duration {
    Duration::from_secs_f64(1.0 / fps.clamp(FPS_RANGE.0, FPS_RANGE.1))
}

/// A duration from seconds a parser of this module accepted.
pub fn duration(seconds: f64) -> Duration {
    Duration::from_secs_f64(seconds.clamp(0.0, MAX_SECONDS))
}

fn level(text: &str, max: f32, unit: &str) -> Result<f32, String> {
    let v = number(text)?;
    if !(0.0..=f64::from(max)).contains(&v) {
        return Err(format!("{v} is out of range: give 0 to {max} {unit}"));
    }
    Ok(v as f32)
}

/// `render --noise`: 0 to [`MAX_NOISE_SIGMA`] grey levels.
pub fn noise_sigma(text: &str) -> Result<f32, String> {
    level(text, MAX_NOISE_SIGMA, "grey levels")
}

/// `render --blur`: 0 to [`MAX_BLUR_SIGMA`] px.
pub fn blur_sigma(text: &str) -> Result<f32, String> {
    level(text, MAX_BLUR_SIGMA, "px")
}

/// A share from 0 to 1 (`sim --corrupt`).
pub fn share(text: &str) -> Result<f64, String> {
    let v = number(text)?;
    if !(0.0..=1.0).contains(&v) {
        return Err(format!("{v} is out of range: give 0 to 1 (1 = every byte)"));
    }
    Ok(v)
}

/// A frame count from 1 to [`MAX_FRAMES`].
pub fn frame_count(text: &str) -> Result<usize, String> {
    let n: usize = text
        .trim()
        .parse()
        .map_err(|_| format!("{} is not a whole number", quote_value(text)))?;
    if !(1..=MAX_FRAMES).contains(&n) {
        return Err(format!(
            "{n} frames is out of range: give 1 to {MAX_FRAMES}"
        ));
    }
    Ok(n)
}

/// A strictly positive, finite number (one-euro cutoffs, Hz).
pub fn positive(text: &str) -> Result<f32, String> {
    let v = number(text)?;
    if !(v > 0.0 && v <= 1e6) {
        return Err(format!(
            "{v} is out of range: give a number above 0, at most 1e6"
        ));
    }
    Ok(v as f32)
}

/// A finite number ≥ 0 (one-euro betas).
pub fn non_negative(text: &str) -> Result<f32, String> {
    let v = number(text)?;
    if !(0.0..=1e6).contains(&v) {
        return Err(format!("{v} is out of range: give 0 to 1e6"));
    }
    Ok(v as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_refuse_what_would_panic() {
        for bad in ["1e30", "NaN", "inf", "-1", "0", "1e-30", "x"] {
            assert!(positive_seconds(bad).is_err(), "{bad}");
        }
        assert_eq!(positive_seconds("2.5"), Ok(2.5));
        assert_eq!(seconds_or_zero("0"), Ok(0.0));
        assert!(seconds_or_zero("1e30").is_err());
        assert!(seconds_or_zero("-0.5").is_err());
        assert_eq!(duration(MAX_SECONDS), Duration::from_secs(604_800));
    }

    #[test]
    fn rates_levels_and_counts_have_bounds() {
        assert!(fps("1e-30").is_err());
        assert!(fps("1e30").is_err());
        assert_eq!(fps("30"), Ok(30.0));
        assert_eq!(frame_period(1e-30), Duration::from_secs(100));
        assert!(blur_sigma("1e6").is_err());
        assert!(blur_sigma("inf").is_err());
        assert!(blur_sigma("-1").is_err());
        assert!(noise_sigma("NaN").is_err());
        assert_eq!(noise_sigma("8"), Ok(8.0));
        assert!(frame_count("0").is_err());
        assert!(frame_count("100001").is_err());
        assert!(share("1.5").is_err());
        assert!(positive("0").is_err());
        assert!(non_negative("-1").is_err());
    }

    #[test]
    fn a_long_bad_value_is_quoted_short() {
        let long = "9".repeat(10_000) + "x";
        let e = positive_seconds(&long).unwrap_err();
        assert!(e.len() < 200, "{e}");
    }
}
