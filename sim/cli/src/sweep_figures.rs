//! The figures of `walker sweep --plot`: the continuation's bifurcation diagram (a state at
//! heel strike against the parameter) and the largest multiplier's modulus against the
//! parameter. Each branch is drawn in arclength order through its grid points and its
//! bifurcations, solid where the gait is stable and dashed where it is not; folds, period
//! doublings, Neimark–Sacker points and branch points are marked and named in the legend.

use crate::axis::Scale;
use crate::figures::state_label;
use crate::labels::{parameter_label, walker_name};
use crate::plot::{Marker, Plot, Series, Style, PALETTE};
use nalgebra::{Complex, DVector};
use sim::analysis::continuation::{BifurcationKind, Branch, BranchPoint, Continuation};
use sim::engine::hermite::{self, Knot};
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
    // Curves: per period, stable (solid) and unstable (dashed), in both figures.
    let mut curves = Curves::default();
    let mut periods: Vec<usize> = Vec::new();
    for b in &c.branches {
        let color = match periods.iter().position(|p| *p == b.period_strides) {
            Some(k) => PALETTE[k % PALETTE.len()],
            None => {
                periods.push(b.period_strides);
                PALETTE[(periods.len() - 1) % PALETTE.len()]
            }
        };
        let nodes = branch_nodes(c, b);
        let label = |stable: bool| {
            let period = if b.period_strides == 1 {
                "period-1 gait".to_string()
            } else {
                format!("period-{} gait", b.period_strides)
            };
            format!("{period}, {}", if stable { "stable" } else { "unstable" })
        };
        for stable in [true, false] {
            let (pts, lam) = stability_polylines(&nodes, b.period_strides, index, stable);
            if lam.iter().all(|p| p.0.is_nan()) {
                continue;
            }
            curves.add(label(stable), color, stable, pts, lam);
        }
    }
    let Curves { state, modulus } = add_markers(curves, c, index);
    figures(scene, c, coordinate, state, modulus)
}

/// The curves of both figures: the state at heel strike and max |λ|, series for series.
#[derive(Default)]
struct Curves {
    state: Vec<Series>,
    modulus: Vec<Series>,
}

impl Curves {
    /// Adds a branch's polylines of one stability to the series of its label and colour (a
    /// new series if there is none yet), broken from what is there by NaN.
    fn add(
        &mut self,
        label: String,
        color: &'static str,
        stable: bool,
        by_phase: Vec<Vec<(f64, f64)>>,
        lam: Vec<(f64, f64)>,
    ) {
        let existing = self
            .state
            .iter()
            .position(|s| s.label == label && s.color == color);
        let style = if stable { Style::LINE } else { Style::DASHED };
        let mut pts: Vec<(f64, f64)> = Vec::new();
        for ph in by_phase {
            pts.extend(ph);
            pts.push((f64::NAN, f64::NAN));
        }
        match existing {
            Some(k) => {
                self.state[k].points.push((f64::NAN, f64::NAN));
                self.state[k].points.extend(pts);
                self.modulus[k].points.push((f64::NAN, f64::NAN));
                self.modulus[k].points.extend(lam);
            }
            None => {
                self.state.push(Series {
                    label: label.clone(),
                    points: pts,
                    style,
                    color,
                });
                self.modulus.push(Series {
                    label,
                    points: lam,
                    style,
                    color,
                });
            }
        }
    }
}

/// A branch's points in arclength order: where it was born (a branch switched onto at a
/// bifurcation starts at its parent's point), then its grid points with its bifurcations
/// among them ([`slots`]).
fn branch_nodes<'a>(c: &'a Continuation, b: &'a Branch) -> Vec<Node<'a>> {
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
    nodes
}

