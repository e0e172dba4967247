//! The `hand.dh` parser and writer: the built-in hand against `docs/hand-model.md`, round trips, and
//! every error path of `ModelErrorKind` with the line it is reported on.

use digiteyes_core::config::{MAX_CHAIN, MAX_LINKS, MAX_NAME_LEN, MAX_STATES};
use digiteyes_core::model::{
    Limit, Model, ModelError, ModelErrorKind, Shape, Theta, BASE_STATES, DEFAULT_BOX_CENTRE,
    HAND_DH,
};
use digiteyes_core::model_writer::write_dh;

/// The published table as data (no `limit` rows), kept apart from `models/hand.dh` so the
/// built-in model is checked against an independent copy (`fixtures/README.md`).
const SPEC_HAND_DH: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../fixtures/hand-published.dh"
));

fn hand() -> Model {
    Model::hand().expect("built-in hand parses")
}

fn written(model: &Model) -> String {
    let mut text = String::new();
    write_dh(model, &mut text).expect("writing to a String cannot fail");
    text
}

fn error(text: &str) -> ModelError {
    match Model::parse(text) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e,
    }
}

#[track_caller]
fn assert_error(text: &str, line: u32, kind: ModelErrorKind) {
    let e = error(text);
    assert_eq!(e, ModelError { line, kind }, "text:\n{text}");
    let shown = e.to_string();
    assert!(
        shown.contains(&format!("line {line}")),
        "`{shown}` does not mention line {line}"
    );
}

// ---------------------------------------------------------------------------------------------
// The built-in whole-hand model against docs/hand-model.md.

#[test]
fn hand_has_37_frames_and_28_states() {
    let m = hand();
    assert_eq!(m.links().len(), 37);
    assert_eq!(m.n_states(), 28);
    assert_eq!(m.links()[0].theta, Theta::Base);
}

#[test]
fn hand_names_sit_on_the_corrected_frames() {
    // docs/hand-model.md: proximal phalanges on the MCP frames 4, 11, 18, 25 (thumb 32), Thumb Link 1
    // on frame 34; each finger is link0, link1, link2, tip on consecutive frames.
    let m = hand();
    assert_eq!(m.find("palm"), Some(0));
    for (k, first) in [4usize, 11, 18, 25].into_iter().enumerate() {
        let f = k + 1;
        assert_eq!(m.find(&format!("finger{f}.link0")), Some(first));
        assert_eq!(m.find(&format!("finger{f}.link1")), Some(first + 1));
        assert_eq!(m.find(&format!("finger{f}.link2")), Some(first + 2));
        assert_eq!(m.find(&format!("finger{f}.tip")), Some(first + 3));
    }
    assert_eq!(m.find("thumb.link0"), Some(32));
    assert_eq!(m.find("thumb.link1"), Some(34));
    assert_eq!(m.find("thumb.link2"), Some(35));
    assert_eq!(m.find("thumb.tip"), Some(36));
    assert_eq!(m.find("finger5.link0"), None);
    // The constant frames inside the palm carry no name and no geometry.
    for f in [1, 2, 3, 8, 9, 10, 15, 16, 17, 22, 23, 24, 29, 30, 31, 33] {
        assert_eq!(m.links()[f].name.as_str(), "-", "frame {f}");
        assert_eq!(m.links()[f].shape, Shape::None, "frame {f}");
    }
}

#[test]
fn hand_joint_frames_follow_table_order() {
    let m = hand();
    for s in 0..BASE_STATES {
        assert_eq!(m.joint_frame(s), None, "palm state q{s} is not a joint");
    }
    // Finger k (0-based): abduction on frame 3 + 7k, then MCP, PIP, DIP on the next three.
    for k in 0..4 {
        for j in 0..4 {
            assert_eq!(m.joint_frame(7 + 4 * k + j), Some(3 + 7 * k + j));
        }
    }
    // Thumb q23..q27 (docs/hand-model.md's correction of the repeated q25).
    for (s, f) in [(23, 31), (24, 32), (25, 33), (26, 34), (27, 35)] {
        assert_eq!(m.joint_frame(s), Some(f), "q{s}");
        assert_eq!(m.links()[f].theta, Theta::State(s as u8));
    }
    assert_eq!(m.joint_frame(28), None);
    assert_eq!(m.joint_frame(MAX_STATES + 5), None);
}

