//! The start state of `walker walk`: another scene's gait, a start-state file, perturbations.

use crate::input_error::InputError;
use crate::options::Common;
use anyhow::Result;
use nalgebra::DVector;
use serde_json::Value;
use sim::scene::Scene;
use sim::walker::Walker;

/// The gait of scene `other` (with this scene's shared parameter values), mapped onto this
/// walker's stride-map entries by name. `None` (after a message) if it has no gait.
pub fn from_other_scene(
    other: &str,
    scene: &Scene,
    walker: &Walker,
    common: &Common,
) -> Result<Option<DVector<f64>>> {
    let mut other_scene = Scene::load(other)?;
    for (k, val) in &scene.values {
        if other_scene.file.parameters.contains_key(k) {
            other_scene.set(k, *val)?;
        }
    }
    let oset = other_scene.setup()?;
    let ow = &oset.walker;
    let og = match oset.find_gait(&common.newton()) {
        Ok(g) => g,
        Err(e) => {
            eprintln!("error: scene `{other}` has no gait to start from: {e}");
            return Ok(None);
        }
    };
    let names = walker.map_names();
    let onames = ow.map_names();
    let mut v = DVector::zeros(names.len());
    for (i, n) in names.iter().enumerate() {
        if let Some(j) = onames.iter().position(|m| m == n) {
            v[i] = og.fixed_point[j];
        }
    }
    Ok(Some(v))
}

/// The entries a start-state file sets, as (stride-map index, value); every problem with the
/// file is bad input naming it.
pub fn read_start_state(
    path: &std::path::Path,
    names: &[String],
) -> Result<Vec<(usize, f64)>, InputError> {
    let bad = |why: String| InputError::Other(format!("--start-state `{}`: {why}", path.display()));
    let text = std::fs::read_to_string(path).map_err(|e| bad(e.to_string()))?;
    let doc: Value = serde_json::from_str(&text).map_err(|e| bad(format!("not JSON: {e}")))?;
    // A `walker gait --json` output also lists its scene's conventional outputs (e.g.
    // Goswami's angles) in `fixed_point`: there, only the stride-map entries are read.
    let (obj, from_gait) = match doc.get("fixed_point") {
        Some(f) => (f, true),
        None => (&doc, false),
    };
    let obj = obj
        .as_object()
        .ok_or_else(|| bad("expected an object of entry names to numbers".into()))?;
    let mut out = Vec::with_capacity(obj.len());
    for (k, x) in obj {
        let Some(i) = names.iter().position(|n| n == k) else {
            if from_gait {
                continue;
            }
            return Err(bad(format!(
                "unknown entry `{k}` (known: {})",
                names.join(", ")
            )));
        };
        let x = x
            .as_f64()
            .filter(|x| x.is_finite())
            .ok_or_else(|| bad(format!("`{k}` = {x} is not a finite number")))?;
        out.push((i, x));
    }
    if out.is_empty() {
        return Err(bad("names no entry".into()));
    }
    Ok(out)
}

/// A `--perturb coord=delta` option as (stride-map index, delta).
pub fn parse_perturbation(p: &str, names: &[String]) -> Result<(usize, f64), InputError> {
    let (k, d) = p
        .split_once('=')
        .ok_or_else(|| InputError::Other(format!("--perturb `{p}`: expected coord=delta")))?;
    let i = names.iter().position(|n| n == k.trim()).ok_or_else(|| {
        InputError::Other(format!(
            "--perturb: unknown coordinate `{}` (known: {})",
            k.trim(),
            names.join(", ")
        ))
    })?;
    let d: f64 = d
        .trim()
        .parse()
        .ok()
        .filter(|x: &f64| x.is_finite())
        .ok_or_else(|| {
            InputError::Other(format!(
                "--perturb `{p}`: `{}` is not a finite number",
                d.trim()
            ))
        })?;
    Ok((i, d))
}
