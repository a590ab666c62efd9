//! Pseudo-arclength continuation (`sim::analysis::continuation`), checked against the hand-written Garcia
//! model of the simplest walker (tests/garcia, no code shared with the engine) and against
//! the engine's own Newton solves at single parameter values.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod garcia;

use garcia::State;
use nalgebra::DVector;
use sim::analysis::continuation::{
    continuation, BifurcationKind, BranchEndKind, BranchPoint, Continuation, ContinuationSettings,
    LOCATION_TOLERANCE,
};
use sim::analysis::limit_cycle::{GaitSearch, NewtonSettings};
use sim::scene::Scene;

const GUESS_LONG: State = State {
    theta: 0.2,
    theta_dot: -0.2,
};

fn run(scene: &str, param: &str, range: (f64, f64, usize), max_period: usize) -> Continuation {
    let scene = Scene::load(scene).unwrap();
    let settings = ContinuationSettings::builder()
        .newton(NewtonSettings::default())
        .max_period(max_period)
        .build()
        .unwrap();
    continuation(&scene, param, range, &settings, &|_| {}).unwrap()
}

/// The simplest walker's state `v` in Garcia's variables (θ = stance_leg, θ̇ = stance_leg_dot).
fn garcia_state(v: &DVector<f64>) -> State {
    let w = Scene::load("simplest").unwrap().build().unwrap();
    let names = w.map_names();
    let at = |n: &str| v[names.iter().position(|m| m == n).unwrap()];
    // After heel strike the swing leg is at −2θ: the engine's state is on Garcia's section.
    assert!((at("swing_leg") + 2.0 * at("stance_leg")).abs() < 1e-9);
    State {
        theta: at("stance_leg"),
        theta_dot: at("stance_leg_dot"),
    }
}

fn close(a: State, b: State) -> f64 {
    (a.theta - b.theta)
        .abs()
        .max((a.theta_dot - b.theta_dot).abs())
}

#[test]
fn the_simplest_walkers_period_doubling_matches_the_hand_written_model_to_1e_8() {
    let c = run("simplest", "slope", (0.009, 0.017, 5), 1);
    let main = &c.branches[0];
    let pd: Vec<_> = main
        .bifurcations
        .iter()
        .filter(|b| b.kind == BifurcationKind::PeriodDoubling)
        .collect();
    assert_eq!(pd.len(), 1, "{:?}", main.bifurcations);
    let reference = garcia::period_doubling_slope(0.009, 0.017, GUESS_LONG).unwrap();
    let ours = pd[0].value;
    println!(
        "period doubling: ours {ours:.12}, reference {reference:.12}, difference {:e}",
        ours - reference
    );
    assert!(
        (ours - reference).abs() < 1e-8,
        "ours {ours}, reference {reference}, difference {:e}",
        ours - reference
    );
    assert!(pd[0].bracket < LOCATION_TOLERANCE);
    // A multiplier −1 there, and the gait stable before and unstable after.
    let m = &pd[0].multipliers;
    let nearest = m.iter().map(|z| (z + 1.0).norm()).fold(f64::MAX, f64::min);
    assert!(nearest < 1e-7, "{m:?}");
    assert!(pd[0].stable_before && !pd[0].stable_after);
    // The located point is the hand-written model's gait at that slope.
    let g = garcia::continued(0.009, ours, GUESS_LONG, 60).unwrap();
    assert!(close(garcia_state(&pd[0].point.orbit[0]), g.state) < 1e-8);
}