#[test]
fn hand_chains_list_the_joints_root_first() {
    let m = hand();
    assert_eq!(m.chain(7).unwrap().as_slice(), &[7, 8, 9, 10]);
    assert_eq!(m.chain(6).unwrap().as_slice(), &[7, 8, 9, 10]);
    assert_eq!(m.chain(4).unwrap().as_slice(), &[7, 8]);
    assert_eq!(m.chain(28).unwrap().as_slice(), &[19, 20, 21, 22]);
    assert_eq!(m.chain(36).unwrap().as_slice(), &[23, 24, 25, 26, 27]);
    assert_eq!(m.chain(0).unwrap().as_slice(), &[] as &[u8]);
    assert_eq!(m.chain(2).unwrap().as_slice(), &[] as &[u8]);
    assert!(m.chain(37).is_none(), "no frame 37");
}

#[test]
fn hand_tree_shape() {
    let m = hand();
    let links = m.links();
    assert_eq!(links[0].parent, None);
    assert_eq!(links[0].children.as_slice(), &[1, 8, 15, 22, 29]);
    for f in 1..37 {
        let p = usize::from(
            links[f]
                .parent
                .expect("every frame but the palm has a parent"),
        );
        assert!(links[p].children.contains(&(f as u8)), "frame {f}");
    }
    for tip in [7, 14, 21, 28, 36] {
        assert!(links[tip].children.is_empty());
    }
    // `order` visits every frame once, each after its parent.
    let order = m.order();
    assert_eq!(order.len(), 37);
    let position = |f: usize| order.iter().position(|&o| usize::from(o) == f).unwrap();
    for (f, link) in links.iter().enumerate().skip(1) {
        let p = usize::from(link.parent.unwrap());
        assert!(position(p) < position(f), "frame {f} before its parent {p}");
    }
}

#[test]
fn hand_shapes() {
    let m = hand();
    let links = m.links();
    // Palm box 56 x 86 x 15 centred at (2.5, -9, 0): x in [-25.5, 30.5], y in [-52, 34].
    let Shape::Box { size, centre } = links[0].shape else {
        panic!("palm is a box")
    };
    assert_eq!(size, [56.0, 86.0, 15.0]);
    assert_eq!(centre, DEFAULT_BOX_CENTRE);
    assert_eq!(centre[0] - size[0] / 2.0, -25.5);
    assert_eq!(centre[0] + size[0] / 2.0, 30.5);
    assert_eq!(centre[1] - size[1] / 2.0, -52.0);
    assert_eq!(centre[1] + size[1] / 2.0, 34.0);
    // Cylinders on the link frames, tips on the tip frames; the thumb's distal radius is the
    // assumed 9 mm.
    for f in [4, 5, 6, 11, 12, 13, 18, 19, 20, 25, 26, 27, 32, 34, 35] {
        assert!(
            matches!(links[f].shape, Shape::Cylinder { .. }),
            "frame {f}"
        );
        assert!(
            links[f].a > 0.0,
            "a cylinder's frame carries the link length"
        );
    }
    for f in [7, 14, 21, 28, 36] {
        assert!(matches!(links[f].shape, Shape::Tip { .. }), "frame {f}");
    }
    assert_eq!(links[35].shape, Shape::Cylinder { radius: 9.0 });
    assert_eq!(links[4].a, 45.0);
    assert_eq!(links[32].shape, Shape::Cylinder { radius: 14.0 });
    // Constants: pi/2 and -pi/2 are the f32 values of +-PI/2.
    assert_eq!(links[1].theta, Theta::Const(core::f32::consts::FRAC_PI_2));
    assert_eq!(links[1].alpha, -core::f32::consts::FRAC_PI_2);
    assert_eq!(links[30].theta, Theta::Const(-core::f32::consts::PI));
}

