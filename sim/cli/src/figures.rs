//! The paper's figures from our results: eigenvalues in the complex plane (Figs. 11, 13), the
//! floor path of the hip-axle centre (Fig. 12), joint angles over a step, the accuracy
//! study's log-log panels and the orbit diagram. The sweep's bifurcation diagrams are in
//! [`crate::sweep_figures`]. Labels are words with units ([`crate::labels`]).

use crate::axis::Scale;
use crate::labels::{
    coordinate_label, failure_label, integrator_label, parameter_label, step_label, walker_name,
};
use crate::plot::{Aspect, Marker, Note, Plot, Series, Style, PALETTE};
use sim::analysis::limit_cycle::Gait;
use sim::analysis::stability::modes;
use sim::engine::integrators::Sample;
use sim::engine::model::JointKind;
use sim::engine::walker::Walker;
use sim::scene::Scene;
use sim::stride::walk::Walk;

/// Eigenvalues closer than this (in the complex plane) are drawn as one marker with a count.
const COINCIDENT: f64 = 0.02;

/// Groups `points` into clusters of points within [`COINCIDENT`] of the cluster's first:
/// each cluster's first point and its size.
fn clusters(points: &[(f64, f64)]) -> Vec<((f64, f64), usize)> {
    let mut out: Vec<((f64, f64), usize)> = Vec::new();
    for &p in points {
        match out
            .iter_mut()
            .find(|(c, _)| (c.0 - p.0).hypot(c.1 - p.1) < COINCIDENT)
        {
            Some((_, n)) => *n += 1,
            None => out.push((p, 1)),
        }
    }
    out
}

/// Eigenvalues with a modulus below this crowd the origin: the figure's caption lists them.
const NEAR_ZERO: f64 = 0.05;

/// The caption naming the eigenvalues that crowd the origin (`None` if at most one does):
/// how many are 0, and the others' values, 3D modes marked.
fn near_zero_caption(modes: &[sim::analysis::stability::EigenMode]) -> Option<String> {
    let near: Vec<&sim::analysis::stability::EigenMode> = modes
        .iter()
        .filter(|e| e.eigenvalue[0].hypot(e.eigenvalue[1]) < NEAR_ZERO)
        .collect();
    if near.len() < 2 {
        return None;
    }
    // Zero to the three decimals the caption gives.
    const ZERO: f64 = 5e-4;
    let zeros = near
        .iter()
        .filter(|e| e.eigenvalue[0].hypot(e.eigenvalue[1]) < ZERO)
        .count();
    if zeros == near.len() {
        return Some(format!("{zeros} eigenvalues at 0"));
    }
    let mut parts = Vec::new();
    if zeros > 0 {
        parts.push(format!("{zeros} at 0"));
    }
    for e in near
        .iter()
        .filter(|e| e.eigenvalue[0].hypot(e.eigenvalue[1]) >= ZERO)
    {
        let [re, im] = e.eigenvalue;
        let v = if im.abs() < 1e-12 {
            format!("{re:.3}")
        } else {
            format!("{re:.3}{im:+.3}i")
        };
        let v = v.replace('-', "−");
        parts.push(if e.three_d { format!("{v} (3D)") } else { v });
    }
    Some(format!(
        "{} eigenvalues near the origin: {}",
        near.len(),
        parts.join(", ")
    ))
}

/// Eigenvalues of the stride Jacobian with the unit circle, true to scale; those whose
/// eigenvector is dominated by a freedom only the 3D model has are stars. Coincident
/// eigenvalues (several at 0, typically) are one marker with their count beside it.
pub fn eigenvalues(scene: &Scene, walker: &Walker, gait: &Gait) -> Plot {
    let m = modes(
        &gait.jacobian,
        &gait.eigenvalues,
        &walker.map_names(),
        walker.three_d_freedoms(),
    );
    let (three_d, plain): (Vec<_>, Vec<_>) = m.iter().partition(|e| e.three_d);
    let point = |e: &&sim::analysis::stability::EigenMode| (e.eigenvalue[0], e.eigenvalue[1]);
    let mut series = Vec::new();
    let mut notes = Vec::new();
    // Legend label, points, marker, offset of a count note [px].
    type Group<'a> = (&'a str, Vec<(f64, f64)>, Marker, (f64, f64));
    let groups: [Group; 2] = [
        (
            if three_d.is_empty() {
                "eigenvalue"
            } else {
                "other eigenvalues"
            },
            plain.iter().map(point).collect(),
            Marker::Circle,
            (7.0, -7.0),
        ),
        (
            "3D mode (yaw, roll)",
            three_d.iter().map(point).collect(),
            Marker::Star,
            (7.0, 17.0),
        ),
    ];
    for (i, (label, points, marker, offset_px)) in groups.into_iter().enumerate() {
        if points.is_empty() {
            continue;
        }
        let cl = clusters(&points);
        for &(at, n) in &cl {
            // Those near the origin are listed in the caption instead.
            if n > 1 && at.0.hypot(at.1) >= NEAR_ZERO {
                notes.push(Note {
                    at,
                    offset_px,
                    text: format!("×{n}"),
                });
            }
        }
        series.push(Series {
            label: label.into(),
            points: cl.into_iter().map(|(p, _)| p).collect(),
            style: Style::markers(marker),
            color: PALETTE[i],
        });
    }
    Plot {
        title: format!("{}: eigenvalues of the stride map", walker_name(scene)),
        caption: near_zero_caption(&m),
        x_label: "real part of λ".into(),
        y_label: "imaginary part of λ".into(),
        series,
        notes,
        aspect: Aspect::EQUAL,
        unit_circle: true,
        ..Plot::default()
    }
}

