//! A holding board (one board per camera, issue 13): `Hold` refused before `Configure`; a
//! held frame measured at the host's state gives exactly the features the in-process search
//! finds there, narrowed on later iterations as the tracker narrows them; a frame it does
//! not hold is said so; `Reset` makes it track again.

mod common;

use common::*;
use digiteyes_core::features::LinkFeatures;
use digiteyes_core::frame::FrameView;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::palm_outline::{HullEdge, PalmOutline};
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::protocol::*;
use digiteyes_core::search::CameraSearch;
use digiteyes_core::tracker::TrackerConfig;
use digiteyes_firmware::{Board, NoLed, Uploads};

const FRAME_BYTES: usize = (WIDTH * HEIGHT) as usize;

fn board(buffer: &mut [u8]) -> Board<'_, Pipe, Uploads, NoLed, StepClock> {
    let mut board = test_board("test", buffer);
    board.start().unwrap();
    board.serial_mut().received();
    board
}

fn configure() -> HostMessage<'static> {
    HostMessage::Configure(Configure::new(
        CameraParams::from_camera(&camera()).unwrap(),
        TrackerParams::default(),
    ))
}

fn measure(frame: u32, iteration: u8, q: &[f32]) -> HostMessage<'static> {
    HostMessage::Measure(Measure {
        frame,
        iteration,
        q: q.iter().copied().collect(),
    })
}

/// Each link's place in view, model frame and features.
type LinkAnswers = Vec<(u8, u8, LinkFeatures)>;
/// Each palm outline edge and its features.
type PalmAnswers = Vec<(HullEdge, LinkFeatures)>;

/// The in-process search of every link at `q`, as the tracker runs it for one camera, then
/// of every palm outline edge.
fn in_process(
    model: &Model,
    pixels: &[u8],
    q: &[f32],
    search: &mut CameraSearch,
    refine: bool,
) -> (LinkAnswers, PalmAnswers) {
    let config = TrackerConfig::default();
    let cam = camera();
    let poses = Poses::compute(model, q).unwrap();
    let mut view = ProjectedModel::new();
    view.update(model, &poses, &cam, config.features.min_link_px);
    let frame = FrameView::packed(pixels, WIDTH as usize, HEIGHT as usize).unwrap();
    let mut out = Vec::new();
    for index in 0..view.links.len() {
        let mut f = LinkFeatures::default();
        search.link(&view, &cam, &frame, index, &config.features, refine, &mut f);
        out.push((index as u8, view.links[index].frame, f));
    }
    let mut outline = PalmOutline::new();
    outline.update(view.palm.as_ref(), config.features.min_link_px);
    let mut palm = Vec::new();
    for edge in &outline.edges {
        let mut f = LinkFeatures::default();
        search.palm_edge(&view, &cam, &frame, edge, &config.features, refine, &mut f);
        palm.push((*edge, f));
    }
    (out, palm)
}

#[test]
fn hold_before_configure_is_refused() {
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = board(&mut buffer);
    board.serial_mut().send(&HostMessage::Hold);
    board.poll().unwrap();
    assert_eq!(
        board.serial_mut().received(),
        [BoardMessage::Nak(Command::Hold, Refusal::NotConfigured)]
    );
}

#[test]
fn a_held_frame_is_measured_as_the_in_process_search_finds_it() {
    let model = Model::hand().unwrap();
    let truth = pose(&model, 0.3);
    let guess = pose(&model, 0.25);
    let pixels = render(&model, &camera(), &truth);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = board(&mut buffer);
    board.serial_mut().send(&configure());
    board.serial_mut().send(&HostMessage::Hold);
    board.poll().unwrap();
    assert_eq!(
        board.serial_mut().received(),
        [
            BoardMessage::Ack(Command::Configure),
            BoardMessage::Ack(Command::Hold)
        ]
    );
    board
        .serial_mut()
        .send_frame(7, WIDTH as u16, HEIGHT as u16, &pixels);
    board.poll().unwrap();
    assert_eq!(
        board.serial_mut().received(),
        [],
        "a held frame is not tracked"
    );

    let mut search = CameraSearch::new();
    for iteration in 0..3u8 {
        board.serial_mut().send(&measure(7, iteration, &guess));
        board.poll().unwrap();
        let replies = board.serial_mut().received();
        let (reference, palm) = in_process(&model, &pixels, &guess, &mut search, iteration > 0);
        let m = Measure {
            frame: 7,
            iteration,
            q: guess.iter().copied().collect(),
        };
        let mut expected: Vec<BoardMessage> = reference
            .iter()
            .map(|(index, link, f)| LinkEdges::from_features(&m, *index, *link, f))
            .filter(|e| !e.is_empty())
            .map(BoardMessage::LinkEdges)
            .collect();
        let palm_answers: Vec<BoardMessage> = palm
            .iter()
            .map(|(edge, f)| PalmEdges::from_features(&m, edge, f))
            .filter(|e| !e.is_empty())
            .map(BoardMessage::PalmEdges)
            .collect();
        assert!(
            !palm_answers.is_empty(),
            "the palm's outline is measured too"
        );
        expected.extend(palm_answers);
        let (last, edges) = replies.split_last().expect("an answer");
        let BoardMessage::Measured(done) = last else {
            panic!("ends with Measured: {last:?}");
        };
        assert!(done.held);
        assert_eq!((done.frame, done.iteration), (7, iteration));
        assert_eq!(usize::from(done.links), edges.len());
        assert!(done.silhouette.is_some_and(|s| s > 0.5), "{done:?}");
        assert_eq!(edges.len(), expected.len(), "iteration {iteration}");
        let mut found = 0;
        for (got, want) in edges.iter().zip(&expected) {
            assert_eq!(got, want, "iteration {iteration}");
            match got {
                BoardMessage::LinkEdges(e) => found += e.edges.len(),
                BoardMessage::PalmEdges(_) => {}
                other => panic!("LinkEdges and PalmEdges before Measured: {other:?}"),
            }
        }
        assert!(found > 20, "the frame shows the hand: {found} edges");
    }

    // Another frame number: not held. Then Reset: tracking again.
    board.serial_mut().send(&measure(8, 0, &guess));
    board.poll().unwrap();
    let replies = board.serial_mut().received();
    assert!(
        matches!(&replies[..], [BoardMessage::Measured(m)] if !m.held && m.links == 0),
        "{replies:?}"
    );
    board.serial_mut().send(&HostMessage::Reset(Reset {
        q: guess.iter().copied().collect(),
        free: 0b111_0000,
        start: Start::Given,
    }));
    board
        .serial_mut()
        .send_frame(9, WIDTH as u16, HEIGHT as u16, &pixels);
    board.poll().unwrap();
    let replies = board.serial_mut().received();
    assert!(
        matches!(replies.last(), Some(BoardMessage::State(s)) if s.frame == 9),
        "{replies:?}"
    );
}
