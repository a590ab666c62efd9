//! JSON reports of gaits, walks and sweeps: the output contract other tools read.

use crate::continuation::{StabilityBoundary, SweepPoint};
use crate::limit_cycle::{Gait, NewtonError};
use crate::scene::Scene;
use crate::stability::modes;
use crate::stride::{StrideOptions, StrideRequest, StrideSettings};
use crate::walk::Walk;
use crate::walker::Walker;
use serde_json::{json, Map, Value};

/// The fixed point as `name → value`: coordinates, their rates (`_dot`), and the scene's
/// convention outputs.
pub fn fixed_point_object(scene: &Scene, walker: &Walker, gait: &Gait) -> Value {
    let mut m = Map::new();
    for (name, v) in walker.map_names().iter().zip(gait.fixed_point.iter()) {
        m.insert(name.clone(), json!(v));
    }
    let (q, qd) = walker.unpack(&gait.fixed_point);
    if let Ok(extra) = scene.convention_outputs(walker, &q, &qd) {
        for (k, v) in extra {
            m.insert(k, json!(v));
        }
    }
    Value::Object(m)
}

/// Gait summary numbers.
pub struct GaitNumbers {
    /// Step period [s].
    pub step_period_s: f64,
    /// Step length [m].
    pub step_length_m: f64,
    /// Distance walked per step, forward [m].
    pub progress_m: f64,
    /// Speed [m/s].
    pub speed_m_s: f64,
}

/// Period, step length and speed of a gait.
pub fn gait_numbers(walker: &Walker, gait: &Gait) -> GaitNumbers {
    let step_period_s = gait.stride.duration_s;
    let step_length_m = gait.stride.step_m.norm();
    let progress_m = forward_progress_m(walker, gait);
    GaitNumbers {
        step_period_s,
        step_length_m,
        progress_m,
        speed_m_s: progress_m / step_period_s,
    }
}

/// Distance walked per step [m]: half the displacement over two periodic steps, `|c + M c| / 2`
/// with `c` the step between contacts and `M` the map from one stance frame to the next
/// (reflection and heading). For a 3D walker this leaves out the sideways zigzag between the
/// feet, which `step_length_m` (the distance between the contacts) includes.
pub fn forward_progress_m(walker: &Walker, gait: &Gait) -> f64 {
    let c = gait.stride.step_m;
    let next = crate::walk::FloorFrame::default().next(
        &c,
        gait.stride.heading_change_rad,
        walker.relabel.mirror,
    );
    (c + next.r * c).norm() / 2.0
}