/// Nice magnifications of the sideways axis of a floor path.
const MAGNIFICATIONS: [f64; 10] = [1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0];

/// The path of the hip-axle centre on the floor for one or more walks (each with its scene):
/// forward against sideways, true to scale, or with the sideways axis magnified by a stated
/// round factor when the path would otherwise be a flat line in a figure of `width` ×
/// `height` pixels. A walk that fell says in which step (counted from 1) and how.
pub fn floor_paths(walks: &[(&Scene, &Walk)], (width, height): (f64, f64)) -> Plot {
    let series: Vec<Series> = walks
        .iter()
        .enumerate()
        .map(|(i, (scene, w))| Series {
            label: match &w.failure {
                Some(f) => format!(
                    "{} (falls in {}: {})",
                    walker_name(scene),
                    step_label(f.step),
                    failure_label(f.kind)
                ),
                None => format!("{} ({} steps)", walker_name(scene), w.steps_completed),
            },
            points: w
                .path
                .iter()
                .map(|s| (s.hip_floor_m.x, s.hip_floor_m.z))
                .collect(),
            style: if i == 0 { Style::LINE } else { Style::DASHED },
            color: PALETTE[i % PALETTE.len()],
        })
        .collect();
    let span = |f: fn(&(f64, f64)) -> f64| {
        let v = series.iter().flat_map(|s| s.points.iter().map(f));
        let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
        if hi > lo {
            hi - lo
        } else {
            0.0
        }
    };
    let (x_span, z_span) = (span(|p| p.0), span(|p| p.1));
    // The data area is about (width − 120) × (height − 160) px (legend below it).
    let fill = if z_span > 0.0 {
        (x_span / (width - 120.0)) / (z_span / (height - 160.0))
    } else {
        1.0
    };
    let magnification = MAGNIFICATIONS
        .iter()
        .copied()
        .filter(|m| *m <= fill.max(1.0))
        .fold(1.0, f64::max);
    let (y_label, caption) = if magnification > 1.0 {
        (
            format!("sideways z, to the right (m, drawn ×{magnification})"),
            Some(format!(
                "sideways distances magnified ×{magnification} against forward ones"
            )),
        )
    } else {
        ("sideways z, to the right (m)".to_string(), None)
    };
    Plot {
        title: "path of the hip-axle centre on the floor".into(),
        caption,
        x_label: "forward x (m)".into(),
        y_label,
        series,
        aspect: Aspect::Scaled {
            y_over_x: magnification,
        },
        ..Plot::default()
    }
}

/// Points per curve of the joint-angle figure (about; every recorded sample is kept too).
const CURVE_POINTS: f64 = 400.0;

/// `samples` (integrator steps, as recorded) with points between them on the cubic Hermite
/// interpolant of each step (from the coordinates and their rates at both ends: third order,
/// as the integrator's own dense output of Hermite type), about `per_s` per second. Two samples
/// at the same time (an impact) are kept as they are.
pub fn dense(samples: &[Sample], per_s: f64) -> Vec<Sample> {
    let mut out = Vec::with_capacity(samples.len());
    for w in samples.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        out.push(a.clone());
        let h = b.t_s - a.t_s;
        if !(h > 0.0 && h.is_finite()) {
            continue;
        }
        // At most 1000 points per step (the loop's budget).
        let n = ((h * per_s).ceil() as usize).clamp(1, 1000);
        for k in 1..n {
            let x = k as f64 / n as f64;
            let (q, qd) = sim::engine::hermite::vector((&a.q, &a.qd), (&b.q, &b.qd), h, x);
            out.push(Sample {
                t_s: a.t_s + x * h,
                q,
                qd,
            });
        }
    }
    if let Some(last) = samples.last() {
        out.push(last.clone());
    }
    out
}

