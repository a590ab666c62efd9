//! The stride Jacobian from the variational equations (forward-mode automatic differentiation
//! through the flow, saltation at every event) against central differences.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use sim::analysis::limit_cycle::{GaitSearch, JacobianMethod, NewtonSettings};

#[test]
fn the_variational_jacobian_matches_central_differences_on_every_event_kind() {
    // compass: heel strike only; kneed2d: a knee lock; wisse3d: the string's engagement, its
    // drive and its end, a knee lock during the push, mirroring and a cyclic heading.
    for (name, bound) in [("compass", 1e-8), ("kneed2d", 3e-8), ("wisse3d", 3e-8)] {
        let (_, w) = common::walker(name);
        let g = common::gait(&w);
        let s = common::stride_map(&w, &g.fixed_point).unwrap().0;
        let fd = GaitSearch::new(&w.walker, &w.settings, &NewtonSettings::default())
            .stride_jacobian(&g.fixed_point, &s)
            .unwrap();
        let (var, _) =
            sim::analysis::variational::stride_jacobian(&w.walker, &g.fixed_point, &w.settings)
                .unwrap();
        let d = (&var - &fd).amax();
        assert!(d < bound * fd.amax(), "{name}: |J_var - J_fd| = {d:e}");
    }
}

#[test]
fn the_variational_jacobian_has_the_exact_zero_eigenvalues() {
    // The knee coordinate is reset at every stride (locked at heel strike): its column of the
    // stride Jacobian is exactly zero. Central differences leave eigenvalues of about 1e-9
    // there; the variational Jacobian gives zero to rounding.
    let (_, w) = common::walker("kneed2d");
    let g = common::gait(&w);
    let (var, _) =
        sim::analysis::variational::stride_jacobian(&w.walker, &g.fixed_point, &w.settings)
            .unwrap();
    let mut moduli: Vec<f64> = var.complex_eigenvalues().iter().map(|z| z.norm()).collect();
    moduli.sort_by(f64::total_cmp);
    assert!(moduli[0] < 1e-13, "{moduli:?}");
}

#[test]
fn a_gait_says_which_jacobian_it_used() {
    let settings = NewtonSettings {
        jacobian: JacobianMethod::Variational,
        ..Default::default()
    };
    let (_, w) = common::walker("kneed2d");
    let g = w.find_gait(&settings).unwrap();
    assert_eq!(g.jacobian_method, JacobianMethod::Variational);
    // The simplest walker's infinitesimal masses are outside the method: central differences,
    // and the gait says so.
    let (_, w) = common::walker("simplest");
    let g = w.find_gait(&settings).unwrap();
    assert_eq!(g.jacobian_method, JacobianMethod::CentralDifferences);
}