/// The segments of one stability of a branch (its `nodes`, of period `period_strides`) as
/// polylines broken by NaN: stride-map entry `index` against the parameter, one per phase of
/// the orbit, and max |λ| against the parameter.
#[allow(clippy::type_complexity)]
fn stability_polylines(
    nodes: &[Node],
    period_strides: usize,
    index: usize,
    stable: bool,
) -> (Vec<Vec<(f64, f64)>>, Vec<(f64, f64)>) {
    let mut by_phase: Vec<Vec<(f64, f64)>> = vec![Vec::new(); period_strides.max(1)];
    let mut lam: Vec<(f64, f64)> = Vec::new();
    let mut open = false;
    // The largest |λ| along the arclength, for drawing between the points of a
    // period-1 branch: monotone cubic slopes (it has no tangent of its own).
    let lam_nodes: Vec<f64> = nodes.iter().map(|n| n.point.max_abs_multiplier()).collect();
    let arc: Vec<f64> = nodes
        .windows(2)
        .map(|w| (w[1].point.x() - w[0].point.x()).norm())
        .collect();
    let lam_slopes = monotone_slopes(&arc, &lam_nodes);
    for (i, w) in nodes.windows(2).enumerate() {
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
                // A period-1 branch between its points: the cubic through both with
                // the continuation's tangents (its orbit has one state, the tangent's).
                if period_strides == 1 {
                    pts.extend(between(w[0].point, w[1].point, index));
                }
                pts.push((w[1].value, y(&w[1])));
            }
            if !open {
                lam.push((w[0].value, lam_nodes[i]));
            }
            if period_strides == 1 {
                let ps = between(w[0].point, w[1].point, index);
                let a = Knot {
                    value: lam_nodes[i],
                    rate: lam_slopes[i],
                };
                let z = Knot {
                    value: lam_nodes[i + 1],
                    rate: lam_slopes[i + 1],
                };
                lam.extend(ps.iter().enumerate().map(|(k, (p, _))| {
                    let u = (k + 1) as f64 / (HERMITE_POINTS + 1) as f64;
                    (*p, hermite::scalar(a, z, arc[i], u).0)
                }));
            }
            lam.push((w[1].value, lam_nodes[i + 1]));
            open = true;
        } else if open {
            for pts in by_phase.iter_mut() {
                pts.push((f64::NAN, f64::NAN));
            }
            lam.push((f64::NAN, f64::NAN));
            open = false;
        }
    }
    (by_phase, lam)
}

/// The curves with a marker series per bifurcation kind found: at each state of its orbit
/// in the diagram, at its crossing multiplier's modulus in the stability figure.
fn add_markers(mut curves: Curves, c: &Continuation, index: usize) -> Curves {
    for kind in [
        BifurcationKind::Fold,
        BifurcationKind::PeriodDoubling,
        BifurcationKind::NeimarkSacker,
        BifurcationKind::BranchPoint,
    ] {
        let found: Vec<&sim::analysis::continuation::Bifurcation> = c
            .branches
            .iter()
            .flat_map(|b| &b.bifurcations)
            .filter(|x| x.kind == kind)
            .collect();
        if found.is_empty() {
            continue;
        }
        let (marker, color, label) = mark(kind);
        curves.state.push(Series {
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
        curves.modulus.push(Series {
            label: label.into(),
            points: found
                .iter()
                .map(|x| (x.value, crossing_modulus(kind, &x.multipliers)))
                .collect(),
            style: Style::markers(marker),
            color,
        });
    }
    curves
}

/// The two figures around the series: the stability boundary under the curves across the
/// values the branches reach, a log axis when max |λ| spans more than a decade, titles,
/// captions and axis labels.
fn figures(
    scene: &Scene,
    c: &Continuation,
    coordinate: &str,
    state: Vec<Series>,
    mut modulus: Vec<Series>,
) -> [Plot; 2] {
    let param = parameter_label(scene, &c.family.param);
    let name = walker_name(scene);
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
                "continuation: every state of a period-k gait; period-1 branches as cubics \
                 along the tangents"
                    .into(),
            ),
            x_label: param.clone(),
            y_label: state_label(coordinate, "at heel strike"),
            series: state,
            ..Plot::default()
        },
        Plot {
            title: format!("{name}: stability against the {}", param_words(&param)),
            caption: Some(
                "bifurcations at their crossing multiplier's modulus (≈ 1); \
                 monotone cubics between computed points"
                    .into(),
            ),
            x_label: param,
            y_label: "largest |λ| of the stride map".into(),
            y_scale,
            series: modulus,
            ..Plot::default()
        },
    ]
}

