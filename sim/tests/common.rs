//! Shared helpers for the integration tests.
#![allow(
    dead_code,
    missing_docs,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic
)]

use nalgebra::DVector;
use sim::limit_cycle::{Gait, NewtonSettings};
use sim::scene::Scene;
use sim::walker::Walker;

pub fn walker(name: &str) -> (Scene, Walker) {
    let scene = Scene::load(name).expect("scene loads");
    let walker = scene.build().expect("scene builds");
    (scene, walker)
}

pub fn gait(w: &Walker) -> Gait {
    let v0 = w.pack(&w.guess_q, &w.guess_qd);
    w.find_gait(&v0, &NewtonSettings::default())
        .expect("gait converges")
}

pub fn start_state(w: &Walker, g: &Gait) -> (DVector<f64>, DVector<f64>) {
    w.unpack(&g.fixed_point)
}