/// `samples` (a stride's recording, which holds the state after each impact) with the state
/// just before each impact of `events` (`(before, after)` pairs, as
/// [`sim::stride::StrideResult::event_states`]) inserted before the sample at its time, so that
/// no interval of [`dense`] ends on a velocity from after an impact.
pub fn with_pre_impact_states(samples: &[Sample], events: &[(Sample, Sample)]) -> Vec<Sample> {
    let mut out: Vec<Sample> = Vec::with_capacity(samples.len() + events.len());
    for s in samples {
        let at_event = events
            .iter()
            .find(|(before, _)| (before.t_s - s.t_s).abs() <= 1e-12 * s.t_s.abs().max(1.0));
        if let Some((before, _)) = at_event {
            let already = out
                .last()
                .is_some_and(|p| p.t_s == before.t_s && p.qd == before.qd);
            if !already && s.qd != before.qd {
                out.push(before.clone());
            }
        }
        out.push(s.clone());
    }
    out
}

/// Every joint coordinate over one step, from that step's recorded `samples` and the states
/// before and after its impacts (`events`), made dense ([`dense`]); coordinates that stay at
/// zero are left out.
pub fn joint_angles(
    scene: &Scene,
    walker: &Walker,
    samples: &[Sample],
    events: &[(Sample, Sample)],
) -> Plot {
    let samples = with_pre_impact_states(samples, events);
    let samples = &samples[..];
    let duration_s = match (samples.first(), samples.last()) {
        (Some(a), Some(b)) if b.t_s > a.t_s => b.t_s - a.t_s,
        _ => 1.0,
    };
    let samples = dense(samples, CURVE_POINTS / duration_s);
    let coords = &walker.model().coordinates;
    let revolute = coords.iter().all(|c| {
        walker
            .model()
            .links
            .get(c.link.0)
            .is_none_or(|l| matches!(l.joint, JointKind::Revolute { .. }))
    });
    let series = coords
        .iter()
        .enumerate()
        .filter(|(i, _)| samples.iter().any(|s| s.q[*i].abs() > 1e-12))
        .enumerate()
        .map(|(k, (i, c))| Series {
            label: coordinate_label(&c.name),
            points: samples.iter().map(|s| (s.t_s, s.q[i])).collect(),
            style: if k < PALETTE.len() {
                Style::LINE
            } else {
                Style::DASHED
            },
            color: PALETTE[k % PALETTE.len()],
        })
        .collect();
    Plot {
        title: format!("{}: joint angles over one step", walker_name(scene)),
        x_label: "time from heel strike (s)".into(),
        y_label: if revolute {
            "joint angle (rad)".into()
        } else {
            "joint coordinate (rad or m)".into()
        },
        series,
        ..Plot::default()
    }
}

/// One log-log panel of a speed-against-error study: an error measure (`what`, with its unit)
/// against CPU time per stride, one line per integrator with a marker at each setting.
pub fn accuracy(
    scene: &Scene,
    study: &sim::analysis::accuracy::AccuracyStudy,
    error: fn(&sim::analysis::accuracy::AccuracyPoint) -> Option<f64>,
    what: &str,
) -> Plot {
    let mut families: Vec<String> = Vec::new();
    for p in &study.points {
        if !families.contains(&p.integrator) {
            families.push(p.integrator.clone());
        }
    }
    let series = families
        .iter()
        .enumerate()
        .map(|(i, f)| Series {
            label: integrator_label(f),
            points: study
                .points
                .iter()
                .filter(|p| &p.integrator == f)
                .filter_map(|p| error(p).map(|e| (p.cpu_us_per_stride, e)))
                .collect(),
            style: Style::LINE_CIRCLES,
            color: PALETTE[i % PALETTE.len()],
        })
        .collect();
    Plot {
        title: format!(
            "{}: {} against CPU time",
            walker_name(scene),
            what.split(" (").next().unwrap_or(what)
        ),
        x_label: "CPU time per stride (µs)".into(),
        y_label: what.into(),
        x_scale: Scale::Log10,
        y_scale: Scale::Log10,
        series,
        ..Plot::default()
    }
}

