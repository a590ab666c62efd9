//! Scene variants: a scene file may derive from another by welding joints (fixing freedoms)
//! and removing bodies, so that e.g. the 2D and uncompensated walkers are the 3D walker's file
//! with freedoms taken away, not copies of it.
//!
//! ```toml
//! [variant]
//! base = "wisse3d"
//! weld = ["stance_foot_yaw"]       # these joints become welds (their coordinates disappear)
//! remove = ["pelvis_pitch"]         # these links and everything hanging from them go
//! [scene]                           # replaces the base's header
//! ...
//! ```
//! Other top-level tables of the variant replace the base's (`[guess]`, `[integrator]`, ...),
//! except `[parameters]`, which is merged entry by entry.

use super::SceneError;
use std::collections::BTreeSet;
use toml::{Table, Value};

fn invalid(msg: String) -> SceneError {
    SceneError::Invalid(msg)
}

/// Resolves a variant table against its base table (already resolved).
pub fn apply(base: Table, variant: Table) -> Result<Table, SceneError> {
    let mut out = base;
    let spec = variant
        .get("variant")
        .and_then(Value::as_table)
        .cloned()
        .ok_or_else(|| invalid("variant: missing [variant] table".into()))?;
    let names = |key: &str| -> Result<Vec<String>, SceneError> {
        match spec.get(key) {
            None => Ok(Vec::new()),
            Some(Value::Array(a)) => a
                .iter()
                .map(|v| {
                    v.as_str()
                        .map(String::from)
                        .ok_or_else(|| invalid(format!("variant.{key}: expected strings")))
                })
                .collect(),
            Some(_) => Err(invalid(format!(
                "variant.{key}: expected an array of link names"
            ))),
        }
    };
    let weld = names("weld")?;
    let remove = names("remove")?;
    for (k, v) in variant {
        match k.as_str() {
            "variant" => {}
            "parameters" => {
                let merged = out
                    .entry("parameters")
                    .or_insert_with(|| Value::Table(Table::new()));
                if let (Some(m), Value::Table(add)) = (merged.as_table_mut(), v) {
                    for (pk, pv) in add {
                        m.insert(pk, pv);
                    }
                }
            }
            _ => {
                out.insert(k, v);
            }
        }
    }
    let links = out
        .get_mut("link")
        .and_then(Value::as_array_mut)
        .ok_or_else(|| invalid("base has no links".into()))?;
    let link_name = |l: &Value| {
        l.get("name")
            .and_then(Value::as_str)
            .unwrap_or("")
            .to_string()
    };
    let known: BTreeSet<String> = links.iter().map(link_name).collect();
    for n in weld.iter().chain(remove.iter()) {
        if !known.contains(n) {
            return Err(invalid(format!("variant: unknown link `{n}`")));
        }
    }
    // Removing a link removes its descendants (links are parents-first).
    let mut gone: BTreeSet<String> = remove.iter().cloned().collect();
    for l in links.iter() {
        let parent = l.get("parent").and_then(Value::as_str).unwrap_or("");
        if gone.contains(parent) {
            gone.insert(link_name(l));
        }
    }
    links.retain(|l| !gone.contains(&link_name(l)));
    for l in links.iter_mut() {
        if weld.contains(&link_name(l)) {
            if let Some(t) = l.as_table_mut() {
                t.insert("joint".into(), Value::String("weld".into()));
                for k in ["axis", "stiffness", "rest", "damping"] {
                    t.remove(k);
                }
            }
        }
    }
    // Coordinates that no longer exist, and points on removed links.
    let dead_coords: BTreeSet<String> = gone.iter().chain(weld.iter()).cloned().collect();
    let mut dead_points = BTreeSet::new();
    if let Some(points) = out.get_mut("point").and_then(Value::as_array_mut) {
        points.retain(|p| {
            let on = p.get("link").and_then(Value::as_str).unwrap_or("");
            let keep = !gone.contains(on);
            if !keep {
                dead_points.insert(
                    p.get("name")
                        .and_then(Value::as_str)
                        .unwrap_or("")
                        .to_string(),
                );
            }
            keep
        });
    }
    let keep_str =
        |v: &Value, dead: &BTreeSet<String>| v.as_str().is_none_or(|s| !dead.contains(s));
    if let Some(r) = out.get_mut("relabel").and_then(Value::as_table_mut) {
        for (key, dead) in [("pairs", &gone), ("point_pairs", &dead_points)] {
            if let Some(a) = r.get_mut(key).and_then(Value::as_array_mut) {
                a.retain(|pair| {
                    pair.as_array()
                        .is_none_or(|p| p.iter().all(|x| keep_str(x, dead)))
                });
            }
        }
        if let Some(a) = r.get_mut("cyclic").and_then(Value::as_array_mut) {
            a.retain(|x| keep_str(x, &dead_coords));
        }
    }
    if let Some(a) = out
        .get_mut("three_d_freedoms")
        .and_then(Value::as_array_mut)
    {
        a.retain(|x| keep_str(x, &dead_coords));
    }
    if let Some(g) = out.get_mut("guess").and_then(Value::as_table_mut) {
        for key in ["q", "qd"] {
            if let Some(t) = g.get_mut(key).and_then(Value::as_table_mut) {
                t.retain(|k, _| !dead_coords.contains(k));
            }
        }
    }
    if let Some(knees) = out.get_mut("knee").and_then(Value::as_array_mut) {
        knees.retain(|k| {
            k.get("coordinate")
                .is_none_or(|x| keep_str(x, &dead_coords))
        });
    }
    Ok(out)
}