#[test]
fn the_period_two_branch_beyond_the_doubling_matches_the_hand_written_model() {
    let c = run("simplest", "slope", (0.009, 0.017, 9), 2);
    assert_eq!(c.branches.len(), 2, "{:?}", c.switch_failures);
    let two = &c.branches[1];
    assert_eq!(two.period_strides, 2);
    let values: Vec<f64> = two.grid.iter().map(|g| g.value).collect();
    assert!(
        values.contains(&0.016) && values.contains(&0.017),
        "{values:?}"
    );
    for gp in &two.grid {
        let gamma = gp.value;
        let p1 = garcia::continued(0.009, gamma, GUESS_LONG, 80).unwrap();
        let cycle = garcia::period2_near(gamma, &p1).unwrap();
        let ours = [
            garcia_state(&gp.point.orbit[0]),
            garcia_state(&gp.point.orbit[1]),
        ];
        // The same cycle, whichever state each starts from.
        let d = close(ours[0], cycle[0])
            .max(close(ours[1], cycle[1]))
            .min(close(ours[0], cycle[1]).max(close(ours[1], cycle[0])));
        assert!(
            d < 1e-7,
            "slope {gamma}: ours {ours:?}, reference {cycle:?}"
        );
        // Its multipliers (the engine's two nonzero ones) match the reference's.
        let reference = garcia::period2_eigenvalues(gamma, cycle[0]).unwrap();
        let mut ours_m: Vec<f64> = gp
            .point
            .multipliers
            .iter()
            .filter(|z| z.norm() > 1e-6)
            .map(|z| z.re)
            .collect();
        let mut theirs: Vec<f64> = reference.iter().map(|z| z.0).collect();
        ours_m.sort_by(f64::total_cmp);
        theirs.sort_by(f64::total_cmp);
        assert_eq!(ours_m.len(), 2, "{:?}", gp.point.multipliers);
        for (a, b) in ours_m.iter().zip(&theirs) {
            assert!(
                (a - b).abs() < 1e-5,
                "slope {gamma}: {ours_m:?} vs {theirs:?}"
            );
        }
        // A genuine period-2 cycle: the two states differ.
        assert!(close(ours[0], ours[1]) > 1e-4);
    }
}

#[test]
fn a_coarse_sweep_stays_on_the_long_period_branch() {
    // Two grid steps of 0.0035 from 0.009 to 0.016: each point must be the long-period gait
    // the hand-written model continues in fine steps, not the short-period one.
    let c = run("simplest", "slope", (0.009, 0.016, 3), 1);
    let main = &c.branches[0];
    assert_eq!(main.grid.len(), 3);
    for gp in &main.grid {
        let reference = garcia::continued(0.009, gp.value, GUESS_LONG, 100).unwrap();
        let d = close(garcia_state(&gp.point.orbit[0]), reference.state);
        assert!(
            d < 1e-8,
            "slope {}: off the long-period branch by {d}",
            gp.value
        );
    }
}

#[test]
fn a_sweep_from_slope_0_015_starts_on_the_long_period_gait_as_walker_gait_does() {
    // At 0.015 the scene's guess finds the unstable short-step gait; the sweep must start on
    // the gait `walker gait` returns there (the long-period one) and follow it.
    let scene = Scene::load("simplest").unwrap();
    let c = run("simplest", "slope", (0.015, 0.017, 3), 1);
    let main = &c.branches[0];
    assert!(c.no_start.is_empty(), "{:?}", c.no_start);
    let first = &main.grid[0];
    assert_eq!(first.value, 0.015);
    let mut at = scene.clone();
    at.set("slope", 0.015).unwrap();
    let setup_for = |s: &Scene| s.setup();
    let gait = sim::analysis::homotopy::long_period_gait(
        &at,
        &setup_for,
        &NewtonSettings::default(),
        &sim::analysis::homotopy::HomotopySettings::default(),
    )
    .unwrap()
    .unwrap();
    assert!((&first.point.orbit[0] - &gait.fixed_point).amax() < 1e-8);
    for gp in main.grid.iter().filter(|g| g.point.period_strides() == 1) {
        let reference = garcia::continued(0.009, gp.value, GUESS_LONG, 100).unwrap();
        let d = close(garcia_state(&gp.point.orbit[0]), reference.state);
        assert!(
            d < 1e-8,
            "slope {}: off the long-period branch by {d}",
            gp.value
        );
    }
    // The short-step gait (Newton from the scene's guess there) is another one.
    let setup = at.setup().unwrap();
    let short = setup.find_gait(&NewtonSettings::default()).unwrap();
    assert!(short.stride.duration_s < 0.9 * gait.stride.duration_s);
}