/// The `walker gait --json` object.
pub fn gait_json(
    scene: &Scene,
    walker: &Walker,
    settings: &StrideSettings,
    result: &Result<Gait, NewtonError>,
) -> Value {
    let mut map = Map::new();
    let o = &mut map;
    o.insert("scene".into(), json!(scene.name()));
    o.insert("parameters".into(), json!(scene.values));
    o.insert("integrator".into(), json!(settings.integrator));
    match result {
        Err(e) => {
            o.insert("converged".into(), json!(false));
            o.insert("error".into(), json!(e.to_string()));
            for k in [
                "fixed_point",
                "eigenvalues",
                "max_abs_eigenvalue",
                "stable",
                "step_period_s",
                "step_length_m",
                "speed_m_s",
            ] {
                o.insert(k.into(), Value::Null);
            }
            let iterations = match e {
                NewtonError::NotConverged { iterations, .. } => json!(iterations),
                NewtonError::StrideFailed { iteration, failure } => {
                    o.insert("failure".into(), json!(failure));
                    json!(iteration)
                }
                NewtonError::Singular { iteration } => json!(iteration),
            };
            o.insert("newton_iterations".into(), iterations);
        }
        Ok(g) => {
            let n = gait_numbers(walker, g);
            let mass = walker.model.total_mass_kg();
            let g_m_s2 = walker.model.gravity_floor_m_s2.norm();
            o.insert("converged".into(), json!(true));
            o.insert("fixed_point".into(), fixed_point_object(scene, walker, g));
            o.insert(
                "eigenvalues".into(),
                json!(g
                    .eigenvalues
                    .iter()
                    .map(|z| [z.re, z.im])
                    .collect::<Vec<_>>()),
            );
            o.insert("max_abs_eigenvalue".into(), json!(g.max_abs_eigenvalue()));
            o.insert("stable".into(), json!(g.stable()));
            o.insert("step_period_s".into(), json!(n.step_period_s));
            o.insert("step_length_m".into(), json!(n.step_length_m));
            o.insert("progress_m_per_step".into(), json!(n.progress_m));
            o.insert("speed_m_s".into(), json!(n.speed_m_s));
            o.insert("newton_iterations".into(), json!(g.iterations));
            o.insert("jacobian_method".into(), json!(g.jacobian_method));
            o.insert("residual".into(), json!(g.residual));
            o.insert("events".into(), json!(g.stride.events));
            o.insert(
                "impact_energy_loss_j".into(),
                json!(g.stride.impact_energy_loss_j),
            );
            if mass > 0.0 && n.step_length_m > 0.0 {
                o.insert(
                    "specific_cost_of_transport".into(),
                    json!(g.stride.impact_energy_loss_j / (mass * g_m_s2 * n.step_length_m)),
                );
            }
            o.insert(
                "heading_change_rad_per_step".into(),
                json!(g.stride.heading_change_rad),
            );
            o.insert("total_mass_kg".into(), json!(mass));
            let names = walker.map_names();
            o.insert(
                "eigenvalue_modes".into(),
                json!(modes(
                    &g.jacobian,
                    &g.eigenvalues,
                    &names,
                    &walker.three_d_freedoms
                )),
            );
            if walker.ankle.is_some() {
                let s = &g.stride;
                o.insert("actuator_work_j_per_step".into(), json!(s.actuator_work_j));
                o.insert(
                    "damping_dissipation_j_per_step".into(),
                    json!(s.damping_dissipation_j),
                );
                o.insert(
                    "cost_of_transport_J_per_kg_m".into(),
                    json!(s.actuator_work_j / (mass * n.progress_m)),
                );
                // Over a periodic stride on level ground the actuator's work is what the impacts
                // and dampers take: the difference checks the quadrature.
                o.insert(
                    "energy_balance_residual_j".into(),
                    json!(s.actuator_work_j - s.impact_energy_loss_j - s.damping_dissipation_j),
                );
            }
            let (q, qd) = walker.unpack(&g.fixed_point);
            if let Ok(c) = walker.stride(
                &q,
                &qd,
                StrideRequest::new(settings).options(StrideOptions {
                    record: false,
                    contact: true,
                }),
            ) {
                o.insert(
                    "max_lateral_cop_m".into(),
                    json!(c.contact.max_lateral_cop_m),
                );
                o.insert(
                    "min_normal_force_n".into(),
                    json!(c.contact.min_normal_force_n),
                );
                o.insert(
                    "mid_swing_clearance_m".into(),
                    json!(c.contact.mid_swing_clearance_m),
                );
            }
        }
    }
    Value::Object(map)
}

/// The `walker walk --json` object.
pub fn walk_json(scene: &Scene, walk: &Walk) -> Value {
    json!({
        "scene": scene.name(),
        "parameters": scene.values,
        "steps_completed": walk.steps_completed,
        "failure": walk.failure,
        "steps": walk.steps,
    })
}