#[test]
fn hand_limits_match_hand_model_md() {
    let m = hand();
    let finger = [(-0.35, 0.35), (0.0, 1.4), (0.0, 1.6), (0.0, 1.2)];
    for k in 0..4 {
        for (j, &(lo, hi)) in finger.iter().enumerate() {
            // The index's MCP (q8) extends to -0.5 rad: the 3D mouse's raised finger.
            let lo = if (k, j) == (0, 1) { -0.5 } else { lo };
            assert_eq!(
                m.limit(7 + 4 * k + j),
                Some(Limit { lo, hi }),
                "q{}",
                7 + 4 * k + j
            );
        }
    }
    let thumb = [
        (0.0, 0.8),
        (-0.6, 0.3),
        (-0.3, 0.3),
        (-0.9, 0.1),
        (-1.2, 0.1),
    ];
    for (j, &(lo, hi)) in thumb.iter().enumerate() {
        assert_eq!(m.limit(23 + j), Some(Limit { lo, hi }), "q{}", 23 + j);
    }
    for s in 0..BASE_STATES {
        assert_eq!(m.limit(s), None);
    }
    assert_eq!(m.limit(28), None);
    assert_eq!(m.limit(1000), None);
}

#[test]
fn set_limit_accepts_joints_only() {
    let mut m = hand();
    assert!(
        !m.set_limit(3, Some(Limit { lo: 0.0, hi: 1.0 })),
        "palm state"
    );
    assert!(
        !m.set_limit(28, Some(Limit { lo: 0.0, hi: 1.0 })),
        "no such state"
    );
    assert_eq!(m.limit(3), None);
    assert!(m.set_limit(8, None));
    assert_eq!(m.limit(8), None);
    assert!(m.set_limit(8, Some(Limit { lo: -0.1, hi: 0.2 })));
    assert_eq!(m.limit(8), Some(Limit { lo: -0.1, hi: 0.2 }));
}

#[test]
fn spec_table_is_the_builtin_without_limits() {
    let spec = Model::parse(SPEC_HAND_DH).expect("the spec's hand.dh parses");
    let mut builtin = hand();
    for s in BASE_STATES..builtin.n_states() {
        assert!(builtin.set_limit(s, None));
    }
    // Equality covers every field, including each row's source line (the two files share
    // their header, so the rows sit on the same lines).
    assert_eq!(spec, builtin);
}

// ---------------------------------------------------------------------------------------------
// Writer round trips.

