//! Wall time of the tracker: one Gauss–Newton iteration and one whole frame for the
//! `mouse`, `fullhand-mono` and `fullhand-stereo` scenarios, and each Table 4.1 stage on its
//! own for the whole hand seen by one camera.
//!
//! Every case renders its scenario (seed [`support::SEED`], frames 0 and 1) into a temporary
//! folder, starts the tracker at the truth of frame 0 and tracks frame 1, so the iteration does
//! real work (the hand has moved). Wall time on a shared machine is noisy: the figures quoted in
//! docs/performance.md are instruction counts from `scripts/bench-instructions`; these are the
//! wall-time column beside them.
//!
//! ```text
//! cargo bench -p digiteyes-host --bench tracker -- --warm-up-time 1 --measurement-time 3
//! ```

mod support;

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use digiteyes_host::TrackerConfig;

use support::{render_if_missing, Case, Stages};

const SCENARIOS: [&str; 3] = ["mouse", "fullhand-mono", "fullhand-stereo"];

/// Renders `name` (frames 0 and 1) into a temporary folder and loads it.
fn case(name: &str) -> (tempfile::TempDir, Case) {
    let dir = tempfile::tempdir().expect("a temporary folder");
    render_if_missing(name, dir.path(), 2).expect("the scenario renders");
    let case = Case::load(dir.path(), Some(2)).expect("the rendered sequence loads");
    (dir, case)
}

fn one_iteration() -> TrackerConfig {
    let mut config = TrackerConfig::default();
    config.iterations = 1;
    config
}

/// (a)–(c): one iteration; (d): one frame at the default number of iterations.
fn iterations_and_frames(c: &mut Criterion) {
    for name in SCENARIOS {
        let (_dir, case) = case(name);
        let frame1 = case.views(1);
        for (group, config) in [
            ("iteration", one_iteration()),
            ("frame", TrackerConfig::default()),
        ] {
            let tracker = case.tracker(config).expect("a tracker");
            let probe = tracker.clone().track(&frame1).expect("frame 1 tracks");
            eprintln!(
                "{group}/{name}: {} iteration(s), {} features found, rms {:.3} px",
                probe.iterations, probe.features_found, probe.rms_px
            );
            c.bench_function(&format!("{group}/{name}"), |b| {
                b.iter_batched_ref(
                    || tracker.clone(),
                    |t| black_box(t.track(black_box(&frame1))),
                    BatchSize::SmallInput,
                )
            });
        }
    }
}

/// (e): each stage on its own, whole hand, one camera, first iteration of frame 1.
fn stages(c: &mut Criterion) {
    let (_dir, case) = case("fullhand-mono");
    let frames = case.views(1);
    let tracker = case.tracker(TrackerConfig::default()).expect("a tracker");
    let q = case.initial.clone();
    let mut stages = Stages::new(&tracker, &q);
    let (rows, step) = stages.iterate(&q, &frames);
    assert!(
        step.is_some(),
        "the first iteration of frame 1 takes a step"
    );
    eprintln!("stage/fullhand-mono: {rows} residual rows");

    let mut group = c.benchmark_group("stage/fullhand-mono");
    group.bench_function("kinematics", |b| {
        b.iter(|| stages.kinematics(black_box(&q)))
    });
    group.bench_function("projection", |b| b.iter(|| stages.projection()));
    group.bench_function("features", |b| {
        b.iter(|| black_box(stages.features(black_box(&frames))))
    });
    group.bench_function("jacobian_normal", |b| {
        b.iter(|| black_box(stages.jacobian_normal()))
    });
    group.bench_function("solve", |b| b.iter(|| black_box(stages.solve())));
    group.finish();
}

fn config() -> Criterion {
    // Short runs: the machine is shared, and wall time is the noisy, secondary figure here.
    Criterion::default()
        .sample_size(30)
        .warm_up_time(std::time::Duration::from_secs(1))
        .measurement_time(std::time::Duration::from_secs(3))
}

criterion_group! {
    name = benches;
    config = config();
    targets = iterations_and_frames, stages
}
criterion_main!(benches);
