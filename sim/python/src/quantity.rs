//! The `quantity=` and `sigma_m=` of a study (`stability_map`, `sweep`): a number of each
//! gait to measure beside it (`walker stability-map --quantity`, `walker sweep --quantity`),
//! checked as the command checks it, with the keywords' spelling in the messages.

use crate::errors;
use pyo3::prelude::*;
use sim::analysis::quantity::{Quantity, QuantityOptions};

/// The quantity named `quantity` (if any) with its options, `sigma_m` the rough floor of
/// `mfpt`. Raises `walker.InputError`: an unknown name, `mfpt` without a finite `sigma_m`
/// ≥ 0, `sigma_m` without `mfpt`.
pub fn choose(
    py: Python<'_>,
    quantity: Option<&str>,
    sigma_m: Option<f64>,
) -> PyResult<(Option<Quantity>, QuantityOptions)> {
    let options = QuantityOptions {
        sigma_m,
        ..QuantityOptions::default()
    };
    let quantity = match quantity {
        Some(name) => {
            let q = Quantity::parse(name).ok_or_else(|| {
                errors::input_error(
                    py,
                    &format!("quantity `{name}`: expected one of {}", Quantity::names()),
                )
            })?;
            if q == Quantity::Mfpt && sigma_m.is_none() {
                return Err(errors::input_error(
                    py,
                    "quantity mfpt needs the rough floor's standard deviation: give sigma_m",
                ));
            }
            if let Some(bad) = sigma_m.filter(|s| !(s.is_finite() && *s >= 0.0)) {
                return Err(errors::input_error(
                    py,
                    &format!("sigma_m {bad}: a standard deviation must be a finite number ≥ 0"),
                ));
            }
            q.check(&options)
                .map_err(|e| errors::input_error(py, &format!("quantity {q}: {e}")))?;
            Some(q)
        }
        None => None,
    };
    if sigma_m.is_some() && quantity != Some(Quantity::Mfpt) {
        return Err(errors::input_error(
            py,
            "sigma_m is the rough floor of quantity=\"mfpt\": give quantity=\"mfpt\" too",
        ));
    }
    Ok((quantity, options))
}

/// Checks `quantity=` and `sigma_m=` as `stability_map` does, before anything is computed (a
/// study on a cluster checks them before it contacts the cluster or writes its file). Raises
/// `walker.InputError` as `stability_map` would.
#[pyfunction]
#[pyo3(signature = (quantity = None, sigma_m = None))]
pub fn check_quantity(
    py: Python<'_>,
    quantity: Option<String>,
    sigma_m: Option<f64>,
) -> PyResult<()> {
    choose(py, quantity.as_deref(), sigma_m).map(|_| ())
}