#[test]
fn builtin_round_trips_through_text() {
    let m = hand();
    let text = written(&m);
    let back = Model::parse(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(back, m);
    // Writing is deterministic: the second generation's text is the first's.
    assert_eq!(written(&back), text);
    assert_eq!(text.lines().filter(|l| l.starts_with("limit ")).count(), 21);
}

#[test]
fn writer_writes_exact_pi_multiples_symbolically() {
    let text = written(&hand());
    let row = |f: usize| {
        text.lines()
            .find(|l| l.split_whitespace().next() == Some(&f.to_string()))
            .unwrap()
            .split_whitespace()
            .collect::<Vec<_>>()
    };
    assert_eq!(row(1)[2..6], ["pi/2", "0", "38", "-pi/2"]);
    assert_eq!(row(30)[2..6], ["-pi", "38", "0", "0"]);
    // A value near, but not exactly, pi/2 stays a decimal (and still round-trips).
    let m = Model::parse("0 palm base 0 0 1.5707963 - 1\n1 a 2*pi/3 0 0 3*pi/4 - -").unwrap();
    let out = written(&m);
    assert!(out.contains("1.5707963") && !out.contains("pi/2"), "{out}");
    assert!(out.contains("2*pi/3") && out.contains("3*pi/4"), "{out}");
    assert_eq!(Model::parse(&out).unwrap(), m);
}

#[test]
fn spec_table_round_trips_through_text() {
    let m = Model::parse(SPEC_HAND_DH).unwrap();
    let text = written(&m);
    assert!(!text.contains("limit"), "no limits to write:\n{text}");
    assert_eq!(Model::parse(&text).unwrap(), m);
}

#[test]
fn box_centre_is_written_only_when_not_the_default() {
    let m = Model::parse("0 palm base 0 0 0 box 1 2 3 -").unwrap();
    assert!(!written(&m).contains(" at "));

    let m = Model::parse("0 palm base 0 0 0 box 1 2 3 at -0.5 0 7.25 -").unwrap();
    assert_eq!(
        m.links()[0].shape,
        Shape::Box {
            size: [1.0, 2.0, 3.0],
            centre: [-0.5, 0.0, 7.25]
        }
    );
    let text = written(&m);
    assert!(text.contains("at -0.5 0 7.25"), "{text}");
    assert_eq!(Model::parse(&text).unwrap(), m);
}

#[test]
fn awkward_numbers_round_trip_exactly() {
    let text = "\
# constants whose decimal forms are long, tiny, huge or negative zero
0 palm base 1e-3 2*pi/3 -0 box 0.1 300000 0.000001 at 1e-7 -123456.79 3 1 2
1 a -pi/7 -0.0000001 16777217 pi*pi cyl 0.3 -
2 b q7 1.1754944e-38 0.1 -2*pi tip 1e-38 -
limit q7 -3.4028235e38 3.4028235e38
";
    let m = Model::parse(text).unwrap();
    let out = written(&m);
    let back = Model::parse(&out).unwrap_or_else(|e| panic!("{e}\n{out}"));
    assert_eq!(back, m, "{out}");
    // Bitwise, not just ==, for the values where it matters (-0 == 0 under ==).
    assert_eq!(
        back.links()[0].alpha.to_bits(),
        m.links()[0].alpha.to_bits()
    );
    assert_eq!(back.links()[2].d.to_bits(), m.links()[2].d.to_bits());
}

#[test]
fn writer_keeps_row_lines_and_limits_after_the_frames() {
    // Rows parsed from lines 3, 4, 7 come back on lines 3, 4, 7; a limit given between rows
    // is written after the last frame, where it is still valid.
    let text = "\n# comment\n0 palm base 0 0 0 - 1\n1 a q7 0 10 0 cyl 5 2\nlimit q7 0 1\n\n2 b 0 0 0 0 tip 4 -\n";
    let m = Model::parse(text).unwrap();
    assert_eq!(
        m.links().iter().map(|l| l.line).collect::<Vec<_>>(),
        vec![3, 4, 7]
    );
    let out = written(&m);
    let lines: Vec<&str> = out.lines().collect();
    assert!(lines[2].starts_with("0 "), "{out}");
    assert!(lines[3].starts_with("1 "), "{out}");
    assert!(lines[6].starts_with("2 "), "{out}");
    assert!(lines.last().unwrap().starts_with("limit q7"), "{out}");
    assert_eq!(Model::parse(&out).unwrap(), m);
}

#[test]
fn writer_writes_limits_set_after_parsing() {
    let mut m = hand();
    assert!(m.set_limit(9, None));
    assert!(m.set_limit(
        25,
        Some(Limit {
            lo: -0.25,
            hi: 0.125
        })
    ));
    let back = Model::parse(&written(&m)).unwrap();
    assert_eq!(back.limit(9), None);
    assert_eq!(
        back.limit(25),
        Some(Limit {
            lo: -0.25,
            hi: 0.125
        })
    );
    assert_eq!(back, m);
}

#[test]
fn writer_works_without_allocation() {
    // Any fmt::Write sink: a fixed-capacity heapless string big enough for the hand.
    let mut text: heapless::String<8192> = heapless::String::new();
    write_dh(&hand(), &mut text).unwrap();
    assert_eq!(Model::parse(&text).unwrap(), hand());
    // A sink that fills up reports the error instead of panicking.
    let mut small: heapless::String<64> = heapless::String::new();
    assert!(write_dh(&hand(), &mut small).is_err());
}

// ---------------------------------------------------------------------------------------------
// Error paths: one small text per kind, with the line it must be reported on.

/// A valid three-frame model (palm, one joint, a tip) on lines 1..3.
const TINY: &str = "0 palm base 0 0 0 - 1\n1 a q7 0 10 0 cyl 5 2\n2 a.tip 0 0 0 0 tip 4 -\n";

#[test]
fn tiny_model_is_valid() {
    let m = Model::parse(TINY).unwrap();
    assert_eq!(m.links().len(), 3);
    assert_eq!(m.n_states(), 8);
    assert_eq!(m.chain(2).unwrap().as_slice(), &[7]);
}

#[test]
fn missing_field() {
    use ModelErrorKind::MissingField;
    assert_error("0 palm base", 1, MissingField("d"));
    assert_error("\n0", 2, MissingField("name"));
    assert_error("0 palm base 0 0 0 -", 1, MissingField("next"));
    assert_error("0 palm base 0 0 0 box 1 2", 1, MissingField("box z"));
    assert_error(
        "0 palm base 0 0 0 box 1 2 3 at 1 2",
        1,
        MissingField("box centre"),
    );
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a q7 0 10 0 cyl",
        2,
        MissingField("radius"),
    );
    assert_error(&format!("{TINY}limit q7 0"), 4, MissingField("hi"));
    assert_error(&format!("{TINY}limit"), 4, MissingField("limit state"));
}

