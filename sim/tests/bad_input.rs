//! Bad input to the engine gets a typed error naming what was wrong: never a panic, a stack
//! overflow or a stride that runs forever (issue #14).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use sim::engine::integrators::{IntegratorChoice, IntegratorError};
use sim::scene::expr::ExprError;
use sim::scene::{Scene, SceneError, BUILTIN};
use sim::stride::{FailureKind, StrideSettings};

/// The text of a built-in scene.
fn builtin(name: &str) -> &'static str {
    BUILTIN.iter().find(|(n, _)| *n == name).unwrap().1
}

/// A built-in scene's text with `from` replaced by `to` (which must occur in it).
fn edited(name: &str, from: &str, to: &str) -> String {
    let text = builtin(name);
    assert!(text.contains(from), "`{from}` is not in scene {name}");
    text.replacen(from, to, 1)
}

/// Parses and builds a scene text.
fn setup_of(text: &str) -> Result<sim::scene::Setup, SceneError> {
    Scene::parse("test.toml", text)?.setup()
}

// --- heel_strike.release ------------------------------------------------------------------

#[test]
fn an_empty_or_non_ascii_release_is_a_scene_error_not_a_panic() {
    for bad in [r#"[""]"#, r#"["é"]"#, r#"["t"]"#, r#"["txx"]"#, r#"["té"]"#] {
        let text = edited(
            "compass",
            r#"release = ["tx", "ty"]"#,
            &format!("release = {bad}"),
        );
        match setup_of(&text) {
            Err(SceneError::Invalid(m)) => assert!(m.contains("heel_strike.release"), "{m}"),
            other => panic!("release = {bad}: {other:?}"),
        }
    }
    // The six valid freedoms still build.
    let text = edited(
        "compass",
        r#"release = ["tx", "ty"]"#,
        r#"release = ["tx", "ty", "tz", "rx", "ry", "rz"]"#,
    );
    assert!(setup_of(&text).is_ok());
}

// --- expression nesting -------------------------------------------------------------------

