//! A slice of the basin of attraction of a gait (Schwab & Wisse 2001): on a grid of two
//! stride-map coordinates just after heel strike, which states return to the gait.
//!
//! A cell's state is the gait's fixed point with the two coordinates set to the cell's values,
//! then put back on the section: the swing foot on the floor, by solving one more position
//! coordinate (the one the swing foot's height depends on most at the fixed point, unless it
//! is itself an axis) so that the swing foot's height above the stance contact equals the
//! fixed point's. A cell whose swing foot cannot be brought to the floor (or, when both
//! position coordinates are axes, is not on it within [`SECTION_TOLERANCE`]) is `off_section`.
//! The other coordinates stay at the gait's values (rates included: a walker whose impact
//! ties rates together, as the simplest walker's massless swing foot does, is sliced with the
//! gait's swing rate, not the impact's).
//!
//! From there the strides of [`super::Recovery::follow`] (level floor) give the cell's
//! outcome: `gait` (back within the tolerance), `periodic` (another periodic motion, with its
//! period), the failure (`fell_forward`, `fell_backward`, ...) or `not_settled`, and the
//! strides it took.

use super::recovery::{Outcome, Recovery, Until};
use crate::engine::kinematics::Kinematics;
use crate::engine::model::PointIndex;
use crate::engine::walker::Walker;
use crate::stride::StrideWorkspace;
use nalgebra::DVector;
use rayon::prelude::*;
use serde::Serialize;

/// How far (in leg lengths) the swing foot's height may be from the fixed point's for a cell
/// to be on the section.
pub const SECTION_TOLERANCE: f64 = 1e-9;

/// One axis of a slice: a stride-map coordinate and its values.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BasinAxis {
    /// The stride-map name (`stance_leg`, `stance_leg_dot`, ...).
    pub name: String,
    /// Its values, in order.
    pub values: Vec<f64>,
}

/// How a cell ended.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum BasinCell {
    /// The strides from the cell's state.
    Strides(Outcome),
    /// The swing foot could not be brought to the floor at these values.
    OffSection,
}

impl BasinCell {
    /// The outcome's name (`gait`, `periodic`, `fell_forward`, ..., `not_settled`,
    /// `off_section`).
    pub fn name(&self) -> String {
        match self {
            BasinCell::Strides(o) => o.name(),
            BasinCell::OffSection => "off_section".into(),
        }
    }

    /// Strides taken (0 off the section).
    pub fn strides(&self) -> usize {
        match self {
            BasinCell::Strides(o) => o.strides(),
            BasinCell::OffSection => 0,
        }
    }
}

/// A basin slice.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BasinSlice {
    /// The first axis (columns).
    pub x: BasinAxis,
    /// The second axis (rows).
    pub y: BasinAxis,
    /// The position coordinate solved to keep the swing foot on the floor (`None` when both
    /// position coordinates are axes or the walker has no other).
    pub solved_coordinate: Option<String>,
    /// One row per `y` value, one cell per `x` value.
    pub cells: Vec<Vec<BasinCell>>,
    /// Cells back on the gait over all cells.
    pub fraction_returning: f64,
}

/// Most strides a cell may take to return to the gait.
pub const MAX_BASIN_CELL_STRIDES: usize = 10_000;

/// Why a slice was refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BasinError {
    /// An axis names no stride-map coordinate.
    #[error("`{name}` is not a stride-map coordinate of this walker (it has: {known})")]
    UnknownCoordinate {
        /// The name given.
        name: String,
        /// The names it has.
        known: String,
    },
    /// Both axes name the same coordinate.
    #[error("the two axes are the same coordinate `{0}`")]
    SameAxis(String),
    /// An axis without values.
    #[error("axis `{0}` has no values")]
    Empty(String),
}

/// The swing foot's height above the stance contact (stance frame's normal) at `q`.
struct FootHeight<'a> {
    model: &'a crate::engine::model::Model,
    kin: Kinematics,
    foot: PointIndex,
    stance: PointIndex,
}

impl FootHeight<'_> {
    fn at(&mut self, q: &DVector<f64>) -> f64 {
        let qd = DVector::zeros(q.len());
        self.kin.update(self.model, q, &qd);
        let y = |kin: &Kinematics, i: PointIndex| {
            let p = &self.model.points[i.0];
            kin.position_of(p.link, &p.p_link_m).y
        };
        y(&self.kin, self.foot) - y(&self.kin, self.stance)
    }
}

