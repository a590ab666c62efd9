//! Shared helpers for the integration tests.
#![allow(
    dead_code,
    missing_docs,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic
)]

use nalgebra::DVector;
use sim::analysis::limit_cycle::{Gait, GaitSearch, NewtonSettings};
use sim::scene::{Scene, Setup};
use sim::stride::walk::{Walk, WalkRequest};
use sim::stride::{StrideFailure, StrideRequest, StrideResult};

pub fn walker(name: &str) -> (Scene, Setup) {
    let scene = Scene::load(name).expect("scene loads");
    let setup = scene.setup().expect("scene builds");
    (scene, setup)
}

pub fn gait(w: &Setup) -> Gait {
    w.find_gait(&NewtonSettings::default())
        .expect("gait converges")
}

pub fn start_state(w: &Setup, g: &Gait) -> (DVector<f64>, DVector<f64>) {
    w.walker.unpack(&g.fixed_point)
}

/// The stride map `S(v)` with the setup's settings.
pub fn stride_map(
    w: &Setup,
    v: &DVector<f64>,
) -> Result<(DVector<f64>, StrideResult), StrideFailure> {
    GaitSearch::new(&w.walker, &w.settings, &NewtonSettings::default()).stride_map(v)
}

/// A free stride with the setup's settings, recording nothing.
pub fn stride(
    w: &Setup,
    q: &DVector<f64>,
    qd: &DVector<f64>,
) -> Result<StrideResult, StrideFailure> {
    w.walker.stride(q, qd, StrideRequest::new(&w.settings))
}

/// A walk of up to `steps` strides with the setup's settings.
pub fn walk(w: &Setup, q: &DVector<f64>, qd: &DVector<f64>, steps: usize, record: bool) -> Walk {
    sim::stride::walk::walk(
        &w.walker,
        q,
        qd,
        WalkRequest::new(&w.settings, steps).recording(record),
    )
}
