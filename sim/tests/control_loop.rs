//! The control-tick machinery: a sampled version of the ideal reflex walks like the ideal one.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use sim::engine::control::SampledReflex;
use sim::stride::walk::WalkRequest;

#[test]
fn a_sampled_reflex_at_1_khz_walks_like_the_ideal_actuator() {
    let (_, w) = common::walker("wisse3d");
    let g = common::gait(&w);
    let (q, qd) = common::start_state(&w, &g);
    let reflex = w.walker.ankle().cloned().unwrap();
    let mut ctl = SampledReflex::new(1e-3, &reflex);
    let request = WalkRequest::new(&w.settings, 20).controlled(&mut ctl);
    let walk = sim::stride::walk::walk(&w.walker, &q, &qd, request);
    assert!(walk.failure.is_none(), "{:?}", walk.failure);
    let ideal = g.stride.duration_s;
    for s in &walk.steps {
        // The extension starts up to one tick late: the step period moves by a few milliseconds.
        assert!(
            (s.duration_s - ideal).abs() < 5e-3,
            "step {} period {} vs {ideal}",
            s.step,
            s.duration_s
        );
        assert!(s.events.iter().any(|e| e.name == "string_engaged"));
    }
}