fn fold_test(p: &BranchPoint) -> f64 {
    sim::analysis::continuation::fold_test(&p.multipliers)
}

#[test]
fn the_tuned_wisse2d_branch_turns_at_a_fold_and_the_gait_does_not_exist_beyond_it() {
    let c = run("wisse2d-tuned", "ankle_engage_rad", (-0.055, -0.06, 3), 1);
    let main = &c.branches[0];
    let folds: Vec<_> = main
        .bifurcations
        .iter()
        .filter(|b| b.kind == BifurcationKind::Fold)
        .collect();
    assert_eq!(folds.len(), 1, "{:?}", main.bifurcations);
    let fold = folds[0];
    assert!(fold.value < -0.055 && fold.value > -0.06, "{}", fold.value);
    // A multiplier +1 at the fold, where the branch's tangent has no parameter component.
    let t = &fold.point.tangent;
    assert!(t[t.len() - 1].abs() < 1e-4, "dp/ds = {}", t[t.len() - 1]);
    assert!(fold_test(&fold.point).abs() < 1e-6);
    let end = main.end.as_ref().unwrap();
    assert_eq!(end.kind, BranchEndKind::Fold);
    // The branch came back to the start value: two gaits there, one stable, one not.
    let at_start: Vec<_> = main.grid.iter().filter(|g| g.value == -0.055).collect();
    assert_eq!(at_start.len(), 2);
    assert!(at_start[0].point.stable() && !at_start[1].point.stable());
    // Independently, Newton at single values: just before the fold it converges from the
    // fold's state; just beyond it, it does not.
    let scene = Scene::load("wisse2d-tuned").unwrap();
    let newton = NewtonSettings::default();
    let solve = |p: f64| {
        let mut s = scene.clone();
        s.set("ankle_engage_rad", p).unwrap();
        let setup = s.setup().unwrap();
        GaitSearch::new(&setup.walker, &setup.settings, &newton).find(&fold.point.orbit[0])
    };
    assert!(solve(fold.value + 1e-4).is_ok());
    assert!(solve(fold.value - 1e-4).is_err());
}

#[test]
fn the_parallel_stride_jacobian_is_bit_identical_to_the_sequential_columns() {
    let scene = Scene::load("simplest").unwrap();
    let setup = scene.setup().unwrap();
    let newton = NewtonSettings::default();
    let search = GaitSearch::new(&setup.walker, &setup.settings, &newton);
    let g = setup.find_gait(&newton).unwrap();
    let v = &g.fixed_point;
    let s = search.stride_map(v).unwrap().0;
    let j = search.stride_jacobian(v, &s).unwrap();
    let d = newton.perturbation;
    for k in 0..v.len() {
        let (mut vp, mut vm) = (v.clone(), v.clone());
        vp[k] += d;
        vm[k] -= d;
        let col =
            (search.stride_map(&vp).unwrap().0 - search.stride_map(&vm).unwrap().0) / (2.0 * d);
        for i in 0..v.len() {
            assert_eq!(j[(i, k)].to_bits(), col[i].to_bits(), "({i}, {k})");
        }
    }
}

