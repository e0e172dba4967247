//! Plot primitives as inline SVG text: linear scales, "nice" ticks, and a [`Chart`] that draws
//! axes, lines (with gaps at NaN), shaded spans and markers in SVG user units.
//!
//! Every chart is a `viewBox` of [`WIDTH`] × [`HEIGHT`] user units; the page scales it. Styling
//! is by class (`estimate`, `truth`, `lost`, `dropped`, ...), from the page's stylesheet.

use std::fmt::Write;

use super::html::escape;

/// Width of a chart's view box (SVG user units).
pub const WIDTH: f64 = 440.0;
/// Height of a chart's view box (SVG user units).
pub const HEIGHT: f64 = 230.0;
/// Height of the status band along the top of a plot (user units).
pub const STRIP_HEIGHT: f64 = 5.0;
/// Room left of the plot area for the y ticks and label.
const LEFT: f64 = 62.0;
/// Room right of the plot area.
const RIGHT: f64 = 12.0;
/// Room above the plot area for the title and legend.
const TOP: f64 = 40.0;
/// Room below the plot area for the x ticks and label.
const BOTTOM: f64 = 38.0;
/// Ticks aimed for on each axis.
const TICKS: f64 = 5.0;

/// A linear map from data values (`d0..d1`) to SVG user units (`p0..p1`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scale {
    /// Data value at `p0`.
    pub d0: f64,
    /// Data value at `p1`.
    pub d1: f64,
    /// User-unit position of `d0`.
    pub p0: f64,
    /// User-unit position of `d1`.
    pub p1: f64,
}

impl Scale {
    /// The position (user units) of data value `v`.
    pub fn map(&self, v: f64) -> f64 {
        self.p0 + (v - self.d0) / (self.d1 - self.d0) * (self.p1 - self.p0)
    }

    /// The data value at position `p` (user units).
    pub fn invert(&self, p: f64) -> f64 {
        self.d0 + (p - self.p0) / (self.p1 - self.p0) * (self.d1 - self.d0)
    }
}

/// Ticks covering `lo..hi`: a step of 1, 2 or 5 × 10ⁿ giving about `TICKS` ticks, and the
/// tick values from the last multiple of the step at or below `lo` to the first at or above
/// `hi`. A span that is empty or not finite is widened first.
pub fn nice_ticks(lo: f64, hi: f64) -> (Vec<f64>, f64) {
    let (lo, hi) = widen(lo, hi);
    let raw = (hi - lo) / TICKS;
    let magnitude = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * magnitude)
        .find(|&s| s >= raw * (1.0 - 1e-9))
        .unwrap_or(10.0 * magnitude);
    let first = (lo / step + 1e-9).floor() as i64;
    let last = (hi / step - 1e-9).ceil() as i64;
    let ticks = (first..=last).map(|i| i as f64 * step).collect();
    (ticks, step)
}

/// `lo..hi` made usable for a scale: finite, ordered and not empty.
fn widen(lo: f64, hi: f64) -> (f64, f64) {
    if !lo.is_finite() || !hi.is_finite() {
        return (0.0, 1.0);
    }
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    if hi - lo > 1e-12 * hi.abs().max(lo.abs()).max(1e-300) {
        return (lo, hi);
    }
    let pad = if lo.abs() > 0.0 { lo.abs() * 0.05 } else { 1.0 };
    (lo - pad, hi + pad)
}

/// A tick value as text, with as many decimals as the step needs ("0.25", "-10", "600").
pub fn format_tick(v: f64, step: f64) -> String {
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    let v = if v.abs() < step * 1e-6 { 0.0 } else { v };
    format!("{v:.decimals$}")
}

