//! How far the simplest walker's period doubling may move between stride-Jacobian methods
//! (`tests/continuation.rs`, `SIMPLEST_PERIOD_DOUBLING_TOL`): locates it with the plain and the
//! frozen-step central differences, and at each located point prints both Jacobians' largest
//! difference, their multipliers through −1, `dλ/dμ` from the gaits on the branch at ±1e-6
//! of slope, and the parameter shift `δλ / (dλ/dμ)` the methods' difference implies
//! (`cargo run --release -p sim --example pd_sensitivity`).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]
use sim::analysis::continuation::{continuation, BifurcationKind, ContinuationSettings};
use sim::analysis::limit_cycle::{GaitSearch, JacobianMethod, NewtonSettings};
use sim::scene::Scene;

fn near_minus_one(ev: &[nalgebra::Complex<f64>]) -> f64 {
    ev.iter()
        .min_by(|a, b| (*a + 1.0).norm().partial_cmp(&(*b + 1.0).norm()).unwrap())
        .unwrap()
        .re
}

fn main() {
    let scene = Scene::load("simplest").unwrap();
    let frozen = NewtonSettings {
        frozen_steps: true,
        jacobian: JacobianMethod::CentralDifferences,
        ..NewtonSettings::default()
    };
    let plain = NewtonSettings::default();
    for (label, newton) in [("plain", &plain), ("frozen", &frozen)] {
        let settings = ContinuationSettings::builder()
            .newton(*newton)
            .max_period(1)
            .build()
            .unwrap();
        let c = continuation(&scene, "slope", (0.009, 0.017, 5), &settings, &|_| {}).unwrap();
        let b = c.branches[0]
            .bifurcations
            .iter()
            .find(|b| b.kind == BifurcationKind::PeriodDoubling)
            .unwrap();
        println!(
            "{label}: PD at {:.13} bracket {:e} lambda {:?}",
            b.value, b.bracket, b.multipliers
        );
        let mut s = scene.clone();
        s.set("slope", b.value).unwrap();
        let setup = s.setup().unwrap();
        let v = &b.point.orbit[0];
        let jac = |n: &NewtonSettings| {
            let search = GaitSearch::new(&setup.walker, &setup.settings, n);
            let sv = search.stride_map(v).unwrap().0;
            search.stride_jacobian_by(v, &sv).unwrap().0
        };
        let (jp, jf) = (jac(&plain), jac(&frozen));
        let (lp, lf) = (
            near_minus_one(jp.complex_eigenvalues().as_slice()),
            near_minus_one(jf.complex_eigenvalues().as_slice()),
        );
        println!(
            "  at it: |Jp - Jf|max = {:e}, lambda plain {:.13} frozen {:.13}, diff {:e}",
            (&jp - &jf).amax(),
            lp,
            lf,
            lp - lf
        );
        // dλ/dμ from gaits on either side
        let d = 1e-6;
        let mut lam = vec![];
        for mu in [b.value - d, b.value + d] {
            let mut s = scene.clone();
            s.set("slope", mu).unwrap();
            let setup = s.setup().unwrap();
            let g = GaitSearch::new(&setup.walker, &setup.settings, newton)
                .find(v)
                .unwrap();
            lam.push(near_minus_one(&g.eigenvalues));
        }
        let dl = (lam[1] - lam[0]) / (2.0 * d);
        println!("  dlambda/dmu = {dl:.6}; predicted shift of mu from the Jacobian methods' lambda difference: {:e}", (lp - lf) / dl);
    }
}