#[test]
fn unknown_token() {
    use ModelErrorKind::UnknownToken;
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a foo 0 0 0 - -",
        2,
        UnknownToken("theta"),
    );
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a q7x 0 0 0 - -",
        2,
        UnknownToken("theta"),
    );
    assert_error("0 palm base 0 0 0 sphere 3 -", 1, UnknownToken("shape"));
    assert_error(
        "0 palm base 0 0 0 cyl 3 at 1 2 3 -",
        1,
        UnknownToken("shape"),
    );
    assert_error("0 palm base 0 0 0 - one", 1, UnknownToken("next"));
    assert_error("0 palm base x 0 0 - -", 1, UnknownToken("d"));
    assert_error(
        &format!("{TINY}limit x7 0 1"),
        4,
        UnknownToken("limit state"),
    );
    assert_error(&format!("{TINY}limit q7 nan 1"), 4, UnknownToken("lo"));
}

#[test]
fn bad_number() {
    use ModelErrorKind::BadNumber;
    assert_error("x palm base 0 0 0 - -", 1, BadNumber("frame"));
    assert_error("0 palm base 1.2.3 0 0 - -", 1, BadNumber("d"));
    assert_error("0 palm base 0 1e39 0 - -", 1, BadNumber("a"));
    assert_error("0 palm base 0 0 pi/0 - -", 1, BadNumber("alpha"));
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a 1e30*1e30 0 0 0 - -",
        2,
        BadNumber("theta"),
    );
    assert_error(
        "0 palm base 0 0 0 box 1 0 1 -",
        1,
        ModelErrorKind::NotPositive("box y"),
    );
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a 0 0 0 0 cyl -2 -",
        2,
        ModelErrorKind::NotPositive("radius"),
    );
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a 0 0 0 0 cyl abc -",
        2,
        ModelErrorKind::UnknownToken("radius"),
    );
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a 0 0 0 0 tip 0 -",
        2,
        ModelErrorKind::NotPositive("radius"),
    );
    assert_error(&format!("{TINY}limit q7 0 1e40"), 4, BadNumber("hi"));
}

