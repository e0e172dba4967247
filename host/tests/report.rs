//! `digiteyes report`: one plot per free state whose lines are the CSV's values, truth only
//! with a truth.csv, thumbnails that decode, no external reference, and clear failures.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use base64::Engine;
use digiteyes_host::report::{build_report, write_report, ReportOptions};
use digiteyes_host::sequence::{read_states, Sequence};
use digiteyes_host::{track_sequence, TrackerConfig};

use common::{message, small_sequence, FIXTURE};

/// The fixture tracked into `dir/states.csv`.
fn tracked_fixture(dir: &Path) -> PathBuf {
    let states = dir.join("states.csv");
    track_sequence(Path::new(FIXTURE), &states, TrackerConfig::default(), false).unwrap();
    states
}

/// A small rendered sequence of `scenario`, tracked: (sequence folder, states CSV).
fn tracked_small(dir: &Path, scenario: &str, frames: usize) -> (PathBuf, PathBuf) {
    let seq = small_sequence(dir, scenario, frames);
    let states = dir.join(format!("{scenario}.csv"));
    track_sequence(&seq, &states, TrackerConfig::default(), false).unwrap();
    (seq, states)
}

fn options(every: usize, width: u32) -> ReportOptions {
    let mut options = ReportOptions::default();
    options.thumb_every = every;
    options.thumb_width = width;
    options
}

/// Every `<svg ...>...</svg>` element whose opening tag contains `class="{class}"`.
fn svgs<'a>(html: &'a str, class: &str) -> Vec<&'a str> {
    let marker = format!(r#"class="{class}""#);
    let mut out = Vec::new();
    let mut rest = html;
    while let Some(start) = rest.find("<svg ") {
        let end = start + rest[start..].find("</svg>").expect("unclosed svg") + "</svg>".len();
        let element = &rest[start..end];
        let open_tag = &element[..element.find('>').unwrap()];
        if open_tag.contains(&marker) {
            out.push(element);
        }
        rest = &rest[end..];
    }
    out
}

/// The value of attribute `name` in the first tag of `element`.
fn attribute<'a>(element: &'a str, name: &str) -> Option<&'a str> {
    let tag = &element[..element.find('>')?];
    let key = format!(r#" {name}=""#);
    let start = tag.find(&key)? + key.len();
    Some(&tag[start..start + tag[start..].find('"')?])
}

