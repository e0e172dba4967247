//! Property tests ("fuzzing") of the `hand.dh` parser and writer: whatever the text, parsing
//! returns `Ok` or `Err` without panicking, errors point at a line of the text, and every model
//! that parses is written back to text that parses to the same model.
//!
//! Case counts: each of the four properties below runs 2000 cases (8000 parses, plus a write,
//! a re-parse and a forward-kinematics pass for every one that succeeds); about 1–2 s in
//! total with the workspace's optimised test profile.

use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::{Model, ModelErrorKind, HAND_DH};
use digiteyes_core::model_writer::write_dh;
use digiteyes_core::nalgebra::Vector3;
use proptest::prelude::*;

const CASES: u32 = 2000;

/// Parses `text` and checks everything that must hold for any input.
fn check(text: &str) {
    match Model::parse(text) {
        Ok(model) => check_model(&model),
        Err(e) => {
            let lines = text.lines().count() as u32;
            if e.kind == ModelErrorKind::Empty {
                assert!(e.line <= lines, "{e}: beyond the text's {lines} lines");
            } else {
                assert!(
                    e.line >= 1 && e.line <= lines,
                    "{e}: line outside the text's {lines} lines"
                );
            }
            assert!(e.to_string().contains(&format!("line {}", e.line)));
        }
    }
}

/// Round trip, invariants, and that kinematics copes with whatever tree parsed.
fn check_model(model: &Model) {
    let mut text = String::new();
    write_dh(model, &mut text).unwrap();
    let back = Model::parse(&text).unwrap_or_else(|e| panic!("written text fails: {e}\n{text}"));
    assert_eq!(&back, model, "round trip changed the model:\n{text}");

    let n = model.links().len();
    assert_eq!(model.order().len(), n);
    for f in 0..n {
        assert!(model.chain(f).is_some());
    }
    let mut q = vec![0.3f32; model.n_states()];
    q[..4].copy_from_slice(&[1.0, 0.0, 0.0, 0.0]);
    let poses = Poses::compute(model, &q).expect("a valid state for a parsed model");
    for f in 0..n {
        let p = poses.origin(f).unwrap();
        // Far-fetched tables (lengths up to f32::MAX) may overflow to inf; no panic either way.
        let d = poses.point_derivatives(model, f, &(p + Vector3::new(1.0, 2.0, 3.0)));
        // A point on frame `f` moves with the seven palm states, then with exactly the joints
        // of `f`'s chain, root first: every one a state of the model.
        let states: Vec<u8> = d.iter().map(|(s, _)| *s).collect();
        let mut expected: Vec<u8> = (0..7).collect();
        expected.extend(model.chain(f).unwrap());
        assert_eq!(states, expected, "states moving a point on frame {f}");
        assert!(states.iter().all(|&s| usize::from(s) < model.n_states()));
    }
}

/// Tokens the format knows, tokens near its edges, and garbage.
fn token() -> impl Strategy<Value = String> {
    let special = prop::sample::select(vec![
        "nan",
        "NaN",
        "inf",
        "-inf",
        "infinity",
        "1e39",
        "-1e39",
        "1e-45",
        "0",
        "-0",
        "+0",
        "-",
        "--1",
        "+",
        "base",
        "pi",
        "-pi",
        "pi/0",
        "0/0",
        "2*pi/3",
        "pi*pi*pi",
        "1/2/3",
        "*",
        "/",
        ".",
        "1.",
        ".5",
        "q",
        "q7",
        "q8",
        "q25",
        "q27",
        "q28",
        "q31",
        "q32",
        "q255",
        "q256",
        "q99999999999",
        "q-1",
        "limit",
        "at",
        "box",
        "cyl",
        "tip",
        "#",
        "340282350000000000000000000000000000000",
        "340282360000000000000000000000000000000",
        "99999999999999999999",
        "65535",
        "65536",
        "36",
        "37",
        "47",
        "48",
        "49",
        "aaaaaaaaaaaaaaaaaaaaaaaaa",
        "finger1.tip",
        "é",
        "\u{feff}",
    ])
    .prop_map(String::from);
    prop_oneof![
        4 => special,
        2 => (0u32..60).prop_map(|v| v.to_string()),
        1 => any::<i32>().prop_map(|v| v.to_string()),
        1 => any::<f32>().prop_map(|v| v.to_string()),
        1 => (-10.0f32..10.0).prop_map(|v| v.to_string()),
        1 => "[a-z0-9.*/+#-]{1,6}",
    ]
}

/// One edit of a text, seen as lines of whitespace-separated tokens. Indices are reduced
/// modulo the current line or token count when applied.
#[derive(Debug, Clone)]
enum Edit {
    Delete(usize),
    Duplicate(usize),
    Swap(usize, usize),
    Replace(usize, usize, String),
    InsertToken(usize, usize, String),
    DropToken(usize, usize),
    InsertLine(usize, String),
}