/// Points drawn between two successive points of a period-1 branch, besides them.
const HERMITE_POINTS: usize = 12;

/// The branch between points `a` and `b` (in arclength order) as the cubic Hermite curve in
/// the arclength through both, with the continuation's unit tangents `(dv/ds, dp/ds)` as
/// rates, the arclength between them taken as their distance: [`HERMITE_POINTS`] points
/// (parameter, stride-map entry `index`) strictly between them. None when the two coincide or
/// a tangent is missing. A tangent pointing against the chord is turned round (a located
/// bifurcation's may be oriented either way).
pub fn between(a: &BranchPoint, b: &BranchPoint, index: usize) -> Vec<(f64, f64)> {
    hermite_between((&a.x(), &a.tangent), (&b.x(), &b.tangent), index)
}

/// [`between`] on points `x = (v, p)` (the parameter last) with their tangents.
fn hermite_between(
    (xa, ta): (&DVector<f64>, &DVector<f64>),
    (xb, tb): (&DVector<f64>, &DVector<f64>),
    index: usize,
) -> Vec<(f64, f64)> {
    let n = xa.len();
    if xb.len() != n || ta.len() != n || tb.len() != n || index + 1 >= n {
        return Vec::new();
    }
    let chord = xb - xa;
    let h = chord.norm();
    if h <= 0.0 || !h.is_finite() {
        return Vec::new();
    }
    let along = |t: &DVector<f64>| if t.dot(&chord) < 0.0 { -t } else { t.clone() };
    let (ta, tb) = (along(ta), along(tb));
    let knot = |x: &DVector<f64>, t: &DVector<f64>, i: usize| Knot {
        value: x[i],
        rate: t[i],
    };
    let p = n - 1;
    (1..=HERMITE_POINTS)
        .map(|k| {
            let u = k as f64 / (HERMITE_POINTS + 1) as f64;
            let (pv, ..) = hermite::scalar(knot(xa, &ta, p), knot(xb, &tb, p), h, u);
            let (yv, ..) = hermite::scalar(knot(xa, &ta, index), knot(xb, &tb, index), h, u);
            (pv, yv)
        })
        .collect()
}

/// Slopes at the knots of values `y` spaced `h` apart (`h[i]` between knots `i` and `i + 1`)
/// that keep the cubic Hermite curve through them monotone between knots (Fritsch–Carlson:
/// zero at a local extremum, the weighted harmonic mean of the neighbouring secants
/// elsewhere, the one secant at the ends). A zero spacing gives a zero slope.
pub fn monotone_slopes(h: &[f64], y: &[f64]) -> Vec<f64> {
    let n = y.len();
    if n < 2 || h.len() + 1 != n {
        return vec![0.0; n];
    }
    let secant: Vec<f64> = (0..n - 1)
        .map(|i| {
            if h[i] > 0.0 {
                (y[i + 1] - y[i]) / h[i]
            } else {
                0.0
            }
        })
        .collect();
    (0..n)
        .map(|i| {
            if i == 0 {
                secant[0]
            } else if i == n - 1 {
                secant[n - 2]
            } else {
                let (d0, d1) = (secant[i - 1], secant[i]);
                if d0 * d1 <= 0.0 {
                    0.0
                } else {
                    let (w0, w1) = (2.0 * h[i] + h[i - 1], h[i] + 2.0 * h[i - 1]);
                    (w0 + w1) / (w0 / d0 + w1 / d1)
                }
            }
        })
        .collect()
}