#[test]
fn trailing_tokens() {
    use ModelErrorKind::TrailingTokens;
    assert_error("0 palm base 0 0 0 - - 1", 1, TrailingTokens);
    assert_error(&format!("{TINY}limit q7 0 1 2"), 4, TrailingTokens);
}

#[test]
fn frame_out_of_order() {
    use ModelErrorKind::FrameOutOfOrder;
    assert_error("1 palm base 0 0 0 - -", 1, FrameOutOfOrder { expected: 0 });
    assert_error(
        "0 palm base 0 0 0 - 2\n\n2 a 0 0 0 0 - -",
        3,
        FrameOutOfOrder { expected: 1 },
    );
    // A repeated frame number.
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a 0 0 0 0 - -\n1 b 0 0 0 0 - -",
        3,
        FrameOutOfOrder { expected: 2 },
    );
}

#[test]
fn state_out_of_order() {
    use ModelErrorKind::StateOutOfOrder;
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a q8 0 0 0 - -",
        2,
        StateOutOfOrder { expected: 7 },
    );
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a q3 0 0 0 - -",
        2,
        StateOutOfOrder { expected: 7 },
    );
    // The extracted Appendix A's defect: frame 34 repeats q25 (docs/hand-model.md).
    let row34 = SPEC_HAND_DH
        .lines()
        .position(|l| l.starts_with("34 "))
        .unwrap();
    let bad: String = SPEC_HAND_DH
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == row34 {
                l.replacen("q26", "q25", 1) + "\n"
            } else {
                l.to_string() + "\n"
            }
        })
        .collect();
    assert_error(&bad, row34 as u32 + 1, StateOutOfOrder { expected: 26 });
}

#[test]
fn base_not_first() {
    use ModelErrorKind::BaseNotFirst;
    assert_error("0 palm 0 0 0 0 - -", 1, BaseNotFirst);
    assert_error("0 palm q0 0 0 0 - -", 1, BaseNotFirst);
    assert_error("0 palm base 0 0 0 - 1\n1 a base 0 0 0 - -", 2, BaseNotFirst);
}

#[test]
fn missing_frame_in_next() {
    use ModelErrorKind::MissingFrame;
    // Named frame beyond the table (found after all rows are read): reported on the naming row.
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a 0 0 0 0 - 5\n2 b 0 0 0 0 - -",
        2,
        MissingFrame { frame: 5 },
    );
    // Beyond any model's capacity: reported while reading the row, naming the limit.
    assert_error(
        "0 palm base 0 0 0 - 200",
        1,
        ModelErrorKind::FrameBeyondLimit { frame: 200 },
    );
}

#[test]
fn two_parents() {
    use ModelErrorKind::TwoParents;
    assert_error(
        "0 palm base 0 0 0 - 1 2\n1 a 0 0 0 0 - 2\n2 b 0 0 0 0 - -",
        2,
        TwoParents { frame: 2 },
    );
    // The same child twice in one `next`.
    assert_error(
        "0 palm base 0 0 0 - 1 1\n1 a 0 0 0 0 - -",
        1,
        TwoParents { frame: 1 },
    );
}

#[test]
fn cycle() {
    use ModelErrorKind::Cycle;
    // 1 -> 2 -> 1, detached from the palm: each has one parent, yet neither is reached.
    assert_error(
        "0 palm base 0 0 0 - -\n1 a 0 0 0 0 - 2\n2 b 0 0 0 0 - 1",
        2,
        Cycle { frame: 1 },
    );
    // A frame naming itself, and a frame naming the palm.
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a 0 0 0 0 - 1",
        2,
        Cycle { frame: 1 },
    );
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a 0 0 0 0 - 0",
        2,
        Cycle { frame: 0 },
    );
}

#[test]
fn unreachable() {
    use ModelErrorKind::Unreachable;
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a 0 0 0 0 - -\n\n2 b 0 0 0 0 - -",
        4,
        Unreachable { frame: 2 },
    );
}

