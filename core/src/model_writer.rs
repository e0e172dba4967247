//! Writes a [`Model`] back out in the `hand.dh` format, so that
//! `Model::parse(written) == model`.
//!
//! Two things make the round trip exact:
//! - numbers are written with `f32`'s `Display`, which prints the shortest decimal that parses
//!   back to the same `f32` (never an exponent, so the parser's `[-]A[*B][/C]` grammar reads
//!   it); angles that are exactly what the parser makes of `pi/2`, `-pi`, `2*pi/3`, ... are
//!   written that way, as in the published table;
//! - every frame row is written on the source line it was parsed from ([`Link::line`], part of
//!   the model's equality), padding with a header comment and blank lines; `limit` rows follow
//!   the last frame.
//!
//! No allocation: the text goes straight to any [`core::fmt::Write`] sink.

use core::fmt::{self, Write};

use crate::model::{Link, Model, Shape, Theta, BASE_STATES, DEFAULT_BOX_CENTRE};

/// Writes `model` as `hand.dh` text to `out`. Errors only when `out` does.
pub fn write_dh<W: Write>(model: &Model, out: &mut W) -> fmt::Result {
    const HEADER: &str =
        "# frame  name            theta   d      a      alpha   shape            next";
    // The 1-based line the next `writeln!` lands on.
    let mut line: u32 = 1;
    for (index, link) in model.links().iter().enumerate() {
        if line == 1 && link.line > 1 {
            writeln!(out, "{HEADER}")?;
            line += 1;
        }
        while line < link.line {
            writeln!(out)?;
            line += 1;
        }
        write_row(index, link, out)?;
        line += 1;
    }
    let mut wrote_heading = false;
    for state in BASE_STATES..model.n_states() {
        if let Some(limit) = model.limit(state) {
            if !wrote_heading {
                writeln!(out, "\n# Joint ranges (rad): limit qN LO HI")?;
                wrote_heading = true;
            }
            writeln!(out, "limit q{:<3} {:<7} {}", state, limit.lo, limit.hi)?;
        }
    }
    Ok(())
}

fn write_row<W: Write>(index: usize, link: &Link, out: &mut W) -> fmt::Result {
    write!(
        out,
        "{:<8} {:<15} {:<7} {:<6} {:<6} {:<7} ",
        index,
        link.name.as_str(),
        ThetaText(link.theta),
        link.d,
        link.a,
        Angle(link.alpha)
    )?;
    match link.shape {
        Shape::None => write!(out, "{:<16} ", "-")?,
        Shape::Cylinder { radius } => write!(out, "cyl {radius:<12} ")?,
        Shape::Tip { radius } => write!(out, "tip {radius:<12} ")?,
        Shape::Box { size, centre } => {
            write!(out, "box {} {} {}", size[0], size[1], size[2])?;
            if centre != DEFAULT_BOX_CENTRE {
                write!(out, " at {} {} {}", centre[0], centre[1], centre[2])?;
            }
            write!(out, "     ")?;
        }
    }
    if link.children.is_empty() {
        write!(out, "-")?;
    } else {
        for (k, child) in link.children.iter().enumerate() {
            if k > 0 {
                write!(out, " ")?;
            }
            write!(out, "{child}")?;
        }
    }
    writeln!(out)
}

/// `theta` as the format writes it, honouring the formatter's width.
struct ThetaText(Theta);

impl fmt::Display for ThetaText {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Theta::Base => f.pad("base"),
            Theta::Const(v) => fmt::Display::fmt(&Angle(v), f),
            Theta::State(s) => {
                // "q" + at most 3 digits.
                let mut text: heapless::String<4> = heapless::String::new();
                write!(text, "q{s}")?;
                f.pad(&text)
            }
        }
    }
}

/// Multiples of pi written symbolically, each with its value computed the way the parser
/// computes it (factors multiplied left to right from 1, then divided), so the text reads back
/// to the identical `f32`.
const PI_FORMS: [(&str, f32, f32); 8] = [
    ("pi", 1.0, 1.0),
    ("pi/2", 1.0, 2.0),
    ("pi/3", 1.0, 3.0),
    ("pi/4", 1.0, 4.0),
    ("pi/6", 1.0, 6.0),
    ("2*pi", 2.0, 1.0),
    ("2*pi/3", 2.0, 3.0),
    ("3*pi/4", 3.0, 4.0),
];

/// An angle (rad): a `PI_FORMS` text when it is exactly one, else the plain decimal.
struct Angle(f32);

impl fmt::Display for Angle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let pi = core::f32::consts::PI;
        for (text, k, n) in PI_FORMS {
            // The parser computes ((1 · k) · pi) / n; multiplying by 1 and dividing by 1 are
            // exact, so this is bitwise its value.
            let value = k * pi / n;
            if self.0.to_bits() == value.to_bits() {
                return f.pad(text);
            }
            if self.0.to_bits() == (-value).to_bits() {
                let mut signed: heapless::String<8> = heapless::String::new();
                write!(signed, "-{text}")?;
                return f.pad(&signed);
            }
        }
        fmt::Display::fmt(&self.0, f)
    }
}
