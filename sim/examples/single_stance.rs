//! Our side of `scripts/bench-vs-engines`: wisse3d's single stance from its gait's start (the
//! fixed point, just after heel strike) to its first event, in a form another engine can
//! rebuild and compare. Prints one JSON object to stdout:
//! - the model as a tree (each link: name, parent, joint kind, axis and origin in the parent
//!   frame, coordinate, mass, centre of mass and inertia about it in link axes, spring
//!   stiffness and rest position, damping) and gravity (floor frame);
//! - the coordinates free in the first phase and those locked there (with their values), the
//!   start (`q`, `q̇`) and our `q̈` there from the phase's equations of motion, and `q̈` at a
//!   few other states (along the phase and perturbed) for the other engines to check theirs;
//! - the first event's name and time `T` (from a stride at the scene's settings), and a check
//!   that the phase is smooth on `[0, T]`: our stride at the tightest tolerance reaches the same
//!   first event and state as a plain integration to `T`;
//! - for each `--rtol R` (several may be given) and each `--h-max-s H` (several may be given;
//!   default the scene's largest step): the first phase integrated to `T` (a fixed end time, no
//!   event location) by DOP853 at rtol = atol = R and largest step H, the state at `T`, the
//!   evaluations and the wall time (best of `--repeats`, default 20).
//!
//! `cargo run --release -p sim --example single_stance -- --rtol 1e-14 --rtol 1e-8 --repeats 50`
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use nalgebra::{DVector, Matrix3, Vector3};
use serde_json::{json, Value};
use sim::engine::integrators::{Integrator, IntegratorChoice, Sample, SecondOrderSystem};
use sim::engine::model::{JointKind, Model};
use sim::scene::Scene;
use sim::stride::{Phase, StrideRequest};
use std::error::Error;
use std::time::Instant;

fn vec3(v: &Vector3<f64>) -> Value {
    json!([v.x, v.y, v.z])
}

fn mat3(m: &Matrix3<f64>) -> Value {
    json!((0..3)
        .map(|i| (0..3).map(|j| m[(i, j)]).collect::<Vec<_>>())
        .collect::<Vec<_>>())
}

fn dvec(v: &DVector<f64>) -> Value {
    json!(v.iter().copied().collect::<Vec<_>>())
}

fn model_json(model: &Model) -> Value {
    let links: Vec<Value> = model
        .links
        .iter()
        .map(|l| {
            let (kind, axis) = match &l.joint {
                JointKind::Revolute { axis_parent } => ("revolute", vec3(axis_parent)),
                JointKind::Prismatic { axis_parent } => ("prismatic", vec3(axis_parent)),
                JointKind::Weld => ("weld", Value::Null),
            };
            json!({
                "name": l.name,
                "parent": l.parent.map(|p| model.links[p.0].name.clone()),
                "joint": kind,
                "axis": axis,
                "origin_m": vec3(&l.p_parent_joint_m),
                "coordinate": l.coordinate.map(|c| model.coordinates[c.0].name.clone()),
                "coordinate_index": l.coordinate.map(|c| c.0),
                "mass_kg": l.body.mass_kg,
                "com_m": vec3(&l.body.p_link_com_m),
                "inertia_com_kg_m2": mat3(&l.body.inertia_com_kg_m2),
                "infinitesimal": l.body.infinitesimal,
                "stiffness": l.joint_force.stiffness,
                "rest_position": l.joint_force.rest_position,
                "damping": l.joint_force.damping,
            })
        })
        .collect();
    json!({
        "links": links,
        "coordinates": model.coordinates.iter().map(|c| c.name.clone()).collect::<Vec<_>>(),
        "gravity_m_s2": vec3(&model.gravity_floor_m_s2),
    })
}

/// The first phase integrated from `start` to `t_end_s` by `integrator` (fixed end time).
fn integrate(
    integrator: &mut dyn Integrator,
    phase: &mut Phase<'_>,
    start: &Sample,
    t_end_s: f64,
) -> Result<(Sample, Vec<Sample>), Box<dyn Error>> {
    integrator.reset();
    let mut s = start.clone();
    let mut steps = Vec::new();
    while s.t_s < t_end_s {
        let left = t_end_s - s.t_s;
        s = integrator.advance(phase, &s, left)?;
        // The last step lands on the end time up to rounding of `t + (T − t)`.
        if (t_end_s - s.t_s).abs() <= 4.0 * f64::EPSILON * t_end_s {
            s.t_s = t_end_s;
        }
        steps.push(s.clone());
    }
    Ok((s, steps))
}

