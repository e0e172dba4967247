//! The files a user hands the `digiteyes` command, mutated at random: a `sequence.json` (with
//! its cameras and initial state checked as `track` checks them), a states CSV (strict and
//! with gaps) and a hypotheses CSV. Every one must be read or refused with an error, never a
//! panic, and what is read must keep the invariants its readers rely on. The seeds are the
//! independent renderer's sequence in `fixtures/sample-mouse/`.

use std::fs;

use digiteyes_core::config::MAX_HYPOTHESES;
use digiteyes_host::sequence::hypotheses::parse_hypotheses;
use digiteyes_host::sequence::states::{parse_states, parse_states_with_gaps};
use digiteyes_host::sequence::Sequence;
use proptest::prelude::*;

const SEQUENCE_JSON: &str = include_str!("../../fixtures/sample-mouse/sequence.json");
const TRUTH_CSV: &str = include_str!("../../fixtures/sample-mouse/truth.csv");
const N_STATES: usize = 28;

/// One edit of a text: replace, insert or delete a character, or swap a number for another.
#[derive(Debug, Clone)]
enum Edit {
    Replace(usize, char),
    Insert(usize, char),
    Delete(usize),
    /// The `n`-th number of the text (counted modulo the numbers there are) becomes `text`.
    Number(usize, String),
}

/// Characters that matter to these formats, and a few that do not.
fn character() -> impl Strategy<Value = char> {
    prop::sample::select(vec![
        '0', '1', '9', '.', '-', '+', 'e', 'E', ',', '\n', '\r', ' ', '"', ':', '[', ']', '{', '}',
        'q', 'n', 'a', 'i', 'f', 'x', '\u{e9}', '\u{0}',
    ])
}

/// Numbers at and beyond the edges of what the readers accept.
fn number() -> impl Strategy<Value = String> {
    prop::sample::select(vec![
        "0",
        "-0",
        "1",
        "-1",
        "0.5",
        "1e-30",
        "-1e-30",
        "1e30",
        "-1e30",
        "3.5e38",
        "1e400",
        "65535",
        "65536",
        "4294967296",
        "18446744073709551616",
        "-7",
        "NaN",
        "inf",
        "",
        "1.",
        "2e",
        "00",
        "0.0000001",
    ])
    .prop_map(str::to_string)
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), character()).prop_map(|(i, c)| Edit::Replace(i, c)),
        (any::<usize>(), character()).prop_map(|(i, c)| Edit::Insert(i, c)),
        any::<usize>().prop_map(Edit::Delete),
        (any::<usize>(), number()).prop_map(|(i, n)| Edit::Number(i, n)),
    ]
}

/// The byte ranges of the numbers in `text` (digits with their sign, point and exponent).
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit()
            || (bytes[i] == b'-' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit));
        if !starts {
            i += 1;
            continue;
        }
        let start = i;
        i += 1;
        while i < bytes.len()
            && (bytes[i].is_ascii_digit() || matches!(bytes[i], b'.' | b'e' | b'E' | b'-' | b'+'))
        {
            i += 1;
        }
        spans.push((start, i));
    }
    spans
}

fn apply(text: &str, edits: &[Edit]) -> String {
    let mut chars: Vec<char> = text.chars().collect();
    for edit in edits {
        let at = |i: usize, len: usize| if len == 0 { 0 } else { i % len };
        match edit {
            Edit::Replace(i, c) if !chars.is_empty() => {
                let i = at(*i, chars.len());
                chars[i] = *c;
            }
            Edit::Insert(i, c) => chars.insert(at(*i, chars.len() + 1), *c),
            Edit::Delete(i) if !chars.is_empty() => {
                chars.remove(at(*i, chars.len()));
            }
            Edit::Number(n, value) => {
                let current: String = chars.iter().collect();
                let spans = numbers(&current);
                if spans.is_empty() {
                    continue;
                }
                let (start, end) = spans[n % spans.len()];
                let replaced = format!("{}{value}{}", &current[..start], &current[end..]);
                chars = replaced.chars().collect();
            }
            _ => {}
        }
    }
    chars.into_iter().collect()
}

