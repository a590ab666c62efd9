//! The engine's robustness measures (`sim::analysis::robustness`, the gait sensitivity norm)
//! against the same definitions taken on the hand-written models (tests/robustness_reference
//! over tests/garcia and tests/compass_model, which share no code with the engine): the
//! simplest walker at slopes 0.004 and 0.009 and the compass gait at Drake's defaults. Step
//! thresholds down and up (and where survival starts again), rate thresholds, the gait
//! sensitivity norm, a basin slice cell by cell and the mean first-passage time on a rough
//! floor walk by walk, its interval against the chi-square distribution written out here.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;
mod compass_model;
mod garcia;
mod robustness_reference;

use robustness_reference as rr;
use sim::analysis::gait_sensitivity::gait_sensitivity_norm;
use sim::analysis::robustness::{
    basin_slice, first_passage, mean_first_passage, step_threshold, velocity_thresholds, BasinAxis,
    BasinCell, FirstPassageOptions, Outcome, Recovery, StepDirection, Threshold, ThresholdOptions,
};
use sim::scene::{Scene, Setup};
use sim::stride::Floor;

type X = rr::X;
type Stride = Box<dyn FnMut(&X, f64) -> Option<(X, f64, f64)>>;

/// A walker both ways: the engine's setup and gait, and the hand-written stride map with its
/// gravity and leg length.
struct Case {
    name: String,
    setup: Setup,
    gait: sim::analysis::limit_cycle::Gait,
    reference: fn(&str) -> Stride,
    gravity: f64,
}

impl Case {
    fn simplest(gamma: f64) -> Self {
        let mut scene = Scene::load("simplest").unwrap();
        scene.set("slope_rad", gamma).unwrap();
        let setup = scene.setup().unwrap();
        let gait = common::gait(&setup);
        Case {
            name: format!("simplest {gamma}"),
            setup,
            gait,
            reference: |name| {
                let gamma: f64 = name.trim_start_matches("simplest ").parse().unwrap();
                Box::new(garcia::engine_stride(gamma))
            },
            gravity: 1.0,
        }
    }

    fn compass() -> Self {
        let setup = Scene::load("compass").unwrap().setup().unwrap();
        let gait = common::gait(&setup);
        Case {
            name: "compass".into(),
            setup,
            gait,
            reference: |_| {
                let p = compass_model::Params::goswami();
                Box::new(move |x: &X, h: f64| compass_model::stride_onto_step(&p, *x, h))
            },
            gravity: 9.81,
        }
    }

    fn all() -> Vec<Self> {
        vec![
            Self::simplest(0.004),
            Self::simplest(0.009),
            Self::compass(),
        ]
    }

    fn x(&self) -> X {
        let v = &self.gait.fixed_point;
        assert_eq!(v.len(), 4, "{}", self.name);
        [v[0], v[1], v[2], v[3]]
    }

    fn stride(&self) -> Stride {
        (self.reference)(&self.name)
    }

    fn recovery(&self) -> Recovery<'_> {
        Recovery::new(&self.setup.walker, &self.setup.settings, &self.gait)
    }
}

/// The engine's threshold and the reference's agree: the same grid interval fails first
/// (both bisect the same bracket, so the ends agree to the resolution), and survival starts
/// again at the same place, or nowhere.
fn agree(what: &str, engine: &Threshold, reference: &rr::Threshold, resolution: f64) {
    eprintln!(
        "{what}: engine {:.10} again {:?}; reference {:.10} again {:?}",
        engine.max, engine.survived_again_from, reference.threshold, reference.survived_again_from
    );
    assert_eq!(engine.at_limit, reference.all_survived, "{what}");
    assert!(
        (engine.max - reference.threshold).abs() <= resolution,
        "{what}: {} against {}",
        engine.max,
        reference.threshold
    );
    match (engine.survived_again_from, reference.survived_again_from) {
        (None, None) => {}
        (Some(a), Some(b)) => assert!((a - b).abs() <= resolution, "{what}: again {a} vs {b}"),
        (a, b) => panic!("{what}: survived again {a:?} against {b:?}"),
    }
}

#[test]
fn step_thresholds_agree_with_the_hand_written_models() {
    for case in Case::all() {
        let x = case.x();
        let recovery = case.recovery();
        assert!((recovery.leg_length_m() - 1.0).abs() < 1e-12);
        for (dir, step) in [
            (StepDirection::Down, rr::Step::Down),
            (StepDirection::Up, rr::Step::Up),
        ] {
            let engine = step_threshold(&recovery, &ThresholdOptions::steps(), dir);
            let reference = rr::step_threshold(&mut case.stride(), &x, 1.0, step);
            agree(
                &format!("{} step {dir:?}", case.name),
                &engine,
                &reference,
                1e-7,
            );
        }
    }
}

