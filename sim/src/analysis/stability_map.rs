//! The stability map: the largest |eigenvalue| of the stride Jacobian of the scene's gait over
//! a grid of two parameters — a designer's first picture of a walker.
//!
//! Every cell's gait is the one `walker gait` reports at the cell's values: the scene's
//! nominal gait ([`crate::analysis::homotopy::nominal_gait`], the one rule every command and
//! study shares — Newton from the scene's guess at the cell and the defaults' gait followed to
//! the cell, the longer-period of the two), with where it came from ([`GaitSource`]). A cell
//! never reports another gait than `walker gait` would at the same values: it does not follow
//! its neighbours along a row (which can land on another branch past a fold; a study that
//! follows a branch on purpose is `walker sweep`). A cell has no gait when both searches fail.
//!
//! Cells are independent and run in parallel (rayon); the results do not depend on the number
//! of threads. Budget per cell: that of [`crate::analysis::homotopy::nominal_gait`] — two
//! searches with the caller's Newton budget and at most [`HomotopySettings::max_solves`]
//! corrector searches along the path from the defaults, whose gait is found once for the map
//! ([`GaitRule`]).

use crate::analysis::homotopy::{GaitRule, GaitSource, HomotopySettings, SetupFor};
use crate::analysis::limit_cycle::{Gait, NewtonError, NewtonSettings};
use crate::analysis::quantity::{Quantity, QuantityError, QuantityOptions};
use crate::scene::{Scene, SceneError};
use nalgebra::DVector;
use rayon::prelude::*;

/// Most cells a caller should ask of one map (`N × M`; `walker stability-map` and
/// `walker.stability_map` in Python refuse more): each is a gait search.
pub const MAX_MAP_CELLS: usize = 40_000;

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
    /// Where the gait came from (as `walker gait`'s `gait_source`).
    pub source: GaitSource,
    /// The map's other quantity of this gait ([`stability_map_of`]), or why it could not be
    /// had; `None` without one.
    pub quantity: Option<Result<f64, QuantityError>>,
}

/// The map: one row per y value, one cell per x value; `Err` where no gait was found.
#[derive(Clone, Debug)]
pub struct StabilityMap {
    /// `rows[j][i]`: the cell at `x.values[i]`, `y.values[j]`.
    pub rows: Vec<Vec<Result<MapCell, NewtonError>>>,
}

impl MapCell {
    fn of(g: &Gait, source: GaitSource) -> Self {
        Self {
            max_abs_eigenvalue: g.max_abs_eigenvalue(),
            stable: g.stable(),
            step_period_s: g.stride.duration_s,
            fixed_point: g.fixed_point.clone(),
            source,
            quantity: None,
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
    stability_map_of(scene, setup_for, x, y, newton, homotopy, None, progress)
}

/// [`stability_map`] with `quantity` of each cell's gait too (a robustness measure,
/// [`MapCell::quantity`]), computed with the cell's own stride settings.
///
/// # Errors
/// As [`stability_map`].
#[allow(clippy::too_many_arguments)]
pub fn stability_map_of(
    scene: &Scene,
    setup_for: &SetupFor<'_>,
    x: &Axis,
    y: &Axis,
    newton: &NewtonSettings,
    homotopy: &HomotopySettings,
    quantity: Option<(Quantity, &QuantityOptions)>,
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
    let rule = GaitRule::new(setup_for, newton, homotopy);
    let nx = x.values.len();
    let cells: Vec<Result<Result<MapCell, NewtonError>, SceneError>> = (0..nx * y.values.len())
        .into_par_iter()
        .map(|k| {
            let mut at = scene.clone();
            at.set(&x.name, x.values[k % nx])?;
            at.set(&y.name, y.values[k / nx])?;
            let mut cell = rule
                .gait(&at)?
                .map(|(g, source)| (MapCell::of(&g, source), g));
            if let (Some((q, options)), Ok((c, g))) = (quantity, &mut cell) {
                let setup = setup_for(&at)?;
                c.quantity = Some(q.evaluate(&setup, g, options));
            }
            let cell = cell.map(|(c, _)| c);
            progress();
            Ok(cell)
        })
        .collect();
    let cells = cells.into_iter().collect::<Result<Vec<_>, _>>()?;
    let mut rows: Vec<Vec<Result<MapCell, NewtonError>>> = Vec::with_capacity(y.values.len());
    let mut cells = cells.into_iter();
    for _ in &y.values {
        rows.push(cells.by_ref().take(nx).collect());
    }
    Ok(StabilityMap { rows })
}
