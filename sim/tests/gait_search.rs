//! The gait search's cost: the stepping Jacobian by forward differences (`n` strides reusing
//! the nominal stride) finds the same fixed point and eigenvalues as central differences
//! (`2n` strides), with the strides it saves counted.

mod common;

use sim::analysis::limit_cycle::NewtonSettings;

#[test]
fn forward_stepping_finds_the_same_gait_with_fewer_strides() {
    for name in ["simplest", "compass", "kneed2d", "wisse2d"] {
        let (_, w) = common::walker(name);
        let forward = NewtonSettings::default();
        assert!(
            forward.forward_stepping,
            "the default steps by forward differences"
        );
        let central = NewtonSettings {
            forward_stepping: false,
            ..forward
        };
        let (gf, gc) = (
            w.find_gait(&forward).unwrap(),
            w.find_gait(&central).unwrap(),
        );
        let n = gf.fixed_point.len();
        // Both converge to the fixed point within Newton's tolerance.
        let dv = (&gf.fixed_point - &gc.fixed_point).amax();
        assert!(
            dv < forward.tolerance,
            "{name}: fixed points differ by {dv:e}"
        );
        assert!(gf.residual < 1e-10 && gc.residual < 1e-10, "{name}");
        // The eigenvalue Jacobian is central in both: eigenvalues to its noise.
        let mut ef: Vec<f64> = gf.eigenvalues.iter().map(|z| z.norm()).collect();
        let mut ec: Vec<f64> = gc.eigenvalues.iter().map(|z| z.norm()).collect();
        ef.sort_by(f64::total_cmp);
        ec.sort_by(f64::total_cmp);
        for (a, b) in ef.iter().zip(&ec) {
            assert!((a - b).abs() < 1e-7, "{name}: eigenvalue moduli {a} vs {b}");
        }
        // The strides: one per iterate or trial, n per forward stepping Jacobian, 2n per
        // central one; the same iterations here, so the forward search saves n strides per
        // stepping Jacobian and at least one.
        assert_eq!(gf.iterations, gc.iterations, "{name}");
        let saved = gc.strides - gf.strides;
        assert!(
            saved >= n && saved % n == 0,
            "{name}: {} vs {}",
            gf.strides,
            gc.strides
        );
        // At least the final central Jacobian, each iterate and one stepping Jacobian.
        assert!(
            gf.strides >= 3 * n + gf.iterations,
            "{name}: {}",
            gf.strides
        );
    }
}

#[test]
fn broyden_updates_find_the_same_gait_in_fewer_strides() {
    // The chord iteration keeps its first Jacobian while the residual falls fourfold and so
    // converges linearly; Broyden's updates, from strides Newton takes anyway, make it
    // superlinear: the same fixed point (within the tolerance) and eigenvalues, fewer strides
    // in all over these walkers.
    let (mut with, mut without) = (0, 0);
    for name in ["simplest", "compass", "kneed2d", "wisse2d"] {
        let (_, w) = common::walker(name);
        let broyden = NewtonSettings::default();
        assert!(broyden.broyden, "the default updates its Newton matrix");
        let chord = NewtonSettings {
            broyden: false,
            ..broyden
        };
        let (gb, gc) = (w.find_gait(&broyden).unwrap(), w.find_gait(&chord).unwrap());
        let dv = (&gb.fixed_point - &gc.fixed_point).amax();
        assert!(
            dv < broyden.tolerance,
            "{name}: fixed points differ by {dv:e}"
        );
        assert!(gb.residual < 1e-10, "{name}: residual {:e}", gb.residual);
        let mut eb: Vec<f64> = gb.eigenvalues.iter().map(|z| z.norm()).collect();
        let mut ec: Vec<f64> = gc.eigenvalues.iter().map(|z| z.norm()).collect();
        eb.sort_by(f64::total_cmp);
        ec.sort_by(f64::total_cmp);
        for (a, b) in eb.iter().zip(&ec) {
            assert!((a - b).abs() < 1e-7, "{name}: eigenvalue moduli {a} vs {b}");
        }
        eprintln!(
            "{name}: {} strides ({} iterations) with Broyden's updates, {} ({}) without",
            gb.strides, gb.iterations, gc.strides, gc.iterations
        );
        assert!(gb.strides <= gc.strides, "{name}");
        with += gb.strides;
        without += gc.strides;
    }
    assert!(
        with < without,
        "{with} strides with the updates, {without} without"
    );
}
