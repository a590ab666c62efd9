//! `walker scenes [NAME]`: the scenes, one line each; or one scene's parameters in full.

use super::print_json;
use crate::output;
use anyhow::Result;
use sim::report::{SceneCatalogue, SceneEntry};
use sim::scene::Scene;
use std::io::Write;
use std::process::ExitCode;

/// Runs `walker scenes`: without `name` the built-in scenes, one line each (with `as_json`,
/// the whole catalogue); with `name` (a built-in scene or a scene file) its parameter table.
/// An unknown name is bad input naming the scenes there are.
pub fn run(name: Option<&str>, as_json: bool) -> Result<ExitCode> {
    match name {
        None => {
            let catalogue = SceneCatalogue::builtin()?;
            if as_json {
                print_json(&catalogue)?;
            } else {
                output::text(|out| print_list(out, &catalogue))?;
            }
        }
        Some(name) => {
            let entry = SceneEntry::of(&Scene::load(name)?)?;
            if as_json {
                print_json(&entry)?;
            } else {
                output::text(|out| print_scene(out, &entry))?;
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// One line per scene: name, degrees of freedom, description.
fn print_list(out: &mut dyn Write, catalogue: &SceneCatalogue) -> std::io::Result<()> {
    let width = column_width("scene", catalogue.scenes.iter().map(|s| s.name.as_str()));
    writeln!(out, "{:<width$}  {:>3}  description", "scene", "dof")?;
    for s in &catalogue.scenes {
        writeln!(
            out,
            "{:<width$}  {:>3}  {}",
            s.name, s.degrees_of_freedom, s.summary
        )?;
    }
    writeln!(
        out,
        "dof: degrees of freedom in single support. `walker scenes NAME` lists a scene's \
         parameters (units, defaults, ranges); `--scene` also takes a scene file's path."
    )
}

/// The full description of one scene: summary, reference, freedoms and the parameter table.
fn print_scene(out: &mut dyn Write, s: &SceneEntry) -> std::io::Result<()> {
    writeln!(out, "{} — {}", s.name, s.summary)?;
    if !s.reference.is_empty() {
        writeln!(out, "reference: {}", s.reference)?;
    }
    writeln!(
        out,
        "degrees of freedom: {} ({})",
        s.degrees_of_freedom,
        s.coordinates.join(", ")
    )?;
    // Each column as wide as its longest entry.
    let rows: Vec<[String; 5]> = s
        .parameters
        .iter()
        .map(|p| {
            let range = match (p.min, p.max) {
                (None, None) => "-".to_owned(),
                (min, max) => format!(
                    "{} to {}",
                    min.map_or_else(|| "-∞".to_owned(), number),
                    max.map_or_else(|| "∞".to_owned(), number)
                ),
            };
            let doc = if p.aliases.is_empty() {
                p.doc.clone()
            } else {
                format!("{} (also: {})", p.doc, p.aliases.join(", "))
            };
            [
                p.name.clone(),
                number(p.default),
                p.unit.clone(),
                range,
                doc,
            ]
        })
        .collect();
    let header = ["parameter", "default", "unit", "range", "description"];
    let width = |i: usize| column_width(header[i], rows.iter().map(|r| r[i].as_str()));
    let (w0, w1, w2, w3) = (width(0), width(1), width(2), width(3));
    writeln!(
        out,
        "{:<w0$}  {:>w1$}  {:<w2$}  {:<w3$}  {}",
        header[0], header[1], header[2], header[3], header[4]
    )?;
    for [name, default, unit, range, doc] in &rows {
        writeln!(
            out,
            "{name:<w0$}  {default:>w1$}  {unit:<w2$}  {range:<w3$}  {doc}"
        )?;
    }
    writeln!(
        out,
        "set a parameter with `--set NAME=VALUE` (walker gait, walk, sil, sweep, ...)"
    )
}

/// The width of a column: its longest entry or its header, in characters.
fn column_width<'a>(header: &str, entries: impl Iterator<Item = &'a str>) -> usize {
    entries
        .map(|e| e.chars().count())
        .chain(std::iter::once(header.chars().count()))
        .max()
        .unwrap_or(0)
}

/// A number as JSON writes it (`1.0`, `0.009`; `null` if not finite).
fn number(x: f64) -> String {
    serde_json::Value::from(x).to_string()
}