/// The finite minimum and maximum of `values`, if any is finite.
pub fn finite_range<'a>(values: impl IntoIterator<Item = &'a f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(None, |acc, &v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// One line of a chart's legend: the class of its swatch and its text.
#[derive(Debug, Clone)]
pub struct LegendEntry {
    /// The class of the thing it names (`estimate`, `truth`, `lost`, ...).
    pub class: &'static str,
    /// What it is.
    pub text: String,
}

/// A chart being drawn: a plot area with an x and a y scale; elements are drawn in call order
/// over the grid and under the axes' labels.
#[derive(Debug, Clone)]
pub struct Chart {
    /// Data → user units along x.
    pub x: Scale,
    /// Data → user units along y (`p0` is the bottom of the plot area).
    pub y: Scale,
    x_ticks: (Vec<f64>, f64),
    y_ticks: (Vec<f64>, f64),
    body: String,
}

impl Chart {
    /// A chart whose x axis spans exactly `x_range` and whose y axis covers `y_range`,
    /// widened to whole ticks.
    pub fn new(x_range: (f64, f64), y_range: (f64, f64)) -> Chart {
        let (x0, x1) = widen(x_range.0, x_range.1);
        let x_ticks = nice_ticks(x0, x1);
        let y_ticks = nice_ticks(y_range.0, y_range.1);
        let (ys, _) = &y_ticks;
        let (y0, y1) = (ys[0], ys[ys.len() - 1]);
        Chart {
            x: Scale {
                d0: x0,
                d1: x1,
                p0: LEFT,
                p1: WIDTH - RIGHT,
            },
            y: Scale {
                d0: y0,
                d1: y1,
                p0: HEIGHT - BOTTOM,
                p1: TOP,
            },
            x_ticks,
            y_ticks,
            body: String::new(),
        }
    }

    /// A vertical band from x `x0` to `x1` (data units, clipped to the plot), full height,
    /// with a tooltip.
    pub fn band(&mut self, x0: f64, x1: f64, class: &str, title: &str) {
        let (a, b) = (self.clip_x(x0), self.clip_x(x1));
        if b <= a {
            return;
        }
        let _ = write!(
            self.body,
            r#"<rect class="{class}" x="{a:.2}" y="{top:.2}" width="{w:.2}" height="{h:.2}"><title>{t}</title></rect>"#,
            top = self.y.p1,
            w = b - a,
            h = self.y.p0 - self.y.p1,
            t = escape(title)
        );
    }

    /// A strip from x `x0` to `x1` (data units, clipped to the plot) along the top of the plot
    /// area, [`STRIP_HEIGHT`] high, with a tooltip: the status band.
    pub fn strip(&mut self, x0: f64, x1: f64, class: &str, title: &str) {
        let (a, b) = (self.clip_x(x0), self.clip_x(x1));
        if b <= a {
            return;
        }
        let _ = write!(
            self.body,
            r#"<rect class="{class}" x="{a:.2}" y="{top:.2}" width="{w:.2}" height="{STRIP_HEIGHT:.2}"><title>{t}</title></rect>"#,
            top = self.y.p1,
            w = b - a,
            t = escape(title)
        );
    }

    /// A marker at x `x` (data units): a thin vertical line over the plot and a small
    /// triangle above it, with a tooltip; `attributes` are added to its group as written.
    pub fn marker(&mut self, x: f64, class: &str, attributes: &str, title: &str) {
        let px = self.clip_x(x);
        let _ = write!(
            self.body,
            r#"<g class="{class}"{attributes}><title>{t}</title><line x1="{px:.2}" x2="{px:.2}" y1="{top:.2}" y2="{bottom:.2}"/><path d="M{l:.2},{tt:.2}H{r:.2}L{px:.2},{top:.2}Z"/></g>"#,
            top = self.y.p1,
            bottom = self.y.p0,
            l = px - 3.5,
            r = px + 3.5,
            tt = self.y.p1 - 6.0,
            t = escape(title)
        );
    }

    /// A horizontal reference line at y `y` (data units) with a label at its right end.
    pub fn rule(&mut self, y: f64, class: &str, label: &str) {
        if !(self.y.d0..=self.y.d1).contains(&y) {
            return;
        }
        let py = self.y.map(y);
        let _ = write!(
            self.body,
            r#"<g class="{class}"><line x1="{l:.2}" x2="{r:.2}" y1="{py:.2}" y2="{py:.2}"/><text x="{r:.2}" y="{ty:.2}" text-anchor="end">{t}</text></g>"#,
            l = self.x.p0,
            r = self.x.p1,
            ty = py - 3.0,
            t = escape(label)
        );
    }

    /// A line through the points (`xs[k]`, `ys[k]`) (data units), as one `<polyline>` of class
    /// `class` per run of finite values: a NaN is a gap.
    pub fn line(&mut self, xs: &[f64], ys: &[f64], class: &str) {
        let mut run = String::new();
        let flush = |run: &mut String, body: &mut String| {
            if !run.is_empty() {
                let _ = write!(body, r#"<polyline class="{class}" points="{run}"/>"#);
                run.clear();
            }
        };
        for (&x, &y) in xs.iter().zip(ys) {
            if x.is_finite() && y.is_finite() {
                if !run.is_empty() {
                    run.push(' ');
                }
                let _ = write!(run, "{:.2},{:.2}", self.x.map(x), self.y.map(y));
            } else {
                flush(&mut run, &mut self.body);
            }
        }
        flush(&mut run, &mut self.body);
    }

    /// The finished `<svg>`: `attributes` (e.g. ` class="state-plot" data-state="8"`) on its
    /// root, `title` above the plot, the legend at the top right, the axes with their ticks
    /// (each a `<g class="xtick">`/`<g class="ytick">` translated to its position, holding its
    /// value as text) and their labels.
    pub fn finish(
        self,
        attributes: &str,
        title: &str,
        x_label: &str,
        y_label: &str,
        legend: &[LegendEntry],
    ) -> String {
        let mut s = String::with_capacity(self.body.len() + 4096);
        let (left, right, top, bottom) = (self.x.p0, self.x.p1, self.y.p1, self.y.p0);
        let _ = write!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg"{attributes} viewBox="0 0 {WIDTH} {HEIGHT}" role="img"><title>{t}</title>"#,
            t = escape(title)
        );
        let _ = write!(
            s,
            r#"<text class="title" x="{left:.2}" y="14">{}</text>"#,
            escape(title)
        );
        s.push_str(r#"<g class="grid">"#);
        for &v in &self.y_ticks.0 {
            let py = self.y.map(v);
            let _ = write!(
                s,
                r#"<line x1="{left:.2}" x2="{right:.2}" y1="{py:.2}" y2="{py:.2}"/>"#
            );
        }
        s.push_str("</g>");
        s.push_str(&self.body);
        let _ = write!(
            s,
            r#"<rect class="frame" x="{left:.2}" y="{top:.2}" width="{w:.2}" height="{h:.2}"/>"#,
            w = right - left,
            h = bottom - top
        );
        let (ticks, step) = &self.y_ticks;
        for &v in ticks {
            let _ = write!(
                s,
                r#"<g class="ytick" transform="translate({left:.2},{py:.2})"><line x1="-4" x2="0"/><text x="-6" y="3.5" text-anchor="end">{t}</text></g>"#,
                py = self.y.map(v),
                t = format_tick(v, *step)
            );
        }
        let (ticks, step) = &self.x_ticks;
        for &v in ticks
            .iter()
            .filter(|&&v| self.x.d0 - 1e-9 <= v && v <= self.x.d1 + 1e-9)
        {
            let _ = write!(
                s,
                r#"<g class="xtick" transform="translate({px:.2},{bottom:.2})"><line y1="0" y2="4"/><text y="15" text-anchor="middle">{t}</text></g>"#,
                px = self.x.map(v),
                t = format_tick(v, *step)
            );
        }
        let _ = write!(
            s,
            r#"<text class="label" x="{cx:.2}" y="{ly:.2}" text-anchor="middle">{t}</text>"#,
            cx = (left + right) / 2.0,
            ly = HEIGHT - 6.0,
            t = escape(x_label)
        );
        let _ = write!(
            s,
            r#"<text class="label" transform="translate(14,{cy:.2}) rotate(-90)" text-anchor="middle">{t}</text>"#,
            cy = (top + bottom) / 2.0,
            t = escape(y_label)
        );
        let mut lx = right;
        for entry in legend.iter().rev() {
            let width = 6.0 * entry.text.chars().count() as f64 + 22.0;
            lx -= width;
            let _ = write!(
                s,
                r#"<g class="legend"><rect class="key {c}" x="{lx:.2}" y="22" width="14" height="6"/><text x="{tx:.2}" y="28">{t}</text></g>"#,
                c = entry.class,
                tx = lx + 17.0,
                t = escape(&entry.text)
            );
        }
        s.push_str("</svg>");
        s
    }

    fn clip_x(&self, x: f64) -> f64 {
        self.x.map(x).clamp(self.x.p0, self.x.p1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_cover_the_range() {
        for (lo, hi) in [
            (0.0, 1.0),
            (-0.37, 0.81),
            (598.2, 612.9),
            (0.0, 1.9667),
            (3.0, 3.0),
        ] {
            let (ticks, step) = nice_ticks(lo, hi);
            assert!(
                ticks[0] <= lo && *ticks.last().unwrap() >= hi,
                "{lo} {hi} {ticks:?}"
            );
            assert!((3..=12).contains(&ticks.len()), "{lo} {hi} {ticks:?}");
            let mantissa = step / 10f64.powf(step.log10().floor());
            assert!(
                [1.0, 2.0, 5.0].iter().any(|m| (m - mantissa).abs() < 1e-9),
                "{step}"
            );
            for t in &ticks {
                let text = format_tick(*t, step);
                assert!(
                    (text.parse::<f64>().unwrap() - t).abs() < step * 1e-6,
                    "{text}"
                );
            }
        }
    }

    #[test]
    fn scales_invert() {
        let chart = Chart::new((0.0, 2.0), (-0.3, 0.7));
        for v in [-0.3, 0.0, 0.25, 0.7] {
            assert!((chart.y.invert(chart.y.map(v)) - v).abs() < 1e-12);
        }
        // Up is larger: SVG y grows downwards.
        assert!(chart.y.map(0.7) < chart.y.map(-0.3));
        assert_eq!(chart.x.map(0.0), LEFT);
        assert_eq!(chart.x.map(2.0), WIDTH - RIGHT);
    }

    #[test]
    fn nan_splits_a_line() {
        let mut chart = Chart::new((0.0, 4.0), (0.0, 1.0));
        let xs = [0.0, 1.0, 2.0, 3.0, 4.0];
        chart.line(&xs, &[0.1, 0.2, f64::NAN, 0.4, 0.5], "estimate");
        let svg = chart.finish("", "t", "x", "y", &[]);
        assert_eq!(svg.matches("<polyline").count(), 2, "{svg}");
        assert!(!svg.contains("NaN"));
    }

    #[test]
    fn text_is_escaped() {
        let chart = Chart::new((0.0, 1.0), (0.0, 1.0));
        let svg = chart.finish("", "a<b & c", "x", "y", &[]);
        assert!(svg.contains("a&lt;b &amp; c") && !svg.contains("a<b"));
    }
}
