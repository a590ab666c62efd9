//! The figures of the paper, from our results: eigenvalues in the complex plane (Figs. 11,
//! 13), the floor path of the hip-axle centre (Fig. 12), and joint angles over a stride.

use crate::plot::{Plot, Series, Style, PALETTE};
use sim::integrators::Sample;
use sim::limit_cycle::Gait;
use sim::stability::modes;
use sim::walk::Walk;
use sim::walker::Walker;

/// Eigenvalues of the stride Jacobian with the unit circle; those whose eigenvector is
/// dominated by a freedom only the 3D model has are drawn as stars.
pub fn eigenvalues(walker: &Walker, gait: &Gait, title: &str) -> Plot {
    let m = modes(
        &gait.jacobian,
        &gait.eigenvalues,
        &walker.map_names(),
        &walker.three_d_freedoms,
    );
    let (three_d, plain): (Vec<_>, Vec<_>) = m.iter().partition(|e| e.three_d);
    let mut series = vec![Series {
        label: "eigenvalue".into(),
        points: plain
            .iter()
            .map(|e| (e.eigenvalue[0], e.eigenvalue[1]))
            .collect(),
        style: Style::Circle,
        color: PALETTE[0],
    }];
    if !three_d.is_empty() {
        series.push(Series {
            label: "* 3D mode (yaw, roll)".into(),
            points: three_d
                .iter()
                .map(|e| (e.eigenvalue[0], e.eigenvalue[1]))
                .collect(),
            style: Style::Star,
            color: PALETTE[1],
        });
    }
    Plot {
        title: title.into(),
        x_label: "Re λ [-]".into(),
        y_label: "Im λ [-]".into(),
        series,
        equal_aspect: true,
        unit_circle: true,
    }
}

/// The path of the hip-axle centre on the floor for one or more walks.
pub fn floor_paths(walks: &[(&str, &Walk)], title: &str) -> Plot {
    let series = walks
        .iter()
        .enumerate()
        .map(|(i, (label, w))| Series {
            label: match &w.failure {
                // Steps counted from 0, as `walker walk` prints them ("in step 1" is the second).
                Some(f) => format!("{label} (fails in step {}: {:?})", f.step, f.kind),
                None => format!("{label} ({} steps)", w.steps_completed),
            },
            points: w
                .path
                .iter()
                .map(|s| (s.hip_floor_m.x, s.hip_floor_m.z))
                .collect(),
            style: if i == 0 { Style::Line } else { Style::Dashed },
            color: PALETTE[i % PALETTE.len()],
        })
        .collect();
    Plot {
        title: title.into(),
        x_label: "forward x [m]".into(),
        y_label: "lateral z [m] (to the right)".into(),
        series,
        equal_aspect: false,
        unit_circle: false,
    }
}

/// Every joint coordinate over one stride, from that stride's recorded `samples` (those that
/// stay at zero are left out).
pub fn joint_angles(walker: &Walker, samples: &[Sample], title: &str) -> Plot {
    let series = walker
        .model
        .coordinates
        .iter()
        .enumerate()
        .filter(|(i, _)| samples.iter().any(|s| s.q[*i].abs() > 1e-12))
        .enumerate()
        .map(|(k, (i, c))| Series {
            label: c.name.clone(),
            points: samples.iter().map(|s| (s.t_s, s.q[i])).collect(),
            style: Style::Line,
            color: PALETTE[k % PALETTE.len()],
        })
        .collect();
    Plot {
        title: title.into(),
        x_label: "time from heel strike [s]".into(),
        y_label: "joint angle [rad]".into(),
        series,
        equal_aspect: false,
        unit_circle: false,
    }
}

/// One log-log panel of a speed-against-error study: an error measure against CPU time per
/// stride, one line per integrator.
pub fn accuracy(
    study: &sim::accuracy::AccuracyStudy,
    error: fn(&sim::accuracy::AccuracyPoint) -> Option<f64>,
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
            label: f.clone(),
            points: study
                .points
                .iter()
                .filter(|p| &p.integrator == f)
                .filter_map(|p| {
                    error(p)
                        .filter(|e| *e > 0.0)
                        .map(|e| (p.cpu_us_per_stride.log10(), e.log10()))
                })
                .collect(),
            style: Style::Line,
            color: PALETTE[i % PALETTE.len()],
        })
        .collect();
    Plot {
        title: format!("{}: {what} against CPU time", study.scene),
        x_label: "log10 CPU time per stride [µs]".into(),
        y_label: format!("log10 {what}"),
        series,
        equal_aspect: false,
        unit_circle: false,
    }
}

/// The orbit diagram: `coordinate` at heel strike on the attractor against the parameter,
/// periodic and chaotic attractors apart; values where the walker fell are marked along the
/// bottom.
pub fn orbit_diagram(r: &sim::report::OrbitDiagramReport, coordinate: &str) -> Plot {
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
            style: Style::Dot,
            color: PALETTE[0],
        },
        Series {
            label: "chaotic (no period up to the bound)".into(),
            points: chaotic,
            style: Style::Dot,
            color: PALETTE[1],
        },
        Series {
            label: "fell".into(),
            points: fell_at.into_iter().map(|x| (x, bottom)).collect(),
            style: Style::Star,
            color: "#555555",
        },
    ];
    Plot {
        title: format!("{}: orbit diagram over {}", r.scene, r.param),
        x_label: r.param.clone(),
        y_label: format!("{coordinate} at heel strike"),
        series,
        equal_aspect: false,
        unit_circle: false,
    }
}