/// A chain palm -> 1 -> ... -> n-1 of constant frames, one per line.
fn constant_chain(n: usize) -> String {
    let mut text = String::from("0 palm base 0 0 0 - 1\n");
    for f in 1..n {
        let next = if f + 1 < n {
            (f + 1).to_string()
        } else {
            "-".into()
        };
        text += &format!("{f} l{f} 0 0 1 0 - {next}\n");
    }
    text
}

#[test]
fn too_many_frames() {
    assert!(
        Model::parse(&constant_chain(MAX_LINKS)).is_ok(),
        "exactly MAX_LINKS fit"
    );
    // One row more (unreferenced: naming frame MAX_LINKS in a `next` is FrameBeyondLimit).
    let text = constant_chain(MAX_LINKS) + &format!("{MAX_LINKS} extra 0 0 0 0 - -\n");
    assert_error(&text, MAX_LINKS as u32 + 1, ModelErrorKind::TooManyFrames);
    // A chain of MAX_LINKS + 1 frames: its last `next` names frame MAX_LINKS, and the
    // message says why that cannot be, not that the frame is missing.
    let text = constant_chain(MAX_LINKS + 1);
    let e = error(&text);
    assert_eq!(
        e.kind,
        ModelErrorKind::FrameBeyondLimit {
            frame: MAX_LINKS as u16
        }
    );
    assert!(
        e.to_string()
            .contains(&format!("at most {MAX_LINKS} frames")),
        "{e}"
    );
}

/// A palm with `n` joint frames q7.. hanging from it in a straight chain.
fn joint_chain(n: usize) -> String {
    let mut text = String::from("0 palm base 0 0 0 - 1\n");
    for k in 0..n {
        let f = k + 1;
        let next = if k + 1 < n {
            (f + 1).to_string()
        } else {
            "-".into()
        };
        text += &format!("{f} j{f} q{} 0 10 0 - {next}\n", 7 + k);
    }
    text
}

/// A palm with `n` joint frames q7.. as short branches of at most MAX_CHAIN joints.
fn joint_branches(n: usize) -> String {
    let mut text = String::from("0 palm base 0 0 0 -");
    let mut rows = String::new();
    let mut k = 0;
    while k < n {
        let len = (n - k).min(MAX_CHAIN);
        text += &format!(" {}", k + 1);
        for j in 0..len {
            let f = k + j + 1;
            let next = if j + 1 < len {
                (f + 1).to_string()
            } else {
                "-".into()
            };
            rows += &format!("{f} j{f} q{} 0 10 0 - {next}\n", 7 + k + j);
        }
        k += len;
    }
    text + "\n" + &rows
}

#[test]
fn too_many_states() {
    let most = MAX_STATES - BASE_STATES;
    let m = Model::parse(&joint_branches(most)).expect("MAX_STATES states fit");
    assert_eq!(m.n_states(), MAX_STATES);
    // One more joint state, in order: reported on its row (frame `most + 1`, line `most + 2`).
    assert_error(
        &joint_branches(most + 1),
        most as u32 + 2,
        ModelErrorKind::TooManyStates,
    );
    // A state number beyond capacity on its own.
    assert_error(
        "0 palm base 0 0 0 - 1\n1 a q99 0 0 0 - -",
        2,
        ModelErrorKind::TooManyStates,
    );
}

#[test]
fn too_many_children() {
    assert_error(
        "0 palm base 0 0 0 - 1 2 3 4 5 6 7",
        1,
        ModelErrorKind::TooManyChildren,
    );
}

#[test]
fn chain_too_deep() {
    assert!(
        Model::parse(&joint_chain(MAX_CHAIN)).is_ok(),
        "MAX_CHAIN joints fit"
    );
    // The first frame whose chain is too long is joint MAX_CHAIN + 1, on line MAX_CHAIN + 2.
    assert_error(
        &joint_chain(MAX_CHAIN + 1),
        MAX_CHAIN as u32 + 2,
        ModelErrorKind::ChainTooDeep,
    );
}

