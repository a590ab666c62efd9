//! The stability map: the largest |eigenvalue| of the stride Jacobian of the long-period
//! gait over a grid of two parameters — a designer's first picture of a walker.
//!
//! Each row (one value of the y parameter) is filled by natural-parameter continuation along x
//! ([`crate::analysis::continuation::along`]): a cell starts Newton from the secant predictor of the
//! row's last two gaits (the last one alone after the first), and accepts the result unless
//! the corrector moved it by more than [`HomotopySettings::max_correction`] or its step period
//! differs from the last gait's by more than [`HomotopySettings::max_period_change`] (a jump
//! to another branch). The first cell of a row, a cell after one without a gait, and a cell
//! whose continuation failed or jumped are **seeded** by [`crate::analysis::homotopy::long_period_gait`]
//! (Newton from the scene's guess and the defaults' gait followed to the cell), so a row
//! re-enters the long-period branch where it reappears. A cell has no gait when both fail.
//!
//! Rows are independent and run in parallel (rayon); the results do not depend on the
//! number of threads. Budget per cell: one continuation search of at most
//! [`HomotopySettings::max_corrector_iterations`] Newton iterations, and when seeded two
//! searches with the caller's Newton budget and at most [`HomotopySettings::max_solves`]
//! corrector searches along the path from the defaults.

use crate::analysis::continuation::along;
use crate::analysis::homotopy::{HomotopySettings, SetupFor};
use crate::analysis::limit_cycle::{Gait, NewtonError, NewtonSettings};
use crate::scene::{Scene, SceneError};
use nalgebra::DVector;
use rayon::prelude::*;

/// One axis of the grid: a parameter and its values.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    /// Parameter name (or alias).
    pub name: String,
    /// Its values, in order.
    pub values: Vec<f64>,
}

/// The gait at one cell.
#[derive(Clone, Debug, PartialEq)]
pub struct MapCell {
    /// Largest eigenvalue modulus.
    pub max_abs_eigenvalue: f64,
    /// All eigenvalues strictly inside the unit circle.
    pub stable: bool,
    /// Step period \[s\].
    pub step_period_s: f64,
    /// The fixed point (stride-map vector).
    pub fixed_point: DVector<f64>,
    /// Found by seeding rather than by continuation along the row.
    pub seeded: bool,
}

/// The map: one row per y value, one cell per x value; `Err` where no gait was found.
#[derive(Clone, Debug)]
pub struct StabilityMap {
    /// `rows[j][i]`: the cell at `x.values[i]`, `y.values[j]`.
    pub rows: Vec<Vec<Result<MapCell, NewtonError>>>,
}

impl MapCell {
    fn of(g: &Gait, seeded: bool) -> Self {
        Self {
            max_abs_eigenvalue: g.max_abs_eigenvalue(),
            stable: g.stable(),
            step_period_s: g.stride.duration_s,
            fixed_point: g.fixed_point.clone(),
            seeded,
        }
    }
}

/// The stability map of `scene` over `x` × `y` (see the [module docs](self)); `progress` is
/// called once per cell done.
///
/// # Errors
/// An unknown parameter, a value out of its range, a scene that cannot be built.
pub fn stability_map(
    scene: &Scene,
    setup_for: &SetupFor<'_>,
    x: &Axis,
    y: &Axis,
    newton: &NewtonSettings,
    homotopy: &HomotopySettings,
    progress: &(dyn Fn() + Sync),
) -> Result<StabilityMap, SceneError> {
    let mut check = scene.clone();
    for (axis, v) in x
        .values
        .iter()
        .map(|v| (x, v))
        .chain(y.values.iter().map(|v| (y, v)))
    {
        check.set(&axis.name, *v)?;
    }
    let rows: Vec<Result<Vec<Result<MapCell, NewtonError>>, SceneError>> = y
        .values
        .par_iter()
        .map(|&yv| {
            let mut at = scene.clone();
            at.set(&y.name, yv)?;
            let cells = along(
                &at, &x.name, &x.values, setup_for, newton, homotopy, progress,
            )?;
            Ok(cells
                .into_iter()
                .map(|c| c.map(|(g, seeded)| MapCell::of(&g, seeded)))
                .collect())
        })
        .collect();
    Ok(StabilityMap {
        rows: rows.into_iter().collect::<Result<_, _>>()?,
    })
}