#[test]
fn the_tuned_wisse2d_branch_ends_where_the_knee_locks_before_the_string_engages() {
    let c = run("wisse2d-tuned", "slope_rad", (0.0, 0.05, 6), 1);
    let main = &c.branches[0];
    let end = main.end.as_ref().expect("the branch ends");
    assert_eq!(end.kind, BranchEndKind::EventChange, "{end:?}");
    assert_eq!(
        end.event.as_deref(),
        Some("knee_lock:swing_knee"),
        "{end:?}"
    );
    assert!(end.value > 0.04 && end.value < 0.05, "{}", end.value);
    assert!(end.bracket < 1e-8, "{end:?}");
    // Independently, Newton at single values from the branch's last grid point: 1e-7 before
    // the end the gait keeps the old order (string, then knee); 1e-7 beyond it there is no
    // gait with that order.
    let last = &main.grid.last().unwrap().point;
    let scene = Scene::load("wisse2d-tuned").unwrap();
    let newton = NewtonSettings::default();
    let events_at = |p: f64| {
        let mut s = scene.clone();
        s.set("slope_rad", p).unwrap();
        let setup = s.setup().unwrap();
        GaitSearch::new(&setup.walker, &setup.settings, &newton)
            .find(&last.orbit[0])
            .map(|g| {
                g.stride
                    .events
                    .iter()
                    .map(|e| e.name.clone())
                    .collect::<Vec<_>>()
            })
    };
    let before = events_at(end.value - 1e-7).unwrap();
    assert_eq!(
        before,
        ["string_engaged", "knee_lock:swing_knee", "heel_strike"]
    );
    let beyond = events_at(end.value + 1e-7);
    assert!(beyond.as_ref() != Ok(&before), "{beyond:?}");
}

/// How far the simplest walker's period doubling may move between the plain and the
/// frozen-step central-difference Jacobians (`sim/examples/pd_sensitivity.rs` computes each
/// term). The location is the zero of `det(M + I)` on the branch, so a Jacobian difference `δJ`
/// moves it by `δλ / (dλ/dμ)`, `λ` the multiplier through −1: there `dλ/dμ = −218.7` per rad of
/// slope (gaits at ±1e-6 on the branch), and the two Jacobians, which differ by 1.1e-8 (largest
/// entry), give multipliers that differ by 4e-8 at the plain location and 4.7e-7 at the
/// frozen-step one, 1.9e-9 of slope away (the frozen steps' Jacobian changes by more than its
/// smooth part wherever the step schedule does): 2.2e-9 of slope, the shift measured between
/// the two locations (1.9e-9). Each located value is itself only known to its arclength
/// bracket, [`LOCATION_TOLERANCE`] (the parameter moves at most as much). Both together:
/// 2.2e-9 + 2 × 1e-9. Rounding changes at the ulp level alone (glibc's or musl's `sincos`, the
/// link pass or the closed form of the equations of motion) move the frozen-step location
/// between 0.0150884360 and 0.0150884403 (4.3e-9), the plain one by 3e-11: the earlier 1e-9
/// was tighter than the methods' own difference.
const SIMPLEST_PERIOD_DOUBLING_TOL: f64 = 2.2e-9 + 2.0 * LOCATION_TOLERANCE;

