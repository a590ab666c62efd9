//! The figures of `walker sweep --plot`: the continuation's bifurcation diagram (a state at
//! heel strike against the parameter) and the largest multiplier's modulus against the
//! parameter. Each branch is drawn in arclength order through its grid points and its
//! bifurcations, solid where the gait is stable and dashed where it is not; folds, period
//! doublings, Neimark–Sacker points and branch points are marked and named in the legend.

use crate::axis::Scale;
use crate::figures::state_label;
use crate::labels::{parameter_label, walker_name};
use crate::plot::{Marker, Plot, Series, Style, PALETTE};
use sim::continuation::{BifurcationKind, BranchPoint, Continuation};
use sim::scene::Scene;

/// A point of a branch in arclength order: a grid point, or a bifurcation (with the
/// stability on its two sides).
struct Node<'a> {
    value: f64,
    point: &'a BranchPoint,
    stable_from_previous: bool,
    stable_to_next: bool,
}

/// Where the bifurcations (their values, and whether each is a fold) go among the grid
/// values of a branch, both in arclength order: for each bifurcation, the index of the grid
/// point it follows (`grid.len()`: after the last, `0` also when before the first). A
/// bifurcation goes into the first segment, from the previous one's, whose values bracket it,
/// or, for a fold, where the branch turns back.
pub fn slots(grid: &[f64], bifurcations: &[(f64, bool)]) -> Vec<usize> {
    let mut out = Vec::with_capacity(bifurcations.len());
    let mut cursor = 0usize;
    for &(v, fold) in bifurcations {
        let mut found = None;
        for i in cursor..grid.len().saturating_sub(1) {
            let (a, b) = (grid[i], grid[i + 1]);
            let brackets = a.min(b) <= v && v <= a.max(b);
            // The branch turns back within this segment: it has no length in the parameter,
            // or the segments before and after it run in opposite directions.
            let turns_here = a == b
                || (i > 0 && i + 2 < grid.len() && (a - grid[i - 1]) * (grid[i + 2] - b) < 0.0);
            if brackets || (fold && turns_here) {
                found = Some(i + 1);
                break;
            }
        }
        let slot = match found {
            Some(s) => s,
            // Beyond the grid: before the first point or after the last.
            None if grid.len() >= 2 && (v - grid[0]).abs() < (v - grid[grid.len() - 1]).abs() => {
                if cursor == 0 {
                    0
                } else {
                    grid.len()
                }
            }
            None => grid.len(),
        };
        cursor = slot.saturating_sub(1).max(cursor);
        out.push(slot);
    }
    out
}

/// The marker, colour and legend name of a bifurcation kind.
fn mark(kind: BifurcationKind) -> (Marker, &'static str, &'static str) {
    match kind {
        BifurcationKind::Fold => (Marker::Triangle, "#000000", "fold"),
        BifurcationKind::PeriodDoubling => (Marker::Square, "#000000", "period doubling"),
        BifurcationKind::NeimarkSacker => (Marker::Diamond, "#000000", "Neimark–Sacker"),
        BifurcationKind::BranchPoint => (Marker::Star, "#000000", "branch point"),
    }
}