#[test]
fn deeply_nested_scene_expressions_are_a_scene_error_not_a_stack_overflow() {
    let deep = format!("{}slope_rad{}", "(".repeat(20_000), ")".repeat(20_000));
    let signs = format!("{}slope_rad", "-".repeat(50_000));
    for e in [deep, signs] {
        let text = edited(
            "compass",
            r#"slope_rad = "slope_rad""#,
            &format!(r#"slope_rad = "{e}""#),
        );
        match setup_of(&text) {
            Err(SceneError::Expr(ExprError::TooDeep { max_depth, .. })) => {
                assert_eq!(max_depth, sim::scene::expr::MAX_DEPTH)
            }
            other => panic!("{:?}", other.map(|_| ())),
        }
    }
}

#[test]
fn deeply_nested_toml_is_a_file_error_not_a_stack_overflow() {
    let text = format!("x = {}", "[".repeat(100_000));
    assert!(matches!(
        Scene::parse("deep.toml", &text),
        Err(SceneError::File { .. })
    ));
    let text = format!("x = {}", "{ a = ".repeat(100_000));
    assert!(matches!(
        Scene::parse("deep.toml", &text),
        Err(SceneError::File { .. })
    ));
}

// --- [integrator] -------------------------------------------------------------------------

const COMPASS_INTEGRATOR: &str = r#"kind = "dop853"
rtol = 1e-12
atol = 1e-12
h_max_s = 0.05
max_stride_time_s = 5.0"#;

/// The compass scene's `[integrator]` replaced by `body`: the error of building it.
fn integrator_error(body: &str) -> IntegratorError {
    let text = edited("compass", COMPASS_INTEGRATOR, body);
    match setup_of(&text) {
        Err(SceneError::Integrator { scene, error }) => {
            assert_eq!(scene, "compass");
            error
        }
        other => panic!("[integrator] {body}: {:?}", other.map(|_| ())),
    }
}

#[test]
fn scene_integrator_values_that_would_loop_forever_are_scene_errors() {
    // h_max_s = 0 and h_s = 0 used to loop forever (steps that do not advance time).
    for (body, setting) in [
        ("kind = \"dopri5\"\nh_max_s = 0.0", "h_max_s"),
        ("kind = \"dop853\"\nh_max_s = -0.01", "h_max_s"),
        ("kind = \"rk4\"\nh_s = 0.0", "h_s"),
        ("kind = \"meijaard\"\nh_s = 0.0", "h_s"),
        ("kind = \"rk4\"\nh_s = nan", "h_s"),
        ("kind = \"dopri5\"\nrtol = 0.0", "rtol"),
        ("kind = \"dopri5\"\nrtol = -1e-8", "rtol"),
        ("kind = \"dop853\"\nrtol = 1e-8\natol = -1.0", "atol"),
        ("kind = \"dop853\"\nrtol = inf", "rtol"),
    ] {
        match integrator_error(body) {
            IntegratorError::NotPositive { setting: s, .. } => assert_eq!(s, setting, "{body}"),
            other => panic!("{body}: {other}"),
        }
    }
}

#[test]
fn a_fixed_step_too_small_for_the_stride_time_budget_is_a_scene_error_naming_it() {
    let e = integrator_error("kind = \"rk4\"\nh_s = 1e-9\nmax_stride_time_s = 5.0");
    match &e {
        IntegratorError::TooManySteps {
            setting,
            value,
            max_steps,
            ..
        } => {
            assert_eq!((*setting, *value), ("h_s", 1e-9));
            assert_eq!(*max_steps, StrideSettings::DEFAULT_MAX_STEPS);
        }
        other => panic!("{other}"),
    }
    assert!(e.to_string().contains("1e-9"), "{e}");
    // A bad time budget is named too.
    assert!(matches!(
        integrator_error("max_stride_time_s = -1.0"),
        IntegratorError::BadTimeBudget { value } if value == -1.0
    ));
    // The same step is fine for a short enough time budget, as is a plain 1 ms step.
    assert!(setup_of(&edited(
        "compass",
        COMPASS_INTEGRATOR,
        "kind = \"rk4\"\nh_s = 1e-3"
    ))
    .is_ok());
}

#[test]
fn every_builtin_scene_passes_the_integrator_checks() {
    for (name, _) in BUILTIN {
        let s = Scene::load(name).unwrap().setup();
        assert!(s.is_ok(), "{name}: {:?}", s.err());
    }
}

// --- IntegratorChoice from command-line values ----------------------------------------------

#[test]
fn integrator_choices_from_the_command_line_are_validated() {
    let (_, w) = common::walker("compass");
    let t = w.settings.max_stride_time_s;
    let budget = sim::stride::StrideSettings::DEFAULT_MAX_STEPS;
    for (kind, h) in [("rk4", 1e-300), ("meijaard", 1e-9)] {
        let c = IntegratorChoice::from_kind(kind, Some(h), None, None, None).unwrap();
        assert!(
            matches!(c.validate_with_budget(t, budget), Err(IntegratorError::TooManySteps { value, .. }) if value == h),
            "{kind} {h}"
        );
        let c = w.settings.integrator.with_tolerance_or_step(None, Some(h));
        // The scene's integrator is adaptive: a step does not apply and it stays valid.
        assert!(c.validate_with_budget(t, budget).is_ok());
    }
    for c in [
        IntegratorChoice::from_kind("dopri5", None, Some(-1e-6), None, None).unwrap(),
        IntegratorChoice::from_kind("rk4", Some(f64::NAN), None, None, None).unwrap(),
        IntegratorChoice::from_kind("meijaard", Some(0.0), None, None, None).unwrap(),
    ] {
        assert!(matches!(
            c.validate_with_budget(t, budget),
            Err(IntegratorError::NotPositive { .. })
        ));
    }
    let ok = IntegratorChoice::from_kind("rk4", Some(1e-3), None, None, None).unwrap();
    assert!(ok.validate_with_budget(t, budget).is_ok());
    assert!(
        ok.validate_with_budget(f64::NAN, budget).is_err(),
        "a NaN time budget"
    );
}

// --- stride budgets -----------------------------------------------------------------------

#[test]
fn a_stride_that_exceeds_its_step_budget_fails_naming_it() {
    let (_, mut w) = common::walker("compass");
    assert!(common::stride(&w, &w.guess.q, &w.guess.qd).is_ok());
    w.settings.max_steps = 10;
    let e = common::stride(&w, &w.guess.q, &w.guess.qd).unwrap_err();
    assert_eq!(e.kind, FailureKind::StepBudgetExceeded, "{e}");
    assert!(e.detail().contains("max_steps = 10"), "{}", e.detail());
    assert_eq!(
        serde_json::to_value(e.kind).unwrap(),
        serde_json::json!("step_budget_exceeded")
    );
}

#[test]
fn a_stride_that_exceeds_its_evaluation_budget_fails_naming_it() {
    let (_, mut w) = common::walker("compass");
    w.settings.max_evaluations = 100;
    let e = common::stride(&w, &w.guess.q, &w.guess.qd).unwrap_err();
    assert_eq!(e.kind, FailureKind::EvaluationBudgetExceeded, "{e}");
    assert!(
        e.detail().contains("max_evaluations = 100"),
        "{}",
        e.detail()
    );
    assert_eq!(
        serde_json::to_value(e.kind).unwrap(),
        serde_json::json!("evaluation_budget_exceeded")
    );
}

#[test]
fn steps_that_do_not_advance_time_end_in_the_default_step_budget() {
    // Settings that bypass validation: a zero largest step used to loop forever. With the
    // default budgets it ends after about 3 s of CPU time (measured; not asserted).
    let (_, mut w) = common::walker("compass");
    w.settings.integrator = IntegratorChoice::Dopri5 {
        rtol: 1e-8,
        atol: 1e-8,
        h_max_s: 0.0,
    };
    assert!(w.settings.validate().is_err());
    let e = common::stride(&w, &w.guess.q, &w.guess.qd).unwrap_err();
    assert!(
        matches!(
            e.kind,
            FailureKind::StepBudgetExceeded | FailureKind::EvaluationBudgetExceeded
        ),
        "{e}"
    );
    assert_eq!(e.t_stride_s, 0.0);
}

#[test]
fn default_budgets_are_far_above_what_a_stride_uses() {
    // The wisse3d stride from its guess (DOP853, 1e-12; measured: 932 evaluations) completes
    // within a thousandth of each default budget, with the same result: the defaults are over
    // a thousand times what it uses, in steps and in evaluations. (The largest stride of the
    // engine's tests, measured: 814 steps, 12,606 evaluations, DOP853 on the wisse walkers.)
    let (_, w) = common::walker("wisse3d");
    assert_eq!(w.settings.max_steps, StrideSettings::DEFAULT_MAX_STEPS);
    assert_eq!(
        w.settings.max_evaluations,
        StrideSettings::DEFAULT_MAX_EVALUATIONS
    );
    let r = common::stride(&w, &w.guess.q, &w.guess.qd).unwrap();
    assert!(r.evaluations > 900, "{}", r.evaluations);
    let mut thousandth = w.settings.clone();
    thousandth.max_steps = StrideSettings::DEFAULT_MAX_STEPS / 1000;
    thousandth.max_evaluations = StrideSettings::DEFAULT_MAX_EVALUATIONS / 1000;
    let small = w
        .walker
        .stride(
            &w.guess.q,
            &w.guess.qd,
            sim::stride::StrideRequest::new(&thousandth),
        )
        .unwrap_or_else(|f| panic!("within a thousandth of the default budgets: {f}"));
    assert_eq!(small.evaluations, r.evaluations);
    assert_eq!(small.q_next, r.q_next);
    // And a budget that binds: half of what the stride needs fails it, naming the budget.
    let mut tight = thousandth.clone();
    tight.max_evaluations = r.evaluations / 2;
    let f = w
        .walker
        .stride(
            &w.guess.q,
            &w.guess.qd,
            sim::stride::StrideRequest::new(&tight),
        )
        .unwrap_err();
    assert_eq!(f.kind, FailureKind::EvaluationBudgetExceeded, "{f}");
}

// --- [convention] -------------------------------------------------------------------------

#[test]
fn convention_errors_are_scene_errors_at_build_time() {
    let unknown = edited(
        "compass",
        "coefficients = { stance_leg = -1.0 }",
        "coefficients = { stance_legg = -1.0 }",
    );
    match setup_of(&unknown) {
        Err(SceneError::Invalid(m)) => assert!(m.contains("stance_legg"), "{m}"),
        other => panic!("{:?}", other.map(|_| ())),
    }
    let nan_scale = edited("compass", "time_scale_s = 1.0", r#"time_scale_s = "0/0""#);
    assert!(matches!(
        setup_of(&nan_scale),
        Err(SceneError::NonFinite { what, .. }) if what.contains("time_scale_s")
    ));
    let zero_scale = edited("compass", "time_scale_s = 1.0", "time_scale_s = 0.0");
    assert!(matches!(
        setup_of(&zero_scale),
        Err(SceneError::Invalid(m)) if m.contains("time_scale_s")
    ));
    let nan_coefficient = edited(
        "compass",
        "coefficients = { stance_leg = -1.0 }",
        "coefficients = { stance_leg = nan }",
    );
    assert!(matches!(
        setup_of(&nan_coefficient),
        Err(SceneError::NonFinite { what, .. }) if what.contains("stance_leg")
    ));
    let bad_offset = edited("compass", r#"offset = "slope_rad""#, r#"offset = "1/0""#);
    assert!(matches!(
        setup_of(&bad_offset),
        Err(SceneError::NonFinite { .. })
    ));
}

// --- [variant] ----------------------------------------------------------------------------

#[test]
fn a_typo_in_a_variant_table_is_rejected() {
    let text = edited("wisse2d", "weld = [", "wled = [");
    match Scene::parse("typo.toml", &text) {
        Err(SceneError::File { message, .. }) => assert!(message.contains("wled"), "{message}"),
        other => panic!("{:?}", other.map(|s| s.name().to_string())),
    }
    let text = edited("wisse2d", "base = \"wisse3d\"", "base = 3");
    assert!(Scene::parse("typo.toml", &text).is_err());
}

#[test]
fn parameters_of_bodies_a_variant_removed_cannot_be_set() {
    for (scene, param, base) in [
        ("wisse3d-uncompensated", "pelvis_mass_kg", "wisse3d"),
        (
            "wisse3d-uncompensated",
            "pelvis_yaw_stiffness_n_m_per_rad",
            "wisse3d",
        ),
        ("wisse2d", "pelvis_yaw_stiffness_n_m_per_rad", "wisse3d"),
        (
            "wisse2d-uncompensated",
            "pelvis_mass_kg",
            "wisse3d-uncompensated",
        ),
    ] {
        let mut s = Scene::load(scene).unwrap();
        assert!(s.is_unused(param), "{scene} {param}");
        let current = s.values[param];
        let e = s
            .set_text(&format!("{param}={}", current * 2.0 + 1.0))
            .unwrap_err();
        match &e {
            SceneError::UnusedParameter {
                scene: sc,
                name,
                variant_of,
            } => {
                assert_eq!((sc.as_str(), name.as_str()), (scene, param));
                assert_eq!(variant_of.as_deref(), Some(base));
            }
            other => panic!("{other}"),
        }
        assert!(e.to_string().contains(base), "{e}");
        assert_eq!(s.values[param], current, "nothing changed");
        // Setting it to its own value changes nothing and is accepted (a walk copies shared
        // values between scenes).
        s.set(param, current).unwrap();
    }
    // The parameters the variant kept still take effect.
    let mut s = Scene::load("wisse2d").unwrap();
    assert!(!s.is_unused("pelvis_mass_kg"));
    s.set("pelvis_mass_kg", 5.0).unwrap();
    // And on the full walker the pelvic spring is a parameter like any other.
    let mut s = Scene::load("wisse3d").unwrap();
    s.set("pelvis_yaw_stiffness_n_m_per_rad", 10.0).unwrap();
    assert_eq!(
        Scene::load("wisse2d-uncompensated")
            .unwrap()
            .variant_bases(),
        ["wisse3d-uncompensated", "wisse3d"]
    );
}

#[test]
fn every_parameter_of_a_scene_that_is_not_a_variant_is_used() {
    // Guards the list of expressions the usage check reads: a field it missed would make a
    // used parameter look unused here.
    for (name, _) in BUILTIN {
        let s = Scene::load(name).unwrap();
        if s.variant_bases().is_empty() {
            let unused: Vec<_> = s.values.keys().filter(|k| s.is_unused(k)).collect();
            assert!(unused.is_empty(), "{name}: {unused:?}");
        }
    }
}