#[test]
fn name_too_long() {
    let fits = "n".repeat(MAX_NAME_LEN);
    assert!(Model::parse(&format!("0 {fits} base 0 0 0 - -")).is_ok());
    let long = "n".repeat(MAX_NAME_LEN + 1);
    assert_error(
        &format!("0 palm base 0 0 0 - 1\n1 {long} 0 0 0 0 - -"),
        2,
        ModelErrorKind::NameTooLong,
    );
}

#[test]
fn bad_limit() {
    use ModelErrorKind::BadLimit;
    assert_error(&format!("{TINY}limit q7 1 0"), 4, BadLimit); // lo > hi
    assert_error(&format!("{TINY}limit q3 0 1"), 4, BadLimit); // a palm state
    assert_error(&format!("{TINY}limit q8 0 1"), 4, BadLimit); // no such state
                                                               // A limit before the row that introduces its state.
    assert_error(
        "0 palm base 0 0 0 - 1\nlimit q7 0 1\n1 a q7 0 10 0 - -",
        2,
        BadLimit,
    );
    assert!(
        Model::parse(&format!("{TINY}limit q7 0.5 0.5")).is_ok(),
        "lo == hi is a range"
    );
}

#[test]
fn empty() {
    assert_eq!(error("").kind, ModelErrorKind::Empty);
    // Only comments and blank lines: reported at the end of the text.
    assert_error(
        "# just a comment\n\n   # and another",
        3,
        ModelErrorKind::Empty,
    );
    // Limits alone are not frames (and name no state).
    assert_eq!(error("limit q7 0 1").kind, ModelErrorKind::BadLimit);
}

#[test]
fn comments_and_whitespace_are_ignored() {
    let text = "  # header\n\t0 palm base 0 0 0 - 1 # the palm\n\n1   a\tq7 0 10 0 cyl 5 2\n2 a.tip 0 0 0 0 tip 4 -   ";
    let m = Model::parse(text).unwrap();
    assert_eq!(m.links().len(), 3);
    assert_eq!(m.links()[1].line, 4);
}

#[test]
fn every_error_kind_displays_its_line() {
    let kinds = [
        ModelErrorKind::MissingField("d"),
        ModelErrorKind::UnknownToken("theta"),
        ModelErrorKind::BadNumber("a"),
        ModelErrorKind::TrailingTokens,
        ModelErrorKind::FrameOutOfOrder { expected: 3 },
        ModelErrorKind::StateOutOfOrder { expected: 26 },
        ModelErrorKind::BaseNotFirst,
        ModelErrorKind::MissingFrame { frame: 9 },
        ModelErrorKind::TwoParents { frame: 9 },
        ModelErrorKind::Cycle { frame: 9 },
        ModelErrorKind::Unreachable { frame: 9 },
        ModelErrorKind::TooManyFrames,
        ModelErrorKind::TooManyStates,
        ModelErrorKind::TooManyChildren,
        ModelErrorKind::ChainTooDeep,
        ModelErrorKind::NameTooLong,
        ModelErrorKind::BadLimit,
        ModelErrorKind::Empty,
    ];
    for kind in kinds {
        let shown = ModelError { line: 4711, kind }.to_string();
        assert!(shown.starts_with("line 4711: "), "{shown}");
        assert!(shown.len() > "line 4711: ".len() + 5, "{shown}");
    }
    let shown = ModelError {
        line: 1,
        kind: ModelErrorKind::StateOutOfOrder { expected: 26 },
    }
    .to_string();
    assert!(shown.contains("q26"), "{shown}");
}

#[test]
fn builtin_constant_is_the_models_file() {
    // HAND_DH is the shipped model file: it parses to the same model as Model::hand().
    assert_eq!(Model::parse(HAND_DH).unwrap(), hand());
}