fn edit() -> impl Strategy<Value = Edit> {
    let line = any::<usize>();
    prop_oneof![
        1 => line.prop_map(Edit::Delete),
        1 => line.prop_map(Edit::Duplicate),
        1 => (line, any::<usize>()).prop_map(|(a, b)| Edit::Swap(a, b)),
        4 => (line, any::<usize>(), token()).prop_map(|(l, t, s)| Edit::Replace(l, t, s)),
        1 => (line, any::<usize>(), token()).prop_map(|(l, t, s)| Edit::InsertToken(l, t, s)),
        1 => (line, any::<usize>()).prop_map(|(l, t)| Edit::DropToken(l, t)),
        1 => (line, prop::collection::vec(token(), 0..10))
            .prop_map(|(l, tokens)| Edit::InsertLine(l, tokens.join(" "))),
    ]
}

fn apply(text: &str, edits: &[Edit]) -> String {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    for e in edits {
        let n = lines.len();
        if n == 0 {
            if let Edit::InsertLine(_, l) = e {
                lines.push(l.clone());
            }
            continue;
        }
        match e {
            Edit::Delete(i) => {
                lines.remove(i % n);
            }
            Edit::Duplicate(i) => {
                let l = lines[i % n].clone();
                lines.insert(i % n, l);
            }
            Edit::Swap(i, j) => lines.swap(i % n, j % n),
            Edit::InsertLine(i, l) => lines.insert(i % (n + 1), l.clone()),
            Edit::Replace(i, t, s) | Edit::InsertToken(i, t, s) => {
                let mut tokens: Vec<&str> = lines[i % n].split_whitespace().collect();
                let len = tokens.len();
                match e {
                    Edit::Replace(..) if len > 0 => tokens[t % len] = s.as_str(),
                    _ => tokens.insert(t % (len + 1), s.as_str()),
                }
                lines[i % n] = tokens.join(" ");
            }
            Edit::DropToken(i, t) => {
                let mut tokens: Vec<&str> = lines[i % n].split_whitespace().collect();
                if !tokens.is_empty() {
                    let len = tokens.len();
                    tokens.remove(t % len);
                }
                lines[i % n] = tokens.join(" ");
            }
        }
    }
    lines.join("\n")
}

/// The built-in table without comments, so that most edits land on rows.
fn hand_rows() -> String {
    HAND_DH
        .lines()
        .filter(|l| !l.trim_start().starts_with('#') && !l.trim().is_empty())
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn unmutated_inputs_hold_the_properties() {
    check(HAND_DH);
    check(&hand_rows());
    check("");
    check("\n\n");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: CASES, ..ProptestConfig::default() })]

    /// Any Unicode text.
    #[test]
    fn arbitrary_text_never_panics(text in any::<String>()) {
        check(&text);
    }

    /// Printable ASCII with line breaks: closer to what the tokenizer sees.
    #[test]
    fn ascii_text_never_panics(text in "[ -~\t\n]{0,600}") {
        check(&text);
    }

    /// Lines of format-shaped tokens, often starting with the right frame number.
    #[test]
    fn token_soup_never_panics(
        rows in prop::collection::vec(prop::collection::vec(token(), 0..12), 0..50),
        numbered in any::<bool>(),
    ) {
        let text: String = rows
            .iter()
            .enumerate()
            .map(|(i, tokens)| {
                let mut line = if numbered { format!("{i} ") } else { String::new() };
                line += &tokens.join(" ");
                line + "\n"
            })
            .collect();
        check(&text);
    }

    /// The built-in hand with 1..8 line and token edits: deleted, duplicated, swapped lines,
    /// tokens replaced by numbers, `nan`, huge values, keywords and junk.
    #[test]
    fn mutated_hand_never_panics_and_round_trips(
        edits in prop::collection::vec(edit(), 1..8),
        with_comments in any::<bool>(),
    ) {
        let base = if with_comments { HAND_DH.to_string() } else { hand_rows() };
        check(&apply(&base, &edits));
    }
}

/// An edit of the hand's rows that keeps the table valid, so the round trip is exercised on
/// every case (random edits mostly give errors).
#[derive(Debug, Clone)]
enum ValidEdit {
    Name(usize, String),
    /// d, a or alpha (field 3, 4, 5) of a row.
    Number(usize, usize, String),
    /// A constant theta (rows with `base` or `qN` are left alone).
    Theta(usize, String),
    /// A cylinder or tip radius, or a box size.
    Size(usize, usize, String),
    BoxCentre(String, String, String),
    Limit(usize, f32, f32),
    DropLimit(usize),
}