/// The stride Jacobian's error at located points (docs/bifurcations.md, "The stride map and its
/// Jacobian"): the simplest walker's has no variational Jacobian (infinitesimal feet) and is
/// compared with central differences on frozen step sizes; the tuned wisse2d one with the
/// variational Jacobian. The located values may move between methods by what the methods'
/// own difference allows: 1e-9 for wisse2d's fold; [`SIMPLEST_PERIOD_DOUBLING_TOL`] for the
/// simplest walker's period doubling.
#[test]
fn the_stride_jacobian_error_at_the_located_points_is_small() {
    use sim::analysis::limit_cycle::JacobianMethod;
    let cases = [
        (
            "simplest",
            "slope",
            (0.009, 0.017, 5),
            BifurcationKind::PeriodDoubling,
            true,
            SIMPLEST_PERIOD_DOUBLING_TOL,
        ),
        (
            "wisse2d-tuned",
            "ankle_engage_rad",
            (-0.055, -0.06, 3),
            BifurcationKind::Fold,
            false,
            1e-9,
        ),
    ];
    for (name, param, range, kind, frozen, tol) in cases {
        let scene = Scene::load(name).unwrap();
        let settings = |newton: &NewtonSettings| {
            ContinuationSettings::builder()
                .newton(*newton)
                .max_period(1)
                .build()
                .unwrap()
        };
        let reference_newton = NewtonSettings {
            frozen_steps: frozen,
            jacobian: if frozen {
                JacobianMethod::CentralDifferences
            } else {
                JacobianMethod::Variational
            },
            ..NewtonSettings::default()
        };
        let located = |newton: &NewtonSettings| {
            let c = continuation(&scene, param, range, &settings(newton), &|_| {}).unwrap();
            c.branches[0]
                .bifurcations
                .iter()
                .find(|b| b.kind == kind)
                .cloned()
                .unwrap()
        };
        let ours = located(&NewtonSettings::default());
        let reference = located(&reference_newton);
        println!(
            "{name}: {kind:?} at {:.12} (central, h = 1e-6) and {:.12} (reference)",
            ours.value, reference.value
        );
        let moved = (ours.value - reference.value).abs();
        assert!(
            moved < tol,
            "{name}: moved by {moved:e} between methods, tolerance {tol:e}"
        );
        let mut s = scene.clone();
        s.set(param, ours.value).unwrap();
        let setup = s.setup().unwrap();
        let v = &ours.point.orbit[0];
        let jacobian = |newton: &NewtonSettings| {
            let search = GaitSearch::new(&setup.walker, &setup.settings, newton);
            let sv = search.stride_map(v).unwrap().0;
            search.stride_jacobian_by(v, &sv).unwrap()
        };
        let (j, _) = jacobian(&NewtonSettings::default());
        let (r, method) = jacobian(&reference_newton);
        assert_eq!(method, reference_newton.jacobian);
        let error = (&j - &r).amax();
        println!("{name}: max |J − J_reference| = {error:e}");
        assert!(error < 1e-7, "{error}");
    }
}

#[test]
fn the_kneed_walkers_smallest_slope_is_a_fold_found_from_either_side() {
    // No gait from the scene's guess at slopes 0.01–0.03: the branch starts at 0.04 and is
    // followed both ways; downhill it turns at a fold (the smallest slope it walks on).
    let c = run("kneed2d", "slope_rad", (0.01, 0.08, 8), 1);
    assert_eq!(c.no_start.len(), 3, "{:?}", c.no_start);
    let main = &c.branches[0];
    let end = main.end_before.as_ref().expect("an end below the start");
    assert_eq!(end.kind, BranchEndKind::Fold);
    let fold = main
        .bifurcations
        .iter()
        .find(|b| b.kind == BifurcationKind::Fold)
        .expect("the fold");
    assert_eq!(fold.value, end.value);
    assert!(fold.value > 0.03 && fold.value < 0.035, "{}", fold.value);
    // The same fold, reached from 0.04 going down.
    let down = run("kneed2d", "slope_rad", (0.04, 0.01, 7), 1);
    let other = down.branches[0]
        .bifurcations
        .iter()
        .find(|b| b.kind == BifurcationKind::Fold)
        .expect("the fold going down");
    assert!(
        (other.value - fold.value).abs() < 1e-9,
        "{} vs {}",
        other.value,
        fold.value
    );
    // The grid values in arclength order: 0.04 on the unstable side, then the stable one up.
    let values: Vec<f64> = main.grid.iter().map(|g| g.value).collect();
    let expected = [0.04, 0.04, 0.05, 0.06, 0.07, 0.08];
    assert_eq!(values.len(), expected.len(), "{values:?}");
    for (v, e) in values.iter().zip(expected) {
        assert!((v - e).abs() < 1e-15, "{values:?}");
    }
    assert!(!main.grid[0].point.stable() && main.grid[1].point.stable());
    // Newton at single values from the fold's state: converges above it, not below.
    let scene = Scene::load("kneed2d").unwrap();
    let newton = NewtonSettings::default();
    let solve = |p: f64| {
        let mut s = scene.clone();
        s.set("slope_rad", p).unwrap();
        let setup = s.setup().unwrap();
        GaitSearch::new(&setup.walker, &setup.settings, &newton).find(&fold.point.orbit[0])
    };
    assert!(solve(fold.value + 1e-5).is_ok());
    assert!(solve(fold.value - 1e-5).is_err());
}

