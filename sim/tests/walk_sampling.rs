//! A walk's path: thinned to an interval for what keeps it (figures, pages), streamed whole
//! to a callback (CSV), the two consistent with the unthinned recording.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use sim::stride::walk::{walk, PathSample, WalkRequest};

#[test]
fn a_thinned_path_keeps_every_step_end_and_the_interval_and_the_stream_keeps_all() {
    let (_, w) = common::walker("compass");
    let g = common::gait(&w);
    let (q, qd) = common::start_state(&w, &g);
    let steps = 3;
    let full = common::walk(&w, &q, &qd, steps, true);
    assert_eq!(full.steps_completed, steps);
    let dt = 0.05;
    let mut streamed: Vec<(usize, f64)> = Vec::new();
    let mut on_sample = |s: &PathSample| streamed.push((s.step, s.t_walk_s));
    let thin = walk(
        &w.walker,
        &q,
        &qd,
        WalkRequest::new(&w.settings, steps)
            .recording(true)
            .path_interval(dt)
            .on_sample(&mut on_sample),
    );
    // the stream is the unthinned recording, sample for sample
    let all: Vec<(usize, f64)> = full.path.iter().map(|s| (s.step, s.t_walk_s)).collect();
    assert_eq!(streamed, all);
    // the thinned path: a subsequence, far shorter, with every step's first and last sample
    let kept: Vec<(usize, f64)> = thin.path.iter().map(|s| (s.step, s.t_walk_s)).collect();
    assert!(kept.len() < all.len(), "{} of {}", kept.len(), all.len());
    let mut it = all.iter();
    assert!(kept.iter().all(|k| it.any(|a| a == k)), "not a subsequence");
    for step in 0..steps {
        let of_step: Vec<&(usize, f64)> = all.iter().filter(|a| a.0 == step).collect();
        for end in [of_step.first().unwrap(), of_step.last().unwrap()] {
            assert!(kept.contains(end), "step {step}: {end:?} dropped");
        }
    }
    // no gap wider than the interval plus one integrator step (the widest in the full path)
    let widest_step = all
        .windows(2)
        .filter(|p| p[0].0 == p[1].0)
        .map(|p| p[1].1 - p[0].1)
        .fold(0.0, f64::max);
    for p in kept.windows(2) {
        assert!(
            p[1].1 - p[0].1 <= dt + widest_step + 1e-12,
            "gap {} at {:?}",
            p[1].1 - p[0].1,
            p[0]
        );
    }
    // the same walk either way
    assert_eq!(thin.steps_completed, full.steps_completed);
    assert_eq!(
        thin.steps.last().unwrap().state,
        full.steps.last().unwrap().state
    );
}

#[test]
fn a_stream_without_recording_keeps_no_path() {
    let (_, w) = common::walker("compass");
    let g = common::gait(&w);
    let (q, qd) = common::start_state(&w, &g);
    let mut n = 0usize;
    let mut on_sample = |_: &PathSample| n += 1;
    let walked = walk(
        &w.walker,
        &q,
        &qd,
        WalkRequest::new(&w.settings, 2).on_sample(&mut on_sample),
    );
    assert!(walked.path.is_empty());
    assert!(n > 20, "{n}");
}

#[test]
fn a_bounded_path_stops_at_its_bound_says_where_and_the_walk_goes_on() {
    let (_, w) = common::walker("compass");
    let g = common::gait(&w);
    let (q, qd) = common::start_state(&w, &g);
    let steps = 3;
    let full = common::walk(&w, &q, &qd, steps, true);
    assert_eq!(full.path_cut_t_walk_s, None);
    let bound = full.path.len() / 2;
    let cut = walk(
        &w.walker,
        &q,
        &qd,
        WalkRequest::new(&w.settings, steps)
            .recording(true)
            .max_path_samples(bound),
    );
    // the first `bound` samples of the whole path, and where it stopped
    assert_eq!(cut.path.len(), bound);
    let t = |p: &[PathSample]| p.iter().map(|s| s.t_walk_s).collect::<Vec<_>>();
    assert_eq!(t(&cut.path), t(&full.path[..bound]));
    assert_eq!(cut.path_cut_t_walk_s, Some(full.path[bound - 1].t_walk_s));
    // the walk itself is the same
    assert_eq!(cut.steps_completed, steps);
    assert_eq!(
        cut.steps.last().unwrap().state,
        full.steps.last().unwrap().state
    );
    // a bound the path never reaches changes nothing
    let roomy = walk(
        &w.walker,
        &q,
        &qd,
        WalkRequest::new(&w.settings, steps)
            .recording(true)
            .max_path_samples(full.path.len()),
    );
    assert_eq!(
        (roomy.path.len(), roomy.path_cut_t_walk_s),
        (full.path.len(), None)
    );
}
