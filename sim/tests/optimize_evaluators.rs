//! `optimize_with`: the search with its candidates evaluated elsewhere (a cluster's workers)
//! is the search [`optimize`] runs, bit for bit, whatever the evaluator's order or batching;
//! evaluations travel as CBOR without losing a bit; an evaluator that answers for other
//! designs is refused.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use sim::analysis::homotopy::HomotopySettings;
use sim::analysis::limit_cycle::NewtonSettings;
use sim::analysis::optimize::{
    evaluate_drawn, optimize, optimize_with, Evaluation, Objective, OptimizeError,
    OptimizeSettings, QuantityOptions, VariedParameter,
};
use sim::scene::{Scene, SceneError, Setup};
use std::sync::atomic::{AtomicUsize, Ordering};

fn setup(scene: &Scene) -> Result<Setup, SceneError> {
    scene.setup()
}

fn params() -> Vec<VariedParameter> {
    vec![
        VariedParameter {
            name: "slope_rad".into(),
            min: 0.02,
            max: 0.07,
        },
        VariedParameter {
            name: "leg_mass_kg".into(),
            min: 2.0,
            max: 8.0,
        },
    ]
}

fn settings<'a>(
    params: &'a [VariedParameter],
    newton: &'a NewtonSettings,
    homotopy: &'a HomotopySettings,
) -> OptimizeSettings<'a> {
    OptimizeSettings {
        params,
        objective: Objective::MaxAbsEigenvalue,
        constraints: &[],
        budget: 45,
        seed: 11,
        initial_step: 0.4,
        setup_for: &setup,
        newton,
        homotopy,
        quantity_options: QuantityOptions::default(),
    }
}

#[test]
fn a_search_evaluated_one_design_at_a_time_backwards_is_the_same_search() {
    let scene = Scene::load("compass").unwrap();
    let (newton, homotopy) = (NewtonSettings::default(), HomotopySettings::default());
    let params = params();
    let s = settings(&params, &newton, &homotopy);
    let here = optimize(&scene, &s, &|| {}).unwrap();
    let batches = AtomicUsize::new(0);
    let elsewhere = |drawn: &[Vec<f64>]| -> Result<Vec<Evaluation>, OptimizeError> {
        batches.fetch_add(1, Ordering::Relaxed);
        let mut out: Vec<Evaluation> = drawn
            .iter()
            .rev()
            .map(|u| {
                // each design in a worker of its own: a fresh evaluator, through CBOR
                let e = evaluate_drawn(&scene, &s, std::slice::from_ref(u), &|| {}).unwrap();
                Evaluation::from_cbor(&e[0].to_cbor()).unwrap()
            })
            .collect();
        out.reverse();
        Ok(out)
    };
    let there = optimize_with(&scene, &s, &|| {}, Some(&elsewhere)).unwrap();
    assert_eq!(here.evaluations, there.evaluations);
    assert_eq!(here.default, there.default);
    assert_eq!(here.runs, there.runs);
    let (a, b) = (here.best.unwrap(), there.best.unwrap());
    assert_eq!(a.index, b.index);
    assert_eq!(a.gait.fixed_point, b.gait.fixed_point);
    assert_eq!(a.gait.eigenvalues, b.gait.eigenvalues);
    assert_eq!(
        serde_json::to_string(&here.generations).unwrap(),
        serde_json::to_string(&there.generations).unwrap()
    );
    // one batch per generation (and the last single mean, when the budget leaves one)
    assert_eq!(batches.load(Ordering::Relaxed), there.generations.len());
}

#[test]
fn an_evaluation_crosses_cbor_bit_for_bit_infinities_and_nan_included() {
    let scene = Scene::load("compass").unwrap();
    let (newton, homotopy) = (NewtonSettings::default(), HomotopySettings::default());
    let params = params();
    let s = settings(&params, &newton, &homotopy);
    let mut e = evaluate_drawn(&scene, &s, &[vec![0.3, -0.25]], &|| {}).unwrap()[0].clone();
    assert!(e.outside_bounds > 0.0);
    e.constrained.insert("mfpt".into(), f64::INFINITY);
    e.constrained.insert("gsn".into(), f64::NAN);
    e.value = Some(-0.0);
    let back = Evaluation::from_cbor(&e.to_cbor()).unwrap();
    assert!(back.constrained["mfpt"].is_infinite() && back.constrained["gsn"].is_nan());
    assert_eq!(back.value.unwrap().to_bits(), (-0.0f64).to_bits());
    assert_eq!(back.normalised, e.normalised);
    assert_eq!(back.fitness.to_bits(), e.fitness.to_bits());
    assert!(Evaluation::from_cbor(b"not cbor").is_err());
}

#[test]
fn an_evaluator_that_answers_for_other_designs_or_too_few_is_refused() {
    let scene = Scene::load("compass").unwrap();
    let (newton, homotopy) = (NewtonSettings::default(), HomotopySettings::default());
    let params = params();
    let s = settings(&params, &newton, &homotopy);
    let shifted = |drawn: &[Vec<f64>]| -> Result<Vec<Evaluation>, OptimizeError> {
        let other: Vec<Vec<f64>> = drawn.iter().map(|u| vec![u[0] + 1e-3, u[1]]).collect();
        evaluate_drawn(&scene, &s, &other, &|| {})
    };
    let err = optimize_with(&scene, &s, &|| {}, Some(&shifted)).unwrap_err();
    assert!(err.to_string().contains("another design"), "{err}");
    let short = |drawn: &[Vec<f64>]| -> Result<Vec<Evaluation>, OptimizeError> {
        evaluate_drawn(&scene, &s, &drawn[1..], &|| {})
    };
    let err = optimize_with(&scene, &s, &|| {}, Some(&short)).unwrap_err();
    assert!(err.to_string().contains("evaluations for"), "{err}");
    let wrong_size = evaluate_drawn(&scene, &s, &[vec![0.5]], &|| {}).unwrap_err();
    assert!(
        wrong_size.to_string().contains("coordinates"),
        "{wrong_size}"
    );
}