#[test]
fn rate_thresholds_agree_with_the_hand_written_models() {
    // the reference's grid: every 1e-3 natural rates up to one
    let options = ThresholdOptions {
        scan_step: 1e-3,
        limit: 1.0,
        resolution: 1e-7,
    };
    for case in Case::all() {
        let x = case.x();
        let unit = case.gravity.sqrt();
        assert!((case.recovery().natural_rate_1_s() - unit).abs() < 1e-12);
        let engine = velocity_thresholds(&case.recovery(), &options);
        assert_eq!(engine.len(), 2);
        for v in &engine {
            assert_eq!(
                v.index,
                if v.coordinate == "stance_leg_dot" {
                    2
                } else {
                    3
                }
            );
            for (sign, e) in [(1.0, &v.positive), (-1.0, &v.negative)] {
                let r = rr::velocity_threshold(
                    &mut case.stride(),
                    &x,
                    v.index,
                    sign,
                    case.gravity,
                    1.0,
                );
                agree(
                    &format!("{} {} {sign:+}", case.name, v.coordinate),
                    e,
                    &r,
                    1e-7 * unit,
                );
            }
        }
    }
}

#[test]
fn gait_sensitivity_norms_agree_with_the_hand_written_models() {
    for case in Case::all() {
        let e = gait_sensitivity_norm(&case.setup.walker, &case.setup.settings, &case.gait, 1e-6)
            .unwrap();
        let (t, l, b) = rr::gait_sensitivity_norm(&mut case.stride(), &case.x(), 1e-6);
        eprintln!("{}: engine {e:?}; reference {t} {l} {b}", case.name);
        for (a, r) in [(e.step_time, t), (e.step_length, l), (e.both, b)] {
            assert!((a - r).abs() <= 1e-6 * r, "{}: {a} against {r}", case.name);
        }
    }
}

/// The reference's cell centres over `(lo, hi)`.
fn centres((lo, hi): (f64, f64), n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo + (i as f64 + 0.5) * (hi - lo) / n as f64)
        .collect()
}

#[test]
fn a_basin_slice_agrees_cell_by_cell_and_its_fraction_converges() {
    let case = Case::simplest(0.009);
    let x = case.x();
    let window = [(0.15, 0.25), (-0.25, -0.15)];
    let mut fractions = Vec::new();
    for n in [20, 40, 80] {
        let engine = basin_slice(
            &case.recovery(),
            BasinAxis {
                name: "stance_leg".into(),
                values: centres(window[0], n),
            },
            BasinAxis {
                name: "stance_leg_dot".into(),
                values: centres(window[1], n),
            },
            &|| {},
        )
        .unwrap();
        assert_eq!(engine.solved_coordinate.as_deref(), Some("swing_leg"));
        let foot_height = |x: &X| x[0].cos() - (x[0] + x[1]).cos();
        let reference = rr::basin_slice(
            &mut case.stride(),
            foot_height,
            &x,
            [0, 2],
            window,
            [n, n],
            100,
            1e-6,
        );
        let mut differ = 0;
        for (k, r) in reference.cells.iter().enumerate() {
            let e = &engine.cells[k / n][k % n];
            let same = match (e, r) {
                (
                    BasinCell::Strides(Outcome::Gait { strides: a }),
                    rr::Outcome::Gait { strides: b },
                ) => a == b,
                (BasinCell::Strides(Outcome::Failed { .. }), rr::Outcome::Fell) => true,
                (BasinCell::OffSection, rr::Outcome::Fell) => true,
                (
                    BasinCell::Strides(Outcome::Periodic { period: a, .. }),
                    rr::Outcome::Periodic { period: b },
                ) => a == b,
                (BasinCell::Strides(Outcome::NotSettled { .. }), rr::Outcome::NotSettled) => true,
                _ => false,
            };
            if !same {
                differ += 1;
                eprintln!("{n}×{n} cell {k}: engine {e:?}, reference {r:?}");
            }
        }
        eprintln!(
            "{n}×{n}: fraction returning engine {} reference {} ({differ} cells differ)",
            engine.fraction_returning, reference.fraction_returning
        );
        // a cell within the models' 1e-12 agreement of the basin's edge may go either way
        assert!(differ * 200 <= n * n, "{differ} of {} cells differ", n * n);
        assert!((engine.fraction_returning - reference.fraction_returning).abs() <= 0.005);
        fractions.push(engine.fraction_returning);
    }
    // refining the grid: the fraction settles (each refinement changes it less than 1 %
    // of the window, and less than the one before)
    let d1 = (fractions[1] - fractions[0]).abs();
    let d2 = (fractions[2] - fractions[1]).abs();
    eprintln!("fractions {fractions:?}: changes {d1}, {d2}");
    assert!(d1 < 0.01 && d2 < 0.01 && d2 <= d1, "{fractions:?}");
}

