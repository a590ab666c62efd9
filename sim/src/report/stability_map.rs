//! The `walker stability-map` report: the largest |eigenvalue| of the long-period gait over
//! a grid of two parameters, `null` where there is no gait.

use crate::analysis::homotopy::GaitSource;
use crate::analysis::quantity::{Quantity, QuantityError, QuantityOptions};
use crate::analysis::stability_map::{Axis, StabilityMap};
use serde::Serialize;

/// The `walker stability-map --json` object. Every grid has one row per y value and one entry
/// per x value.
#[derive(Clone, Debug, Serialize)]
pub struct StabilityMapReport {
    /// Scene name.
    pub scene: String,
    /// The x parameter and its values.
    pub x: AxisRecord,
    /// The y parameter and its values.
    pub y: AxisRecord,
    /// Largest eigenvalue modulus (`null`: no gait).
    pub max_abs_eigenvalue: Vec<Vec<Option<f64>>>,
    /// All eigenvalues inside the unit circle (`null`: no gait).
    pub stable: Vec<Vec<Option<bool>>>,
    /// Step period \[s\] (`null`: no gait).
    pub step_period_s: Vec<Vec<Option<f64>>>,
    /// Why there is no gait (`null` where there is one).
    pub no_gait_reason: Vec<Vec<Option<String>>>,
    /// Where each cell's gait came from, as `walker gait`'s `gait_source` at the cell's values
    /// (`null`: no gait).
    pub gait_source: Vec<Vec<Option<GaitSource>>>,
    /// The map's other quantity (`--quantity`), absent without one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub quantity: Option<QuantityGrid>,
}

/// A robustness measure over the grid.
#[derive(Clone, Debug, Serialize)]
pub struct QuantityGrid {
    /// The quantity (`gsn`, `step_down`, `mfpt`, ...).
    pub name: Quantity,
    /// Its unit.
    pub unit: &'static str,
    /// The rough floor of `mfpt` \[m\] (`null` for the others).
    pub sigma_m: Option<f64>,
    /// Its value (`null`: no gait, or it could not be had).
    pub values: Vec<Vec<Option<f64>>>,
    /// Why it could not be had at a cell with a gait (`null` elsewhere).
    pub errors: Vec<Vec<Option<String>>>,
}

/// An axis of the grid.
#[derive(Clone, Debug, Serialize)]
pub struct AxisRecord {
    /// Parameter name.
    pub name: String,
    /// Its values.
    pub values: Vec<f64>,
}

impl From<&Axis> for AxisRecord {
    fn from(a: &Axis) -> Self {
        Self {
            name: a.name.clone(),
            values: a.values.clone(),
        }
    }
}

impl StabilityMapReport {
    /// The report of `map` over `x` × `y` of scene `scene`, with `quantity` when the map has
    /// one ([`crate::analysis::stability_map::stability_map_of`]).
    pub fn with_quantity(
        scene: &str,
        x: &Axis,
        y: &Axis,
        map: &StabilityMap,
        quantity: Quantity,
        options: &QuantityOptions,
    ) -> Self {
        fn cells<T>(
            map: &StabilityMap,
            f: impl Fn(&Result<f64, QuantityError>) -> Option<T>,
        ) -> Vec<Vec<Option<T>>> {
            map.rows
                .iter()
                .map(|r| {
                    r.iter()
                        .map(|c| {
                            c.as_ref()
                                .ok()
                                .and_then(|c| c.quantity.as_ref())
                                .and_then(&f)
                        })
                        .collect()
                })
                .collect()
        }
        Self {
            quantity: Some(QuantityGrid {
                name: quantity,
                unit: quantity.unit(),
                sigma_m: options.sigma_m.filter(|_| quantity == Quantity::Mfpt),
                values: cells(map, |q| q.as_ref().ok().copied()),
                errors: cells(map, |q| q.as_ref().err().map(ToString::to_string)),
            }),
            ..Self::new(scene, x, y, map)
        }
    }

    /// The report of `map` over `x` × `y` of scene `scene`.
    pub fn new(scene: &str, x: &Axis, y: &Axis, map: &StabilityMap) -> Self {
        let grid =
            |f: &dyn Fn(&crate::analysis::stability_map::MapCell) -> f64| -> Vec<Vec<Option<f64>>> {
                map.rows
                    .iter()
                    .map(|r| r.iter().map(|c| c.as_ref().ok().map(f)).collect())
                    .collect()
            };
        Self {
            scene: scene.to_string(),
            x: x.into(),
            y: y.into(),
            max_abs_eigenvalue: grid(&|c| c.max_abs_eigenvalue),
            stable: map
                .rows
                .iter()
                .map(|r| {
                    r.iter()
                        .map(|c| c.as_ref().ok().map(|c| c.stable))
                        .collect()
                })
                .collect(),
            step_period_s: grid(&|c| c.step_period_s),
            no_gait_reason: map
                .rows
                .iter()
                .map(|r| {
                    r.iter()
                        .map(|c| c.as_ref().err().map(ToString::to_string))
                        .collect()
                })
                .collect(),
            gait_source: map
                .rows
                .iter()
                .map(|r| {
                    r.iter()
                        .map(|c| c.as_ref().ok().map(|c| c.source))
                        .collect()
                })
                .collect(),
            quantity: None,
        }
    }
}