/// The modulus of the multiplier that crosses the unit circle at a bifurcation of `kind`: the
/// one closest to +1 (fold, branch point), to −1 (period doubling), or the complex one
/// closest to the circle (Neimark–Sacker); the largest modulus if there is none such.
pub fn crossing_modulus(kind: BifurcationKind, multipliers: &[Complex<f64>]) -> f64 {
    let target = |z: &Complex<f64>| match kind {
        BifurcationKind::Fold | BifurcationKind::BranchPoint => (z - 1.0).norm(),
        BifurcationKind::PeriodDoubling => (z + 1.0).norm(),
        BifurcationKind::NeimarkSacker if z.im.abs() > 1e-9 => (z.norm() - 1.0).abs(),
        BifurcationKind::NeimarkSacker => f64::INFINITY,
    };
    multipliers
        .iter()
        .filter(|z| target(z).is_finite())
        .min_by(|a, b| target(a).total_cmp(&target(b)))
        .map_or_else(
            || multipliers.iter().map(|z| z.norm()).fold(0.0, f64::max),
            |z| z.norm(),
        )
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

    #[test]
    fn a_branch_is_drawn_through_its_tangents() {
        // A branch on the unit circle (state, parameter) = (sin s, cos s), points 0.6 rad
        // apart: the cubic stays on the circle (to 1e-3), the chord does not (4.5e-2).
        let at = |s: f64| DVector::from_vec(vec![s.sin(), s.cos()]);
        let tangent = |s: f64| DVector::from_vec(vec![s.cos(), -s.sin()]);
        let (a, b) = (0.2, 0.8);
        // The second tangent given the wrong way round: turned along the chord.
        let pts = hermite_between((&at(a), &tangent(a)), (&at(b), &-tangent(b)), 0);
        assert_eq!(pts.len(), HERMITE_POINTS);
        for (p, y) in &pts {
            assert!(
                (p.hypot(*y) - 1.0).abs() < 1e-3,
                "({p}, {y}) off the circle"
            );
        }
        let mid = (at(a) + at(b)) / 2.0;
        assert!(1.0 - mid.norm() > 4e-2);
        // Coincident points: nothing between them.
        assert!(hermite_between((&at(a), &tangent(a)), (&at(a), &tangent(a)), 0).is_empty());
    }

    #[test]
    fn monotone_slopes_keep_the_curve_between_its_knots() {
        // A rise, a peak, a fall: zero slope at the peak, the secant at the ends.
        let h = [1.0, 1.0, 2.0];
        let y = [0.0, 1.0, 2.0, 1.0];
        let d = monotone_slopes(&h, &y);
        assert_eq!(d[0], 1.0);
        assert_eq!(d[2], 0.0);
        assert_eq!(d[3], -0.5);
        assert!(d[1] > 0.0 && d[1] <= 1.0 + 1e-12);
        for i in 0..3 {
            let (a, b) = (
                Knot {
                    value: y[i],
                    rate: d[i],
                },
                Knot {
                    value: y[i + 1],
                    rate: d[i + 1],
                },
            );
            for k in 1..10 {
                let v = hermite::scalar(a, b, h[i], f64::from(k) / 10.0).0;
                assert!(v >= y[i].min(y[i + 1]) - 1e-12 && v <= y[i].max(y[i + 1]) + 1e-12);
            }
        }
    }

    #[test]
    fn a_bifurcation_is_marked_at_its_crossing_multiplier() {
        let z = |re: f64, im: f64| Complex::new(re, im);
        let m = [z(1.257, 0.0), z(0.6, 0.8), z(0.6, -0.8), z(-0.3, 0.0)];
        let ns = crossing_modulus(BifurcationKind::NeimarkSacker, &m);
        assert!((ns - 1.0).abs() < 1e-12, "{ns}");
        let m = [z(1.12, 0.0), z(0.999, 0.0), z(-0.4, 0.0)];
        assert_eq!(crossing_modulus(BifurcationKind::Fold, &m), 0.999);
        let m = [z(1.3, 0.0), z(-1.001, 0.0)];
        assert_eq!(crossing_modulus(BifurcationKind::PeriodDoubling, &m), 1.001);
        // No complex pair: the largest.
        assert_eq!(crossing_modulus(BifurcationKind::NeimarkSacker, &m), 1.3);
    }
}