/// A hypotheses CSV from the truth's rows: each frame carries `1 + frame % 3` of them.
fn hypotheses_text() -> String {
    let mut text = String::from("frame,rank,score,age");
    for i in 0..N_STATES {
        text.push_str(&format!(",q{i}"));
    }
    text.push('\n');
    for line in TRUTH_CSV.lines().skip(1) {
        let (frame, states) = line.split_once(',').unwrap();
        let count = 1 + frame.parse::<usize>().unwrap() % 3;
        for rank in 0..count {
            text.push_str(&format!("{frame},{rank},0.8{rank},{rank},{states}\n"));
        }
    }
    text
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// A mutated `sequence.json` is opened or refused, and a sequence that opens is checked
    /// for a camera that sees the hand (with the fixture's real frames beside it: every
    /// number of the cameras, the initial state and the free list is fair game).
    #[test]
    fn a_mutated_sequence_json_is_opened_or_refused(edits in prop::collection::vec(edit(), 1..6)) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sequence.json");
        fs::write(&path, apply(SEQUENCE_JSON, &edits)).unwrap();
        if let Ok(sequence) = Sequence::open_description(&path) {
            prop_assert_eq!(sequence.initial_state.len(), sequence.n_states());
            prop_assert!(sequence.initial_state.iter().all(|v| v.is_finite()));
            let _ = sequence.check_cameras_see_the_hand(&[0]);
        }
    }

    /// A mutated states CSV is read or refused, strictly and with gaps; what is read has one
    /// state vector of the model's length per frame, and, read strictly, finite states only.
    #[test]
    fn a_mutated_states_csv_is_read_or_refused(edits in prop::collection::vec(edit(), 1..8)) {
        let text = apply(TRUTH_CSV, &edits);
        if let Ok(table) = parse_states(&text, N_STATES) {
            prop_assert!(table.rows.iter().all(|r| r.len() == N_STATES));
            prop_assert!(table.rows.iter().flatten().all(|v| v.is_finite()));
            prop_assert_eq!(table.extras.len(), table.rows.len());
        }
        if let Ok(gaps) = parse_states_with_gaps(&text, N_STATES) {
            prop_assert!(gaps.table.rows.iter().all(|r| r.len() == N_STATES));
            prop_assert_eq!(gaps.extra_text.len(), gaps.table.rows.len());
            for frame in gaps.gap_frames() {
                prop_assert!(gaps.table.rows[frame].iter().any(|v| !v.is_finite()));
            }
        }
    }

    /// A mutated hypotheses CSV is read or refused; what is read ascends by frame, ranks
    /// run 0, 1, 2, … within a frame below the capacity, and every number is finite.
    #[test]
    fn a_mutated_hypotheses_csv_is_read_or_refused(edits in prop::collection::vec(edit(), 1..8)) {
        let text = apply(&hypotheses_text(), &edits);
        if let Ok(table) = parse_hypotheses(&text, N_STATES) {
            for pair in table.rows.windows(2) {
                let (a, b) = (&pair[0], &pair[1]);
                prop_assert!(
                    (b.frame == a.frame && b.rank == a.rank + 1) || (b.frame > a.frame && b.rank == 0)
                );
            }
            prop_assert!(table.rows.iter().all(|r| r.rank < MAX_HYPOTHESES));
            prop_assert!(table.rows.iter().all(|r| r.state.len() == N_STATES
                && r.score.is_finite()
                && r.state.iter().all(|v| v.is_finite())));
        }
    }
}

/// The seeds themselves are read: a mutation test whose seed were refused would test nothing.
#[test]
fn the_unmutated_files_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sequence.json");
    fs::write(&path, SEQUENCE_JSON).unwrap();
    let sequence = Sequence::open_description(&path).unwrap();
    sequence.check_cameras_see_the_hand(&[0]).unwrap();
    assert_eq!(parse_states(TRUTH_CSV, N_STATES).unwrap().rows.len(), 12);
    let table = parse_hypotheses(&hypotheses_text(), N_STATES).unwrap();
    assert_eq!(table.rows.len(), (0..12).map(|f| 1 + f % 3).sum::<usize>());
    assert_eq!(
        apply("a 12 b -3.5e2", &[Edit::Number(1, "7".into())]),
        "a 12 b 7",
        "the number edit replaces a whole number"
    );
}