fn main() -> Result<(), Box<dyn Error>> {
    let mut rtols = Vec::new();
    let mut h_maxes_s: Vec<f64> = Vec::new();
    let mut repeats = 20usize;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--rtol" => rtols.push(value()?.parse::<f64>()?),
            "--h-max-s" => h_maxes_s.push(value()?.parse::<f64>()?),
            "--repeats" => repeats = value()?.parse::<usize>()?.max(1),
            other => return Err(format!("unknown argument {other}").into()),
        }
    }
    let setup = Scene::load("wisse3d")?.setup()?;
    let walker = &setup.walker;
    let model = walker.model();
    let gait = setup.find_gait(&Default::default())?;
    let (q0, qd0) = walker.unpack(&gait.fixed_point);
    let h_max_s = match setup.settings.integrator {
        IntegratorChoice::Dop853 { h_max_s, .. } => h_max_s,
        _ => return Err("wisse3d's integrator is not DOP853".into()),
    };
    if h_maxes_s.iter().any(|h| !(h.is_finite() && *h > 0.0)) {
        return Err("--h-max-s must be a positive number of seconds".into());
    }
    if h_maxes_s.is_empty() {
        h_maxes_s.push(h_max_s);
    }

    // The first phase: every coordinate free but those locked at a stride's start.
    let mut phase = Phase::with_path(model, setup.settings.evaluation);
    for c in walker.initially_locked() {
        phase.active[c.0] = false;
    }
    if phase.prescribed.is_some() {
        return Err("the first phase drives a coordinate".into());
    }
    let active: Vec<String> = (0..model.dof())
        .filter(|&i| phase.active[i])
        .map(|i| model.coordinates[i].name.clone())
        .collect();
    let locked: Vec<Value> = (0..model.dof())
        .filter(|&i| !phase.active[i])
        .map(|i| json!({"name": model.coordinates[i].name, "value": q0[i], "rate": qd0[i]}))
        .collect();
    let qdd0 = phase.accelerations(0.0, &q0, &qd0)?;

    // The first event, from the stride at the scene's settings and at the tightest tolerance.
    let first_event = |rtol: f64| -> Result<_, Box<dyn Error>> {
        let settings = setup.settings.with_integrator(IntegratorChoice::Dop853 {
            rtol,
            atol: rtol,
            h_max_s,
        });
        let r = walker.stride(&q0, &qd0, StrideRequest::new(&settings))?;
        let e = r.events.first().ok_or("the stride has no event")?.clone();
        let before = r.event_states.first().ok_or("no event state")?.0.clone();
        let names: Vec<String> = r.events.iter().map(|e| e.name.clone()).collect();
        Ok((e, before, names))
    };
    let (event, _, event_names) = first_event(1e-12)?;
    let (event_tight, before_tight, _) = first_event(1e-14)?;
    let t_end_s = event.t_stride_s;

    let start = Sample {
        t_s: 0.0,
        q: q0.clone(),
        qd: qd0.clone(),
    };
    let build = |rtol: f64, h_max_s: f64| {
        IntegratorChoice::Dop853 {
            rtol,
            atol: rtol,
            h_max_s,
        }
        .build()
    };
    // Smoothness: the tight plain integration to the tight stride's event time lands on the
    // tight stride's pre-event state (no event, no impact inside [0, T]).
    let mut tight = build(1e-14, h_max_s);
    let (end_tight, steps_tight) =
        integrate(tight.as_mut(), &mut phase, &start, event_tight.t_stride_s)?;
    let smooth_diff = (&end_tight.q - &before_tight.q)
        .amax()
        .max((&end_tight.qd - &before_tight.qd).amax());

    // Accelerations at other states for the cross-check: along the phase and perturbed.
    let mut checks = vec![json!({"q": dvec(&q0), "qd": dvec(&qd0), "qdd": dvec(&qdd0)})];
    let n = steps_tight.len();
    for k in [n / 4, n / 2, (3 * n) / 4, n - 1] {
        let s = &steps_tight[k];
        let a = phase.accelerations(s.t_s, &s.q, &s.qd)?;
        checks.push(json!({"t_s": s.t_s, "q": dvec(&s.q), "qd": dvec(&s.qd), "qdd": dvec(&a)}));
    }
    for (k, scale) in [(1usize, 0.3), (2, 1.0)] {
        // A deterministic perturbation of the free coordinates and rates.
        let mut q = q0.clone();
        let mut qd = qd0.clone();
        for i in 0..model.dof() {
            if phase.active[i] {
                let x = ((i + 1) * (k + 2)) as f64;
                q[i] += scale * 0.4 * x.sin();
                qd[i] += scale * 2.0 * (1.7 * x).cos();
            }
        }
        let a = phase.accelerations(0.0, &q, &qd)?;
        checks.push(json!({"q": dvec(&q), "qd": dvec(&qd), "qdd": dvec(&a)}));
    }

    let mut runs = Vec::new();
    for (&h_max_s, &rtol) in h_maxes_s
        .iter()
        .flat_map(|h| rtols.iter().map(move |r| (h, r)))
    {
        let mut integrator = build(rtol, h_max_s);
        let mut best = f64::INFINITY;
        let mut end = start.clone();
        let mut evaluations = 0;
        let mut steps = 0;
        for _ in 0..repeats {
            let clock = Instant::now();
            let (e, s) = integrate(integrator.as_mut(), &mut phase, &start, t_end_s)?;
            best = best.min(clock.elapsed().as_secs_f64());
            evaluations = integrator.evaluations();
            steps = s.len();
            end = e;
        }
        runs.push(json!({
            "rtol": rtol,
            "atol": rtol,
            "h_max_s": h_max_s,
            "t_end_s": end.t_s,
            "q": dvec(&end.q),
            "qd": dvec(&end.qd),
            "evaluations": evaluations,
            "steps": steps,
            "seconds_min": best,
            "repeats": repeats,
        }));
    }

    let out = json!({
        "scene": "wisse3d",
        "model": model_json(model),
        "fixed_point_residual": gait.residual,
        "active": active,
        "locked": locked,
        "q0": dvec(&q0),
        "qd0": dvec(&qd0),
        "qdd0": dvec(&qdd0),
        "acceleration_checks": checks,
        "evaluation_path": format!("{:?}", setup.settings.evaluation),
        "phase_fast_path": phase.is_axis_tree_fast_path(),
        "first_event": {"name": event.name, "time_s": t_end_s,
                        "time_s_at_rtol_1e-14": event_tight.t_stride_s},
        "stride_events": event_names,
        "smooth_check": {
            "description": "plain DOP853 rtol 1e-14 integration to the tight stride's first event time against that stride's pre-event state (inf-norm)",
            "difference": smooth_diff,
            "steps": steps_tight.len(),
        },
        "runs": runs,
    });
    println!("{out}");
    Ok(())
}