/// The orbit diagram: `coordinate` at heel strike on the attractor against the parameter,
/// periodic and chaotic attractors apart; values where the walker fell are marked along the
/// bottom.
pub fn orbit_diagram(scene: &Scene, r: &sim::report::OrbitDiagramReport, coordinate: &str) -> Plot {
    let mut periodic = Vec::new();
    let mut chaotic = Vec::new();
    let mut fell_at = Vec::new();
    for p in &r.points {
        let ys = p.samples.get(coordinate).map_or(&[][..], Vec::as_slice);
        match p.attractor {
            "periodic" => periodic.extend(ys.iter().map(|&y| (p.value, y))),
            "chaotic" => chaotic.extend(ys.iter().map(|&y| (p.value, y))),
            _ => fell_at.push(p.value),
        }
    }
    let bottom = periodic
        .iter()
        .chain(&chaotic)
        .map(|p| p.1)
        .fold(f64::INFINITY, f64::min);
    let bottom = if bottom.is_finite() { bottom } else { 0.0 };
    let series = vec![
        Series {
            label: "periodic".into(),
            points: periodic,
            style: Style::markers(Marker::Dot),
            color: PALETTE[0],
        },
        Series {
            label: "chaotic".into(),
            points: chaotic,
            style: Style::markers(Marker::Dot),
            color: PALETTE[1],
        },
        Series {
            label: "fell (no attractor)".into(),
            points: fell_at.into_iter().map(|x| (x, bottom)).collect(),
            style: Style::markers(Marker::Dot),
            color: "#555555",
        },
    ];
    let param = parameter_label(scene, &r.param);
    Plot {
        title: format!("{}: orbit diagram", walker_name(scene)),
        caption: Some("chaotic: no period up to the bound".into()),
        x_label: param,
        y_label: state_label(coordinate, "at heel strike"),
        series,
        ..Plot::default()
    }
}