/// The points of every `<polyline class="{class}">` in `svg`, one vector per polyline.
fn polylines(svg: &str, class: &str) -> Vec<Vec<(f64, f64)>> {
    let key = format!(r#"<polyline class="{class}" points=""#);
    svg.match_indices(&key)
        .map(|(i, _)| {
            let start = i + key.len();
            let points = &svg[start..start + svg[start..].find('"').unwrap()];
            points
                .split(' ')
                .map(|p| {
                    let (x, y) = p.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect()
        })
        .collect()
}

/// The ticks of one axis (`xtick` or `ytick`): (position along the axis in user units, the
/// value its label shows).
fn ticks(svg: &str, axis: &str) -> Vec<(f64, f64)> {
    let key = format!(r#"<g class="{axis}" transform="translate("#);
    svg.match_indices(&key)
        .map(|(i, _)| {
            let rest = &svg[i + key.len()..];
            let (x, rest) = rest.split_once(',').unwrap();
            let (y, rest) = rest.split_once(')').unwrap();
            let text = &rest[rest.find("<text").unwrap()..];
            let label = &text[text.find('>').unwrap() + 1..];
            let label = &label[..label.find('<').unwrap()];
            let position: f64 = if axis == "xtick" { x } else { y }.parse().unwrap();
            (position, label.parse().unwrap())
        })
        .collect()
}

/// The linear map from user units back to data values that an axis' ticks show.
fn axis_inverse(svg: &str, axis: &str) -> impl Fn(f64) -> f64 {
    let t = ticks(svg, axis);
    assert!(t.len() >= 2, "{axis}: too few ticks in {svg}");
    let ((p0, v0), (p1, v1)) = (t[0], t[t.len() - 1]);
    move |p| v0 + (p - p0) / (p1 - p0) * (v1 - v0)
}

fn data_uris(html: &str) -> Vec<Vec<u8>> {
    let key = r#"src="data:image/png;base64,"#;
    html.match_indices(key)
        .map(|(i, _)| {
            let start = i + key.len();
            let data = &html[start..start + html[start..].find('"').unwrap()];
            base64::engine::general_purpose::STANDARD
                .decode(data)
                .unwrap()
        })
        .collect()
}

fn assert_self_contained(html: &str) {
    // Base64 may hold "//": look at the page without its images' data.
    let key = r#"src="data:image/png;base64,"#;
    let mut lower = String::new();
    let mut rest = html;
    while let Some(i) = rest.find(key) {
        lower.push_str(&rest[..i + key.len()]);
        rest = &rest[i + key.len()..];
        rest = &rest[rest.find('"').unwrap()..];
    }
    lower.push_str(rest);
    let lower = lower.to_ascii_lowercase();
    assert!(!lower.contains("<script"), "a script");
    assert!(!lower.contains("href="), "a link");
    assert!(!lower.contains("url("), "a CSS url()");
    assert!(!lower.contains("@import"), "a CSS import");
    let without_xmlns = lower.replace(r#"xmlns="http://www.w3.org/2000/svg""#, "");
    assert!(!without_xmlns.contains("http:") && !without_xmlns.contains("https:"));
    assert!(!without_xmlns.contains("//"), "a protocol-relative URL");
    for (i, _) in lower.match_indices("src=") {
        assert!(lower[i..].starts_with(r#"src="data:image/png;base64,"#));
    }
}

#[test]
fn mouse_report_has_a_plot_per_free_state_whose_lines_are_the_csv() {
    let dir = tempfile::tempdir().unwrap();
    let states = tracked_fixture(dir.path());
    let out = dir.path().join("report.html");
    let summary = write_report(Path::new(FIXTURE), &states, &out, &options(5, 200)).unwrap();
    let html = std::fs::read_to_string(&out).unwrap();
    assert_eq!(summary.bytes, html.len());
    assert_eq!(summary.out, out);

    let sequence = Sequence::open(Path::new(FIXTURE)).unwrap();
    let free = sequence.free_states();
    assert_eq!(free, vec![4, 5, 8, 9, 10, 19, 24]);
    let plots = svgs(&html, "state-plot");
    let plotted: Vec<usize> = plots
        .iter()
        .map(|p| attribute(p, "data-state").unwrap().parse().unwrap())
        .collect();
    assert_eq!(plotted, free);
    assert_eq!(summary.state_plots, free.len());

    // Truth is there: one line of each per plot.
    for p in &plots {
        assert_eq!(polylines(p, "truth").len(), 1);
        assert_eq!(polylines(p, "estimate").len(), 1);
    }
    assert!(summary.eval.is_some());
    assert!(html.contains("fingertip mean"), "the eval table");
    assert_eq!(svgs(&html, "error-plot").len(), summary.error_plots);
    assert!(summary.error_plots >= 2);

    // The lines' points, read back through the axes' tick labels, are the CSV's values at
    // the frames' times.
    let fps = sequence.fps().unwrap();
    let estimate = read_states(&states, sequence.n_states()).unwrap();
    let truth = sequence.read_truth().unwrap();
    for p in &plots {
        let state: usize = attribute(p, "data-state").unwrap().parse().unwrap();
        let (x, y) = (axis_inverse(p, "xtick"), axis_inverse(p, "ytick"));
        let ticks_y = ticks(p, "ytick");
        let span = ticks_y[ticks_y.len() - 1].1 - ticks_y[0].1;
        for (class, table) in [("estimate", &estimate), ("truth", &truth)] {
            let line = &polylines(p, class)[0];
            assert_eq!(line.len(), sequence.frames, "q{state} {class}");
            for (k, &(px, py)) in line.iter().enumerate() {
                let t = x(px);
                assert!(
                    (t - k as f64 / fps).abs() < 1e-3,
                    "q{state} frame {k}: t {t}"
                );
                let v = y(py);
                let want = table.rows[k][state];
                assert!(
                    (v - want).abs() < 1e-3 * span,
                    "q{state} {class} frame {k}: plotted {v}, CSV {want}"
                );
            }
        }
    }

    // ceil(12 / 5) thumbnails that decode as PNG of the asked width.
    let images = data_uris(&html);
    assert_eq!(images.len(), sequence.frames.div_ceil(5));
    assert_eq!(summary.thumbnails, images.len());
    for png in &images {
        let image = image::load_from_memory_with_format(png, image::ImageFormat::Png).unwrap();
        assert_eq!(image.width(), 200);
        assert_eq!(image.height(), 150);
    }
    assert_self_contained(&html);
}

#[test]
fn truth_series_only_with_a_truth_file_for_another_free_set() {
    let dir = tempfile::tempdir().unwrap();
    let (seq, states) = tracked_small(dir.path(), "twofinger", 7);
    let free = Sequence::open(&seq).unwrap().free_states();
    assert_ne!(free, vec![4, 5, 8, 9, 10, 19, 24]);

    let (with, summary) = build_report(&seq, &states, &options(3, 100)).unwrap();
    let plots = svgs(&with, "state-plot");
    let plotted: Vec<usize> = plots
        .iter()
        .map(|p| attribute(p, "data-state").unwrap().parse().unwrap())
        .collect();
    assert_eq!(plotted, free);
    assert!(plots.iter().all(|p| polylines(p, "truth").len() == 1));
    assert!(summary.eval.is_some());
    assert_eq!(data_uris(&with).len(), 3); // ceil(7 / 3)

    std::fs::remove_file(seq.join("truth.csv")).unwrap();
    let (without, summary) = build_report(&seq, &states, &options(3, 100)).unwrap();
    let plots = svgs(&without, "state-plot");
    assert_eq!(plots.len(), free.len());
    assert!(plots.iter().all(|p| polylines(p, "truth").is_empty()));
    assert!(plots.iter().all(|p| polylines(p, "estimate").len() == 1));
    assert!(summary.eval.is_none());
    assert!(!without.contains("class=\"truth\""));
    // Without truth, the error over time is the tracker's own residual.
    let errors = svgs(&without, "error-plot");
    assert_eq!(errors.len(), 1);
    assert_eq!(attribute(errors[0], "data-series"), Some("rms"));
    assert_self_contained(&without);
}

/// Rewrites `states` with `edit(frame, fields)` applied to every data row and `header`
/// appended to the header.
fn edit_csv(states: &Path, header: &str, edit: impl Fn(usize, &mut Vec<String>)) {
    let text = std::fs::read_to_string(states).unwrap();
    let mut lines = text.lines();
    let mut out = format!("{}{header}\n", lines.next().unwrap());
    for (k, line) in lines.enumerate() {
        let mut fields: Vec<String> = line.split(',').map(str::to_string).collect();
        edit(k, &mut fields);
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    std::fs::write(states, out).unwrap();
}

#[test]
fn nan_states_are_gaps_and_dropped_frames_are_marked() {
    let dir = tempfile::tempdir().unwrap();
    let (seq, states) = tracked_small(dir.path(), "mouse", 8);
    // q8 (column 9) is not a number at frame 3; the board dropped frame 5 (as `stream` writes
    // it: the last state repeated, lost = 1, a reason).
    edit_csv(&states, ",dropped", |k, fields| {
        if k == 3 {
            fields[9] = "nan".into();
        }
        if k == 5 {
            // The last columns are `lost`, then `status`.
            let lost = fields.len() - 2;
            fields[lost] = "1".into();
            fields[lost + 1] = "lost".into();
        }
        fields.push(if k == 5 { "wrong size 64x48 <bad>" } else { "" }.into());
    });
    let out = dir.path().join("report.html");
    let summary = write_report(&seq, &states, &out, &options(3, 80)).unwrap();
    let html = std::fs::read_to_string(&out).unwrap();
    assert_eq!(summary.nan_frames, vec![3]);
    assert_eq!(summary.dropped_frames, 1);
    assert!(summary.lost_frames >= 1);
    assert!(
        summary
            .warnings
            .iter()
            .any(|w| w.contains("mouse.csv") && w.contains('3')),
        "{:?}",
        summary.warnings
    );
    // The accuracy leaves the NaN frame out.
    assert_eq!(summary.eval.as_ref().unwrap().frames, 7);

    let plots = svgs(&html, "state-plot");
    let q8 = plots
        .iter()
        .find(|p| attribute(p, "data-state") == Some("8"))
        .unwrap();
    let pieces = polylines(q8, "estimate");
    assert_eq!(pieces.len(), 2, "a gap at frame 3");
    assert_eq!(pieces.iter().map(Vec::len).collect::<Vec<_>>(), vec![3, 4]);
    assert!(
        plots.iter().all(|p| !p.contains("NaN")),
        "no NaN coordinates"
    );
    for p in &plots {
        assert!(p.contains(r#"<g class="dropped" data-frame="5">"#));
        assert!(p.contains("wrong size 64x48 &lt;bad&gt;"), "escaped reason");
        assert!(p.contains(r#"<rect class="lost""#));
    }
    assert!(!html.contains("<bad>"));
    // The NaN frame's thumbnail is the bare frame with a note rather than a failure.
    assert_eq!(data_uris(&html).len(), 3);
    let figure = &html[html
        .find(r#"<figure class="thumb" data-frame="3""#)
        .unwrap()..];
    let caption = &figure[..figure.find("</figure>").unwrap()];
    assert!(caption.contains("no overlay"), "{caption}");
    assert_self_contained(&html);
}

#[test]
fn bad_inputs_fail_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let (seq, states) = tracked_small(dir.path(), "mouse", 4);
    let out = dir.path().join("r.html");
    let opts = ReportOptions::default();

    let missing = dir.path().join("nowhere");
    let err = message(write_report(&missing, &states, &out, &opts));
    assert!(err.contains("nowhere"), "{err}");

    let err = message(write_report(
        &seq,
        &dir.path().join("absent.csv"),
        &out,
        &opts,
    ));
    assert!(err.contains("absent.csv"), "{err}");

    // A states file of another model: too few state columns.
    let narrow = dir.path().join("narrow.csv");
    let text = std::fs::read_to_string(&states).unwrap();
    let cut: String = text
        .lines()
        .map(|l| {
            let mut f: Vec<&str> = l.split(',').collect();
            f.remove(28);
            f.join(",") + "\n"
        })
        .collect();
    std::fs::write(&narrow, cut).unwrap();
    let err = message(write_report(&seq, &narrow, &out, &opts));
    assert!(
        err.contains("narrow.csv") && err.contains("state columns"),
        "{err}"
    );

    // One frame short of the sequence.
    let short = dir.path().join("short.csv");
    let lines: Vec<&str> = text.lines().collect();
    std::fs::write(&short, lines[..lines.len() - 1].join("\n")).unwrap();
    let err = message(write_report(&seq, &short, &out, &opts));
    assert!(
        err.contains("short.csv") && err.contains("3 frames") && err.contains('4'),
        "{err}"
    );

    let mut one_camera = ReportOptions::default();
    one_camera.camera = Some(1);
    let err = message(write_report(&seq, &states, &out, &one_camera));
    assert!(err.contains("camera 1"), "{err}");

    let err = message(write_report(
        &seq,
        &states,
        &dir.path().join("no/such/dir/r.html"),
        &opts,
    ));
    assert!(err.contains("r.html"), "{err}");
    assert!(!out.exists(), "no report from bad input");
}

#[test]
fn the_command_writes_the_report_and_says_where() {
    let dir = tempfile::tempdir().unwrap();
    let (seq, states) = tracked_small(dir.path(), "mouse", 5);
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_digiteyes"))
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap()
    };
    let help = run(&["report", "--help"]);
    let help = String::from_utf8_lossy(&help.stdout);
    for option in [
        "--out",
        "--thumb-every",
        "--thumb-width",
        "--camera-index",
        "truth.csv",
    ] {
        assert!(help.contains(option), "{option} missing from\n{help}");
    }
    let (seq, states) = (seq.to_str().unwrap(), states.to_str().unwrap());
    let out = run(&["report", seq, states, "--thumb-every", "2"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("report.html"), "{stdout}");
    assert_eq!(stdout.lines().count(), 1, "{stdout}");
    let html = std::fs::read_to_string(dir.path().join("report.html")).unwrap();
    assert_eq!(data_uris(&html).len(), 3); // ceil(5 / 2)

    let out = run(&["report", seq, "missing.csv"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing.csv"));
}