/// The `walker sweep --json` object.
pub fn sweep_json(
    scene: &Scene,
    walker_for: &dyn Fn(f64) -> Option<(Scene, Walker)>,
    param: &str,
    points: &[SweepPoint],
    boundaries: &[StabilityBoundary],
) -> Value {
    let pts: Vec<Value> = points
        .iter()
        .map(|p| match &p.gait {
            Ok(g) => {
                let fp = walker_for(p.value)
                    .map(|(s, w)| fixed_point_object(&s, &w, g))
                    .unwrap_or(Value::Null);
                json!({
                    "parameter": param,
                    "value": p.value,
                    "converged": true,
                    "max_abs_eigenvalue": g.max_abs_eigenvalue(),
                    "stable": g.stable(),
                    "eigenvalues": g.eigenvalues.iter().map(|z| [z.re, z.im]).collect::<Vec<_>>(),
                    "fixed_point": fp,
                    "step_period_s": g.stride.duration_s,
                    "step_length_m": g.stride.step_m.norm(),
                })
            }
            Err(e) => json!({
                "parameter": param,
                "value": p.value,
                "converged": false,
                "max_abs_eigenvalue": null,
                "stable": false,
                "fixed_point": null,
                "error": e.to_string(),
            }),
        })
        .collect();
    json!({
        "scene": scene.name(),
        "param": param,
        "points": pts,
        "stability_boundaries": boundaries
            .iter()
            .map(|b| json!({"value": b.value, "change": b.change}))
            .collect::<Vec<_>>(),
    })
}

/// Gait figures averaged over the last `last` completed steps of a walk: `step_period_s`,
/// `step_length_m`, `speed_m_s`, `cost_of_transport_J_per_kg_m`, `heading_change_rad_per_step`
/// (mean magnitude of the per-step yaw in each step's mirrored stance frame: the zigzag, not a
/// turn), `heading_change_rad_per_step_signed` (its signed mean) and `heading_rad` (direction
/// of travel of the hip over those steps in the floor frame, `atan2(Δz, Δx)`: 0 straight
/// ahead along the first stance frame's x, positive toward +z; `null` with fewer than two
/// steps), with the number of steps used. `Null` if no step completed.
pub fn walk_gait_json(walker: &Walker, walk: &Walk, last: usize) -> Value {
    let n = walk.steps.len().min(last);
    if n == 0 {
        return Value::Null;
    }
    let steps = &walk.steps[walk.steps.len() - n..];
    let mean =
        |f: &dyn Fn(&crate::walk::StepSummary) -> f64| steps.iter().map(f).sum::<f64>() / n as f64;
    let period = mean(&|s| s.duration_s);
    let length = mean(&|s| s.step_length_m);
    let work = mean(&|s| s.actuator_work_j);
    // Distance walked per step: hip displacement over an even number of steps (so that the
    // sideways zigzag cancels), divided by that number.
    let k = if n >= 3 { (n - 1) / 2 * 2 } else { n - 1 };
    let (progress, heading) = if k == 0 {
        (length, Value::Null)
    } else {
        let a = &steps[n - 1 - k].hip_floor_m;
        let b = &steps[n - 1].hip_floor_m;
        let (dx, dz) = (b[0] - a[0], b[2] - a[2]);
        ((dx * dx + dz * dz).sqrt() / k as f64, json!(dz.atan2(dx)))
    };
    json!({
        "steps_averaged": n,
        "step_period_s": period,
        "step_length_m": length,
        "progress_m_per_step": progress,
        "speed_m_s": progress / period,
        "cost_of_transport_J_per_kg_m": work / (walker.model.total_mass_kg() * progress),
        "heading_change_rad_per_step": mean(&|s| s.heading_change_rad.abs()),
        "heading_rad": heading,
        "heading_change_rad_per_step_signed": mean(&|s| s.heading_change_rad),
    })
}

/// The same figures for a gait's fixed point.
pub fn ideal_gait_json(walker: &Walker, gait: &Gait) -> Value {
    let n = gait_numbers(walker, gait);
    json!({
        "step_period_s": n.step_period_s,
        "step_length_m": n.step_length_m,
        "speed_m_s": n.speed_m_s,
        "cost_of_transport_J_per_kg_m": gait.stride.actuator_work_j / (walker.model.total_mass_kg() * n.progress_m),
        "progress_m_per_step": n.progress_m,
        "heading_change_rad_per_step": gait.stride.heading_change_rad.abs(),
        "max_abs_eigenvalue": gait.max_abs_eigenvalue(),
    })
}