#[test]
fn a_step_refused_at_the_smallest_step_ends_the_branch_instead_of_being_taken() {
    // Contrived: a tangent may turn by at most 1e-9° per step, so every step, down to the
    // smallest, is refused; the branch must end at its start (`not_converged`, saying why)
    // rather than take the step anyway.
    let scene = Scene::load("simplest").unwrap();
    let settings = ContinuationSettings::builder()
        .newton(NewtonSettings::default())
        .max_period(1)
        .max_turn_deg(1e-9)
        .min_step_fraction(0.1)
        .build()
        .unwrap();
    let c = continuation(&scene, "slope", (0.009, 0.017, 3), &settings, &|_| {}).unwrap();
    let main = &c.branches[0];
    let end = main.end.as_ref().unwrap();
    assert_eq!(end.kind, BranchEndKind::NotConverged, "{end:?}");
    assert_eq!(end.value, 0.009);
    assert!(
        end.detail.contains("refused") && end.detail.contains("turned"),
        "{}",
        end.detail
    );
    assert_eq!(main.grid.len(), 1);
    // With the default 60° the same sweep crosses the range.
    let c = run("simplest", "slope", (0.009, 0.017, 3), 1);
    assert!(c.branches[0].end.is_none(), "{:?}", c.branches[0].end);
}

fn report(c: &Continuation) -> serde_json::Value {
    serde_json::to_value(sim::report::SweepReport::from_continuation(c)).unwrap()
}

#[test]
fn period_doublings_without_a_doubled_branch_are_reported() {
    // A budget of one branch: the period doubling on branch 0 gets no period-2 branch, and
    // the report says so with the reason.
    let scene = Scene::load("simplest").unwrap();
    let settings = ContinuationSettings::builder()
        .newton(NewtonSettings::default())
        .max_period(2)
        .max_branches(1)
        .build()
        .unwrap();
    let c = continuation(&scene, "slope", (0.009, 0.017, 5), &settings, &|_| {}).unwrap();
    assert_eq!(c.branches.len(), 1);
    assert_eq!(c.switch_failures.len(), 1, "{:?}", c.switch_failures);
    let pd = &c.branches[0].bifurcations[0];
    assert_eq!(pd.kind, BifurcationKind::PeriodDoubling);
    let v = report(&c);
    let f = &v["switch_failures"][0];
    assert_eq!(f["branch"], 0);
    assert_eq!(f["period_strides"], 1);
    assert_eq!(f["value"].as_f64().unwrap(), pd.value);
    assert!(
        f["reason"].as_str().unwrap().contains("branch budget of 1"),
        "{f}"
    );
    assert_eq!(v["unlocated"].as_array().unwrap().len(), 0);
    assert_eq!(v["param"], "slope");
    assert_eq!(v["param_canonical"], "slope_rad");
    // Detected but not located: `two_neimark_sacker_points_in_one_smallest_step_are_…`.
}