/// `P(χ² ≤ x)` for `2k` degrees of freedom, written out: `1 − e^{−x/2} Σ_{i<k} (x/2)^i / i!`.
fn chi_square_cdf_even(two_k: usize, x: f64) -> f64 {
    let (k, h) = (two_k / 2, x / 2.0);
    let mut term = 1.0;
    let mut sum = 0.0;
    for i in 0..k {
        if i > 0 {
            term *= h / i as f64;
        }
        sum += term;
    }
    1.0 - (-h).exp() * sum
}

/// The `p` quantile of `χ²` with `2k` degrees of freedom, by bisection on the CDF above.
fn chi_square_quantile_even(two_k: usize, p: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 10.0 * two_k as f64 + 100.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if chi_square_cdf_even(two_k, mid) < p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn first_passage_times_agree_walk_by_walk_and_their_intervals_are_exact() {
    let case = Case::compass();
    let x = case.x();
    let options = FirstPassageOptions {
        runs: 40,
        strides_per_run: 150,
        seed: 11,
    };
    for sigma_m in [0.002, 0.004, 0.008] {
        let engine = mean_first_passage(&case.recovery(), sigma_m, &options).unwrap();
        // the same floors (the draws are the walk's input) under the hand-written model
        let (mut strides, mut failed) = (0, 0);
        for r in 0..options.runs {
            let mut heights = Floor::Rough {
                sigma_m,
                seed: options.seed + r as u64,
            }
            .heights();
            let mut stride = case.stride();
            let mut y = x;
            for k in 1..=options.strides_per_run {
                strides += 1;
                match stride(&y, heights.next_step_m()) {
                    Some((next, _, _)) => y = next,
                    None => {
                        failed += 1;
                        break;
                    }
                }
                let _ = k;
            }
        }
        eprintln!(
            "σ {sigma_m}: engine {} strides {} fell {:?}; reference {strides} strides {failed} fell",
            engine.strides_simulated, engine.failed, engine.steps
        );
        assert_eq!(engine.strides_simulated, strides, "σ {sigma_m}");
        assert_eq!(engine.failed, failed, "σ {sigma_m}");
        assert_eq!(engine.censored, options.runs - failed);
        // the estimate T/d and the exact interval [2T/χ²(0.975; 2d+2), 2T/χ²(0.025; 2d)]
        let t = strides as f64;
        if failed > 0 {
            let d = failed as f64;
            assert!((engine.steps.unwrap() - t / d).abs() <= 1e-12 * t);
            let high = 2.0 * t / chi_square_quantile_even(2 * failed, 0.025);
            assert!(
                (engine.ci_high.unwrap() - high).abs() <= 1e-9 * high,
                "{:?} {high}",
                engine.ci_high
            );
        } else {
            assert!(engine.steps.is_none() && engine.ci_high.is_none());
        }
        let low = 2.0 * t / chi_square_quantile_even(2 * failed + 2, 0.975);
        assert!(
            (engine.ci_low - low).abs() <= 1e-9 * low,
            "{} {low}",
            engine.ci_low
        );
    }
    // table values (e.g. Abramowitz & Stegun 26.8): χ²(0.975; 2) = 7.37776, χ²(0.025; 20) = 9.59078
    assert!((chi_square_quantile_even(2, 0.975) - 7.377_759).abs() < 1e-5);
    assert!((chi_square_quantile_even(20, 0.025) - 9.590_777).abs() < 1e-5);
    let (s, lo, hi) = first_passage::estimate(1000, 10);
    assert_eq!(s, Some(100.0));
    assert!((lo - 2000.0 / chi_square_quantile_even(22, 0.975)).abs() < 1e-9);
    assert!((hi.unwrap() - 2000.0 / chi_square_quantile_even(20, 0.025)).abs() < 1e-9);
}