/// A finite f32 written in one of the spellings the parser accepts (the product form only
/// where it cannot overflow).
fn number_text(value: impl Strategy<Value = f32>) -> impl Strategy<Value = String> {
    (value, 0u8..5).prop_map(|(v, style)| match style {
        1 => format!("{v:e}"),
        2 => format!("{v:?}"),
        3 => format!("{v:.3}"),
        4 if v.abs() < 1e30 => format!("{v}*pi/4"),
        _ => format!("{v}"),
    })
}

/// A positive length, spelled so that it stays positive (no rounding to 0.000).
fn length_text() -> impl Strategy<Value = String> {
    (positive(), 0u8..3).prop_map(|(v, style)| match style {
        1 => format!("{v:e}"),
        2 => format!("{v:?}"),
        _ => format!("{v}"),
    })
}

fn finite() -> impl Strategy<Value = f32> {
    use prop::num::f32::{NEGATIVE, NORMAL, POSITIVE, SUBNORMAL, ZERO};
    prop_oneof![
        -200.0f32..200.0,
        POSITIVE | NEGATIVE | NORMAL | SUBNORMAL | ZERO,
    ]
}

fn positive() -> impl Strategy<Value = f32> {
    use prop::num::f32::{NORMAL, POSITIVE, SUBNORMAL};
    prop_oneof![0.01f32..100.0, POSITIVE | NORMAL | SUBNORMAL]
}

fn valid_edit() -> impl Strategy<Value = ValidEdit> {
    let row = 0usize..37;
    prop_oneof![
        1 => (row.clone(), "[A-Za-z0-9._-]{1,24}").prop_map(|(r, n)| ValidEdit::Name(r, n)),
        3 => (row.clone(), 3usize..6, number_text(finite()))
            .prop_map(|(r, f, v)| ValidEdit::Number(r, f, v)),
        1 => (row.clone(), number_text(-10.0f32..10.0)).prop_map(|(r, v)| ValidEdit::Theta(r, v)),
        2 => (row, 0usize..3, length_text())
            .prop_map(|(r, i, v)| ValidEdit::Size(r, i, v)),
        1 => (number_text(finite()), number_text(finite()), number_text(finite()))
            .prop_map(|(x, y, z)| ValidEdit::BoxCentre(x, y, z)),
        1 => (0usize..21, finite(), finite()).prop_map(|(l, a, b)| ValidEdit::Limit(l, a, b)),
        1 => (0usize..21).prop_map(ValidEdit::DropLimit),
    ]
}

fn apply_valid(edits: &[ValidEdit]) -> String {
    let mut rows: Vec<Vec<String>> = hand_rows()
        .lines()
        .map(|l| l.split_whitespace().map(String::from).collect())
        .collect();
    assert_eq!(rows.len(), 37 + 21);
    let mut dropped = [false; 21];
    for e in edits {
        match e {
            ValidEdit::Name(r, n) => rows[*r][1] = n.clone(),
            ValidEdit::Number(r, f, v) => rows[*r][*f] = v.clone(),
            ValidEdit::Theta(r, v) => {
                let t = &rows[*r][2];
                if t != "base" && !t.starts_with('q') {
                    rows[*r][2] = v.clone();
                }
            }
            ValidEdit::Size(r, i, v) => match rows[*r][6].as_str() {
                "cyl" | "tip" => rows[*r][7] = v.clone(),
                "box" => rows[*r][7 + i] = v.clone(),
                _ => {}
            },
            ValidEdit::BoxCentre(x, y, z) => {
                if rows[0][10] == "at" {
                    rows[0].splice(11..14, [x.clone(), y.clone(), z.clone()]);
                } else {
                    rows[0].splice(10..10, ["at".into(), x.clone(), y.clone(), z.clone()]);
                }
            }
            ValidEdit::Limit(l, a, b) => {
                let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
                rows[37 + l].splice(2..4, [lo.to_string(), hi.to_string()]);
            }
            ValidEdit::DropLimit(l) => dropped[*l] = true,
        }
    }
    rows.iter()
        .enumerate()
        .filter(|(i, _)| *i < 37 || !dropped[i - 37])
        .map(|(_, r)| r.join(" ") + "\n")
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: CASES, ..ProptestConfig::default() })]

    /// The hand with valid numbers, names, box centres and limits changed: always parses, and
    /// always round-trips exactly through `write_dh`.
    #[test]
    fn valid_edits_of_the_hand_round_trip(edits in prop::collection::vec(valid_edit(), 1..12)) {
        let text = apply_valid(&edits);
        let model = Model::parse(&text);
        prop_assert!(model.is_ok(), "{:?}\n{}", model.err(), text);
        check_model(&model.unwrap());
    }
}