#[test]
fn two_neimark_sacker_points_in_one_smallest_step_are_reported_unlocated() {
    // The 3D walker's closed branch over the extension duration has two Neimark–Sacker points
    // 1.1 ms apart (docs/bifurcations.md: the roll pair comes inside at 0.239952 s, the
    // pelvis-yaw pair at 0.241056 s). With the default step control the step that takes both
    // is halved until they come one per step, and both are located. With the smallest step
    // equal to the first (`min_step_fraction` 0.5: no step can be halved) and a grid spacing
    // wide enough, the first step takes both pairs through the circle at once: the product of
    // the pairs' `|λ| − 1` keeps its sign, so neither can be located on its own, and the
    // bifurcation is reported in `unlocated`, with its bracket and why, not as a point.
    let scene = Scene::load("wisse3d").unwrap();
    let range = (0.2395, 0.2455, 2);
    let param = "ankle_extension_duration_s";
    let settings = |min_step_fraction: Option<f64>| {
        let b = ContinuationSettings::builder()
            .newton(NewtonSettings::default())
            .max_period(1);
        match min_step_fraction {
            Some(f) => b.min_step_fraction(f),
            None => b,
        }
        .build()
        .unwrap()
    };
    let halved = continuation(&scene, param, range, &settings(None), &|_| {}).unwrap();
    let located: Vec<f64> = halved.branches[0]
        .bifurcations
        .iter()
        .filter(|b| b.kind == BifurcationKind::NeimarkSacker)
        .map(|b| b.value)
        .collect();
    eprintln!("halved steps: Neimark–Sacker at {located:?}");
    assert!(halved.branches[0].unlocated.is_empty());
    assert_eq!(located.len(), 2, "{located:?}");
    let whole = continuation(&scene, param, range, &settings(Some(0.5)), &|_| {}).unwrap();
    let b = &whole.branches[0];
    eprintln!("one step: unlocated {:?}", b.unlocated);
    assert!(
        b.bifurcations
            .iter()
            .all(|x| x.kind != BifurcationKind::NeimarkSacker),
        "{:?}",
        b.bifurcations
            .iter()
            .map(|x| (x.kind, x.value))
            .collect::<Vec<_>>()
    );
    assert_eq!(b.unlocated.len(), 1, "{:?}", b.unlocated);
    let u = &b.unlocated[0];
    assert_eq!(u.kind, BifurcationKind::NeimarkSacker);
    let (lo, hi) = (u.bracket.0.min(u.bracket.1), u.bracket.0.max(u.bracket.1));
    assert_eq!(lo, range.0);
    assert!(
        located.iter().all(|&x| lo < x && x < hi),
        "{located:?} not in {:?}",
        u.bracket
    );
    assert!(u.reason.contains("no single crossing"), "{}", u.reason);
    // The report carries it with its bracket and why.
    let v = report(&whole);
    let r = &v["unlocated"][0];
    assert_eq!(r["kind"], "neimark_sacker");
    assert_eq!(r["bracket"][0].as_f64(), Some(u.bracket.0));
    assert_eq!(r["bracket"][1].as_f64(), Some(u.bracket.1));
    assert_eq!(r["reason"].as_str(), Some(u.reason.as_str()));
}

#[test]
fn a_grazing_end_does_not_claim_the_bisection_width_as_its_accuracy() {
    // Uphill the tuned wisse2d branch ends where a stride fails (the swing foot grazes the floor):
    // the value depends on the stride grid beyond the 1e-9 bracket, so no accuracy is claimed.
    let c = run("wisse2d-tuned", "slope_rad", (0.0, -0.02, 5), 1);
    let end = c.branches[0].end.as_ref().unwrap();
    assert_eq!(end.kind, BranchEndKind::EventChange, "{end:?}");
    assert!(end.grazing, "{end:?}");
    assert!(end.bracket < 1e-8 && !end.budget_exhausted, "{end:?}");
    assert_eq!(end.accuracy(), None);
    let v = report(&c);
    let e = &v["branch_ends"][0];
    assert_eq!(e["grazing"], true);
    assert!(e["accuracy"].is_null(), "{e}");
    // Downhill it ends between two converged event sequences: the bracket bounds it.
    let c = run("wisse2d-tuned", "slope_rad", (0.0, 0.05, 6), 1);
    let end = c.branches[0].end.as_ref().unwrap();
    assert!(!end.grazing, "{end:?}");
    assert_eq!(end.accuracy(), Some(end.bracket));
    let v = report(&c);
    assert_eq!(v["branch_ends"][0]["accuracy"].as_f64(), Some(end.bracket));
    // Every located bifurcation carries its bracket.
    let c = run("simplest", "slope", (0.009, 0.017, 5), 1);
    let v = report(&c);
    let b = &v["stability_boundaries"][0];
    assert!(b["bracket"].as_f64().unwrap() < LOCATION_TOLERANCE, "{b}");
    assert_eq!(b["budget_exhausted"], false);
}