/// The two sweep figures from the continuation `c` of `scene`: the bifurcation diagram of
/// stride-map entry `coordinate` (index `index` in the map), and max |λ| against the parameter.
pub fn sweep_figures(scene: &Scene, c: &Continuation, coordinate: &str, index: usize) -> [Plot; 2] {
    let param = parameter_label(scene, &c.family.param);
    let name = walker_name(scene);
    // Curves: per period, stable (solid) and unstable (dashed), in both figures.
    let mut state: Vec<Series> = Vec::new();
    let mut modulus: Vec<Series> = Vec::new();
    let mut periods: Vec<usize> = Vec::new();
    for b in &c.branches {
        let color = match periods.iter().position(|p| *p == b.period_strides) {
            Some(k) => PALETTE[k % PALETTE.len()],
            None => {
                periods.push(b.period_strides);
                PALETTE[(periods.len() - 1) % PALETTE.len()]
            }
        };
        let grid: Vec<f64> = b.grid.iter().map(|g| g.value).collect();
        let bifs: Vec<(f64, bool)> = b
            .bifurcations
            .iter()
            .map(|x| (x.value, x.kind == BifurcationKind::Fold))
            .collect();
        let slot = slots(&grid, &bifs);
        let mut nodes: Vec<Node> = Vec::new();
        // A branch switched onto at a bifurcation starts there (its parent's point: a
        // period-2k orbit born from a period-k one repeats its states).
        let birth = b.parent.and_then(|(parent, value)| {
            c.branches.iter().find(|p| p.id == parent).and_then(|p| {
                p.bifurcations
                    .iter()
                    .min_by(|x, y| (x.value - value).abs().total_cmp(&(y.value - value).abs()))
            })
        });
        if let (Some(x), Some(first)) = (birth, b.grid.first()) {
            let s = first.point.stable();
            nodes.push(Node {
                value: x.value,
                point: &x.point,
                stable_from_previous: s,
                stable_to_next: s,
            });
        }
        let mut next_bif = 0;
        for i in 0..=b.grid.len() {
            while next_bif < slot.len() && slot[next_bif] == i {
                let x = &b.bifurcations[next_bif];
                nodes.push(Node {
                    value: x.value,
                    point: &x.point,
                    stable_from_previous: x.stable_before,
                    stable_to_next: x.stable_after,
                });
                next_bif += 1;
            }
            if let Some(g) = b.grid.get(i) {
                let s = g.point.stable();
                nodes.push(Node {
                    value: g.value,
                    point: &g.point,
                    stable_from_previous: s,
                    stable_to_next: s,
                });
            }
        }
        let label = |stable: bool| {
            let period = if b.period_strides == 1 {
                "period-1 gait".to_string()
            } else {
                format!("period-{} gait", b.period_strides)
            };
            format!("{period}, {}", if stable { "stable" } else { "unstable" })
        };
        for stable in [true, false] {
            // The segments of this stability, as polylines broken by NaN.
            let mut by_phase: Vec<Vec<(f64, f64)>> = vec![Vec::new(); b.period_strides.max(1)];
            let mut lam: Vec<(f64, f64)> = Vec::new();
            let mut open = false;
            for w in nodes.windows(2) {
                let seg_stable = w[0].stable_to_next && w[1].stable_from_previous;
                if seg_stable == stable {
                    for (k, pts) in by_phase.iter_mut().enumerate() {
                        let y = |n: &Node| {
                            let orbit = &n.point.orbit;
                            orbit
                                .get(k % orbit.len().max(1))
                                .and_then(|s| s.get(index))
                                .copied()
                                .unwrap_or(f64::NAN)
                        };
                        if !open {
                            pts.push((w[0].value, y(&w[0])));
                        }
                        pts.push((w[1].value, y(&w[1])));
                    }
                    if !open {
                        lam.push((w[0].value, w[0].point.max_abs_multiplier()));
                    }
                    lam.push((w[1].value, w[1].point.max_abs_multiplier()));
                    open = true;
                } else if open {
                    for pts in by_phase.iter_mut() {
                        pts.push((f64::NAN, f64::NAN));
                    }
                    lam.push((f64::NAN, f64::NAN));
                    open = false;
                }
            }
            if lam.iter().all(|p| p.0.is_nan()) {
                continue;
            }
            let existing = state
                .iter()
                .position(|s| s.label == label(stable) && s.color == color);
            let style = if stable { Style::LINE } else { Style::DASHED };
            let mut pts: Vec<(f64, f64)> = Vec::new();
            for ph in by_phase {
                pts.extend(ph);
                pts.push((f64::NAN, f64::NAN));
            }
            match existing {
                Some(k) => {
                    state[k].points.push((f64::NAN, f64::NAN));
                    state[k].points.extend(pts);
                    modulus[k].points.push((f64::NAN, f64::NAN));
                    modulus[k].points.extend(lam);
                }
                None => {
                    state.push(Series {
                        label: label(stable),
                        points: pts,
                        style,
                        color,
                    });
                    modulus.push(Series {
                        label: label(stable),
                        points: lam,
                        style,
                        color,
                    });
                }
            }
        }
    }
    // Markers: every located bifurcation, one series per kind.
    for kind in [
        BifurcationKind::Fold,
        BifurcationKind::PeriodDoubling,
        BifurcationKind::NeimarkSacker,
        BifurcationKind::BranchPoint,
    ] {
        let found: Vec<&sim::continuation::Bifurcation> = c
            .branches
            .iter()
            .flat_map(|b| &b.bifurcations)
            .filter(|x| x.kind == kind)
            .collect();
        if found.is_empty() {
            continue;
        }
        let (marker, color, label) = mark(kind);
        state.push(Series {
            label: label.into(),
            points: found
                .iter()
                .flat_map(|x| {
                    x.point
                        .orbit
                        .iter()
                        .filter_map(|s| s.get(index).map(|y| (x.value, *y)))
                })
                .collect(),
            style: Style::markers(marker),
            color,
        });
        modulus.push(Series {
            label: label.into(),
            points: found
                .iter()
                .map(|x| (x.value, x.point.max_abs_multiplier()))
                .collect(),
            style: Style::markers(marker),
            color,
        });
    }
    // The boundary across the values the branches reach; a log axis when max |λ| spans more
    // than a decade.
    let finite = |f: fn(&(f64, f64)) -> f64| {
        modulus
            .iter()
            .flat_map(|s| s.points.iter().map(f))
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            })
    };
    let (lo, hi) = finite(|p| p.0);
    let (lam_lo, lam_hi) = finite(|p| p.1);
    let y_scale = if lam_lo > 0.0 && lam_hi > 10.0 * lam_lo {
        Scale::Log10
    } else {
        Scale::Linear
    };
    // Drawn first, under the curves.
    modulus.insert(
        0,
        Series {
            label: "|λ| = 1: stability boundary".into(),
            points: vec![(lo, 1.0), (hi, 1.0)],
            style: Style {
                line: crate::plot::Line::Solid,
                marker: Marker::None,
            },
            color: "#999999",
        },
    );
    [
        Plot {
            title: format!("{name}: gaits against the {}", param_words(&param)),
            caption: Some(
                "pseudo-arclength continuation; every state of a period-k gait is drawn".into(),
            ),
            x_label: param.clone(),
            y_label: state_label(coordinate, "at heel strike"),
            series: state,
            ..Plot::default()
        },
        Plot {
            title: format!("{name}: stability against the {}", param_words(&param)),
            x_label: param,
            y_label: "largest |λ| of the stride map".into(),
            y_scale,
            series: modulus,
            ..Plot::default()
        },
    ]
}

/// The parameter's words without the unit ("floor slope (rad)" → "floor slope").
fn param_words(label: &str) -> &str {
    label.split(" (").next().unwrap_or(label)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bifurcations_go_between_the_grid_points_that_bracket_them() {
        // A branch through 0.1 … 0.4 and back (a fold near 0.43), with a period doubling at
        // 0.25 on the way out and a Neimark–Sacker point at 0.15 on the way back.
        let grid = [0.1, 0.2, 0.3, 0.4, 0.4, 0.3, 0.2, 0.1];
        let bifs = [(0.25, false), (0.43, true), (0.15, false)];
        assert_eq!(slots(&grid, &bifs), vec![2, 4, 7]);
        // None: everything after the last point, or before the first.
        assert_eq!(slots(&[0.1, 0.2], &[(0.05, false)]), vec![0]);
        assert_eq!(slots(&[0.1, 0.2], &[(0.3, false)]), vec![2]);
    }
}
