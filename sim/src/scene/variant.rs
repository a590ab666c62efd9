//! Scene variants: a scene file may derive from another by welding joints (fixing freedoms),
//! removing bodies, changing parameter defaults and adding springs or dampers to joints, so
//! that e.g. the 2D and uncompensated walkers are the 3D walker's file with freedoms taken
//! away, not copies of it.
//!
//! ```toml
//! [variant]
//! base = "wisse3d"
//! weld = ["stance_foot_yaw"]       # these joints become welds (their coordinates disappear)
//! remove = ["pelvis_pitch"]         # these links and everything hanging from them go
//! [variant.defaults]                # parameter defaults (unit, doc and range kept)
//! ankle_engage_rad = -0.06
//! [variant.joint.swing_knee]        # a spring and/or damper on a joint (the keys of [[link]])
//! damping = 0.05
//! [scene]                           # replaces the base's header
//! ...
//! ```
//! Other top-level tables of the variant replace the base's (`[guess]`, `[integrator]`, ...),
//! except `[parameters]`, which is merged entry by entry. docs/scenes.md is the reference.

use super::error::SceneError;
pub use super::error::VariantError;
use super::file::Num;
use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use toml::{Table, Value};

/// A scene file's `[variant]` table. Unknown keys are rejected (a typo such as `wled` would
/// otherwise leave the base walker unchanged).
#[derive(Clone, Debug, Deserialize, PartialEq)]
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
    /// New defaults of parameters (of the base or of this file's `[parameters]`), by name or
    /// alias; each keeps its unit, doc and range.
    #[serde(default)]
    pub defaults: BTreeMap<String, f64>,
    /// Springs and dampers put on joints, by link name: the keys given replace the link's.
    #[serde(default)]
    pub joint: BTreeMap<String, JointForceDef>,
}

/// A spring and damper on a joint (`[variant.joint.<link>]`): the same keys as a link's.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct JointForceDef {
    /// Joint spring stiffness \[N·m/rad\] (N/m on a prismatic joint).
    #[serde(default)]
    pub stiffness: Option<Num>,
    /// Joint spring rest position \[rad\] (m on a prismatic joint).
    #[serde(default)]
    pub rest: Option<Num>,
    /// Joint damping \[N·m·s/rad\] (N·s/m on a prismatic joint).
    #[serde(default)]
    pub damping: Option<Num>,
}

impl JointForceDef {
    /// The keys given, as TOML values for the link's table.
    fn entries(&self) -> impl Iterator<Item = (&'static str, Value)> + '_ {
        [
            ("stiffness", &self.stiffness),
            ("rest", &self.rest),
            ("damping", &self.damping),
        ]
        .into_iter()
        .filter_map(|(key, n)| {
            n.as_ref().map(|n| {
                let value = match n {
                    Num::Value(v) => Value::Float(*v),
                    Num::Expr(e) => Value::String(e.clone()),
                };
                (key, value)
            })
        })
    }
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

/// Resolves a variant table against its base table (already resolved), the base named
/// `base_name` in errors.
pub fn apply(base_name: &str, base: Table, variant: Table) -> Result<Table, SceneError> {
    let mut out = base;
    let spec = VariantDef::of(&variant)?.ok_or(VariantError::Missing)?;
    let (weld, remove) = (&spec.weld, &spec.remove);
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
    set_defaults(base_name, &mut out, &spec.defaults)?;
    let links = out
        .get_mut("link")
        .and_then(Value::as_array_mut)
        .ok_or(VariantError::NoLinks)?;
    let link_name = |l: &Value| {
        l.get("name")
            .and_then(Value::as_str)
            .unwrap_or("")
            .to_string()
    };
    let known: BTreeSet<String> = links.iter().map(link_name).collect();
    for n in weld.iter().chain(remove.iter()) {
        if !known.contains(n) {
            return Err(VariantError::UnknownLink { link: n.clone() }.into());
        }
    }
    // Removing a link removes its descendants (links are parents-first).
    let mut gone: BTreeSet<String> = remove.iter().cloned().collect();
    let available = known.iter().cloned().collect::<Vec<_>>().join(", ");
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
    for (name, force) in &spec.joint {
        let error = |why| VariantError::NoJoint {
            base: base_name.to_string(),
            link: name.clone(),
            why,
        };
        if !known.contains(name) {
            return Err(VariantError::UnknownJoint {
                base: base_name.to_string(),
                link: name.clone(),
                available: available.clone(),
            }
            .into());
        }
        let link = links
            .iter_mut()
            .find(|l| link_name(l) == *name)
            .and_then(Value::as_table_mut)
            .ok_or_else(|| error("removed by this variant"))?;
        if link.get("joint").and_then(Value::as_str) == Some("weld") {
            return Err(error("a weld").into());
        }
        for (key, value) in force.entries() {
            link.insert(key.into(), value);
        }
    }
    // Coordinates that no longer exist, and points on removed links.
    let dead_coords: BTreeSet<String> = gone.iter().chain(weld).cloned().collect();
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

/// Sets the defaults of `[variant.defaults]` in the merged `[parameters]` of `out`: each name
/// (or alias) must be a parameter there.
fn set_defaults(
    base_name: &str,
    out: &mut Table,
    defaults: &BTreeMap<String, f64>,
) -> Result<(), SceneError> {
    if defaults.is_empty() {
        return Ok(());
    }
    let mut empty = Table::new();
    let parameters = out
        .get_mut("parameters")
        .and_then(Value::as_table_mut)
        .unwrap_or(&mut empty);
    let available = parameters.keys().cloned().collect::<Vec<_>>().join(", ");
    for (name, value) in defaults {
        let has_alias = |p: &Value| {
            p.get("aliases")
                .and_then(Value::as_array)
                .is_some_and(|a| a.iter().any(|x| x.as_str() == Some(name)))
        };
        let parameter = parameters
            .iter_mut()
            .find(|(k, p)| *k == name || has_alias(p))
            .and_then(|(_, p)| p.as_table_mut())
            .ok_or_else(|| VariantError::UnknownParameter {
                base: base_name.to_string(),
                name: name.clone(),
                available: available.clone(),
            })?;
        parameter.insert("default".into(), Value::Float(*value));
    }
    Ok(())
}