/// An axis label for a stride-map entry or convention output `name` (`theta` → "θ at heel
/// strike (rad)", `swing_hip_dot` → "swing hip rate at heel strike (rad/s)").
pub fn state_label(name: &str, when: &str) -> String {
    match name.strip_suffix("_dot") {
        Some(c) => format!("{} rate {when} (rad/s)", coordinate_label(c)),
        None => format!("{} {when} (rad)", coordinate_label(name)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    #[test]
    fn dense_samples_follow_the_motion_between_steps() {
        // q = sin(t), q̇ = cos(t), sampled every 0.2 s: the dense points are on the curve.
        let s = |t: f64| Sample {
            t_s: t,
            q: DVector::from_vec(vec![t.sin()]),
            qd: DVector::from_vec(vec![t.cos()]),
        };
        let coarse: Vec<Sample> = (0..6).map(|k| s(0.2 * k as f64)).collect();
        let fine = dense(&coarse, 100.0);
        assert!(fine.len() >= 100, "{}", fine.len());
        for w in fine.windows(2) {
            assert!(w[1].t_s > w[0].t_s);
        }
        for p in &fine {
            assert!(
                (p.q[0] - p.t_s.sin()).abs() < 2e-5,
                "{} at {}",
                p.q[0],
                p.t_s
            );
        }
        // The recorded samples are all kept.
        for c in &coarse {
            assert!(fine.iter().any(|f| f.t_s == c.t_s && f.q == c.q));
        }
        // An impact at t = 1 (the rate jumps to 0, as at a knee lock): the recording holds
        // only the state after it; with the state before it put back, the interval ending at
        // the impact follows the motion, not a hook towards the new rate.
        let mut recorded: Vec<Sample> = (0..5).map(|k| s(0.2 * k as f64)).collect();
        let mut after = s(1.0);
        after.qd[0] = 0.0;
        recorded.push(after.clone());
        recorded.push(Sample {
            t_s: 1.2,
            q: after.q.clone(),
            qd: after.qd.clone(),
        });
        let events = [(s(1.0), after)];
        let fixed = with_pre_impact_states(&recorded, &events);
        assert_eq!(fixed.len(), recorded.len() + 1);
        let d = dense(&fixed, 100.0);
        assert_eq!(d.iter().filter(|p| p.t_s == 1.0).count(), 2);
        for p in d.iter().filter(|p| p.t_s > 0.8 && p.t_s < 1.0) {
            assert!(
                (p.q[0] - p.t_s.sin()).abs() < 2e-5,
                "{} at {}",
                p.q[0],
                p.t_s
            );
        }
        // Without it the last interval bends away from the motion.
        let hooked = dense(&recorded, 100.0);
        assert!(hooked
            .iter()
            .filter(|p| p.t_s > 0.8 && p.t_s < 1.0)
            .any(|p| (p.q[0] - p.t_s.sin()).abs() > 1e-3));
    }

    #[test]
    fn coincident_eigenvalues_are_one_marker_with_a_count() {
        let c = clusters(&[
            (0.0, 0.0),
            (1e-9, 0.0),
            (0.5, 0.5),
            (0.0, -1e-12),
            (0.5, -0.5),
        ]);
        assert_eq!(c.len(), 3);
        assert_eq!(c[0], ((0.0, 0.0), 3));
    }

    #[test]
    fn eigenvalues_crowding_the_origin_are_named_in_the_caption() {
        let mode = |re: f64, three_d: bool| sim::analysis::stability::EigenMode {
            eigenvalue: [re, 0.0],
            abs: re.abs(),
            dominant: Vec::new(),
            three_d,
        };
        let all = [mode(0.0, false), mode(-4e-8, false), mode(0.9, false)];
        assert_eq!(
            near_zero_caption(&all).as_deref(),
            Some("2 eigenvalues at 0")
        );
        let mixed = [
            mode(0.0, false),
            mode(-0.029, true),
            mode(0.038, true),
            mode(0.5, true),
        ];
        assert_eq!(
            near_zero_caption(&mixed).as_deref(),
            Some("3 eigenvalues near the origin: 1 at 0, −0.029 (3D), 0.038 (3D)")
        );
        assert_eq!(
            near_zero_caption(&[mode(0.0, false), mode(0.5, false)]),
            None
        );
    }

    fn walk(points: &[(f64, f64)], failure: Option<(usize, sim::stride::FailureKind)>) -> Walk {
        Walk {
            steps_completed: 3,
            steps: Vec::new(),
            failure: failure.map(|(step, kind)| sim::stride::walk::WalkFailure {
                kind,
                step,
                t_walk_s: 1.0,
                detail: String::new(),
            }),
            path: points
                .iter()
                .map(|&(x, z)| sim::stride::walk::PathSample {
                    step: 0,
                    t_walk_s: 0.0,
                    q: DVector::zeros(1),
                    qd: DVector::zeros(1),
                    hip_floor_m: nalgebra::Vector3::new(x, 0.0, z),
                    floor: sim::stride::walk::FloorFrame::default(),
                })
                .collect(),
            path_cut_t_walk_s: None,
        }
    }

    #[test]
    fn a_floor_path_is_true_to_scale_or_says_how_much_it_is_magnified() {
        let scene = Scene::load("wisse3d").expect("shipped scene");
        let size = (860.0, 480.0);
        // 11 m forward, 0.27 m sideways: magnified by a round factor, stated twice.
        let flat = walk(&[(0.0, -0.1), (5.0, 0.0), (11.0, 0.17)], None);
        let p = floor_paths(&[(&scene, &flat)], size);
        let Aspect::Scaled { y_over_x } = p.aspect else {
            panic!("a scaled aspect")
        };
        assert_eq!(y_over_x, 10.0);
        assert!(
            p.y_label.contains("×10") && p.caption.as_deref().is_some_and(|c| c.contains("×10"))
        );
        let l = p.layout(size.0, size.1);
        let ppu_x = l.area.w / (l.x_range.1 - l.x_range.0);
        let ppu_y = l.area.h / (l.y_range.1 - l.y_range.0);
        assert!((ppu_y / ppu_x - 10.0).abs() < 1e-9);
        // A path as wide as it is long: true to scale, no magnification mentioned.
        let square = walk(
            &[(0.0, 0.0), (1.0, 1.0)],
            Some((4, sim::stride::FailureKind::FellForward)),
        );
        let p = floor_paths(&[(&scene, &square)], size);
        assert_eq!(p.aspect, Aspect::EQUAL);
        assert!(p.caption.is_none() && !p.y_label.contains('×'));
        // The fall is told in words, its step counted from 1.
        assert_eq!(
            p.series[0].label,
            "3D walker with pelvic compensator (falls in step 5: fell forward)"
        );
    }

    #[test]
    fn state_labels_are_words_with_units() {
        assert_eq!(
            state_label("theta", "at heel strike"),
            "θ at heel strike (rad)"
        );
        assert_eq!(
            state_label("swing_hip_dot", "at heel strike"),
            "swing hip rate at heel strike (rad/s)"
        );
    }
}
