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
use serde::Deserialize;
use std::collections::BTreeSet;
use toml::{Table, Value};

/// A scene file's `[variant]` table. Unknown keys are rejected (a typo such as `wled` would
/// otherwise leave the base walker unchanged).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VariantDef {
    /// The built-in scene this one derives from.
    pub base: String,
    /// Links whose joints become welds (their coordinates disappear).
    #[serde(default)]
    pub weld: Vec<String>,
    /// Links removed, with everything hanging from them.
    #[serde(default)]
    pub remove: Vec<String>,
}

impl VariantDef {
    /// The `[variant]` table of a scene file's table, if it has one.
    ///
    /// # Errors
    /// [`SceneError::Invalid`] for a `[variant]` that is not a table of the fields above.
    pub fn of(table: &Table) -> Result<Option<Self>, SceneError> {
        let Some(v) = table.get("variant") else {
            return Ok(None);
        };
        v.clone()
            .try_into()
            .map(Some)
            .map_err(|e: toml::de::Error| invalid(format!("[variant]: {}", e.message())))
    }
}

fn invalid(msg: String) -> SceneError {
    SceneError::Invalid(msg)
}

/// Resolves a variant table against its base table (already resolved).
pub fn apply(base: Table, variant: Table) -> Result<Table, SceneError> {
    let mut out = base;
    let spec = VariantDef::of(&variant)?
        .ok_or_else(|| invalid("variant: missing [variant] table".into()))?;
    let (weld, remove) = (spec.weld, spec.remove);
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
    // Shapes (drawing only) on removed links go with them.
    if let Some(shapes) = out.get_mut("shape").and_then(Value::as_array_mut) {
        shapes.retain(|s| !gone.contains(s.get("link").and_then(Value::as_str).unwrap_or("")));
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