/// The stride-map indices of the axes `x` and `y` of a slice of `walker`'s basin, checked before
/// anything is computed.
///
/// # Errors
/// An axis that is not a stride-map coordinate, both axes the same, an empty axis.
pub fn basin_axes(
    walker: &Walker,
    x: &BasinAxis,
    y: &BasinAxis,
) -> Result<(usize, usize), BasinError> {
    let names = walker.map_names();
    let index = |a: &BasinAxis| {
        if a.values.is_empty() {
            return Err(BasinError::Empty(a.name.clone()));
        }
        names
            .iter()
            .position(|n| *n == a.name)
            .ok_or_else(|| BasinError::UnknownCoordinate {
                name: a.name.clone(),
                known: names.join(", "),
            })
    };
    let (ix, iy) = (index(x)?, index(y)?);
    if ix == iy {
        return Err(BasinError::SameAxis(x.name.clone()));
    }
    Ok((ix, iy))
}

/// The slice of `recovery`'s gait over the `x` and `y` axes (module documentation).
///
/// # Errors
/// An axis that is not a stride-map coordinate, both axes the same, an empty axis.
pub fn basin_slice(
    recovery: &Recovery<'_>,
    x: BasinAxis,
    y: BasinAxis,
    progress: &(dyn Fn() + Sync),
) -> Result<BasinSlice, BasinError> {
    let walker = recovery.walker;
    let names = walker.map_names();
    let (ix, iy) = basin_axes(walker, &x, &y)?;
    let n = names.len() / 2;
    let coords = walker.map_coordinates();
    let model = walker.model();
    let height = || FootHeight {
        model,
        kin: Kinematics::new(model),
        foot: walker.heel_strike().swing_foot,
        stance: walker.heel_strike().stance_contact,
    };
    let (q_star, _) = walker.unpack(recovery.fixed_point);
    let h_star = height().at(&q_star);
    // The position coordinate to solve: the one the foot's height depends on most
    let solved = {
        let mut h = height();
        (0..n)
            .filter(|&i| i != ix && i != iy)
            .map(|i| {
                let d = 1e-6;
                let (mut qp, mut qm) = (q_star.clone(), q_star.clone());
                qp[coords[i].0] += d;
                qm[coords[i].0] -= d;
                (i, ((h.at(&qp) - h.at(&qm)) / (2.0 * d)).abs())
            })
            .filter(|(_, s)| *s > 1e-9)
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    };
    let leg = recovery.leg_length_m();
    let cells_flat: Vec<BasinCell> = (0..y.values.len() * x.values.len())
        .into_par_iter()
        .map_init(
            || (StrideWorkspace::new(walker), height()),
            |(ws, h), cell| {
                let (row, col) = (cell / x.values.len(), cell % x.values.len());
                let mut v = recovery.fixed_point.clone();
                v[ix] = x.values[col];
                v[iy] = y.values[row];
                let on = match solved {
                    Some(i) => on_section(&mut v, i, coords[i].0, walker, h, h_star, leg),
                    // both position coordinates are axes: only the cells where the foot is on
                    // the floor are on the section
                    None => (h.at(&walker.unpack(&v).0) - h_star).abs() <= SECTION_TOLERANCE * leg,
                };
                let cell = if on {
                    BasinCell::Strides(recovery.follow(ws, &v, &mut |_| 0.0, Until::Settled))
                } else {
                    BasinCell::OffSection
                };
                progress();
                cell
            },
        )
        .collect();
    let returning = cells_flat
        .iter()
        .filter(|c| matches!(c, BasinCell::Strides(Outcome::Gait { .. })))
        .count();
    let fraction_returning = returning as f64 / cells_flat.len() as f64;
    let cells = cells_flat
        .chunks(x.values.len())
        .map(<[BasinCell]>::to_vec)
        .collect();
    Ok(BasinSlice {
        solved_coordinate: solved.map(|i| names[i].clone()),
        x,
        y,
        cells,
        fraction_returning,
    })
}

/// Newton on map entry `i` (model coordinate `c`) of `v` so the swing foot's height is
/// `h_star`, to 1e-13 leg lengths in at most 50 iterations; `false` when it does not get there.
fn on_section(
    v: &mut DVector<f64>,
    i: usize,
    c: usize,
    walker: &crate::engine::walker::Walker,
    h: &mut FootHeight<'_>,
    h_star: f64,
    leg: f64,
) -> bool {
    let (mut q, _) = walker.unpack(v);
    for _ in 0..50 {
        let r = h.at(&q) - h_star;
        if !r.is_finite() {
            return false;
        }
        if r.abs() <= 1e-4 * SECTION_TOLERANCE * leg {
            v[i] = q[c];
            return true;
        }
        let d = 1e-7;
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[c] += d;
        qm[c] -= d;
        let slope = (h.at(&qp) - h.at(&qm)) / (2.0 * d);
        if !(slope.is_finite() && slope.abs() > 1e-12) {
            return false;
        }
        // a step of at most 0.5 rad keeps Newton on the branch it started on
        q[c] -= (r / slope).clamp(-0.5, 0.5);
    }
    false
}
