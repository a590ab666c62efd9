//! docs/scenes.md, the scene format's reference, against what the loader accepts: every table
//! and key the loader accepts is documented there, and every table and key documented there is
//! accepted.
//!
//! The accepted keys are not listed by hand: they are read off the loader's own serde types
//! ([`SceneFile`] and, for `[variant]`, [`VariantDef`]), which all reject unknown keys
//! (`deny_unknown_fields`). A table holding only the planted key `__probe__` is refused with
//! the message "unknown field `__probe__`, expected one of `a`, `b`, …", which names every key
//! that table accepts; planting the probe one level deeper in each of those keys tells a
//! nested table (a struct, an array of tables, a map of tables by name, a table tagged by
//! `kind`) from a value. So a key added to any serde type of the loader appears here at once,
//! and the test fails until docs/scenes.md documents it (see
//! `a_key_the_reference_does_not_document_fails_the_check` for a planted one). A type that
//! stopped rejecting unknown keys fails the test too, since its keys could no longer be read.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use serde::de::DeserializeOwned;
use serde::Deserialize;
use sim::scene::file::SceneFile;
use sim::scene::variant::VariantDef;
use sim::scene::Scene;
use std::collections::{BTreeMap, BTreeSet};
use toml::{Table, Value};

/// The planted key.
const PROBE: &str = "__probe__";

/// One step from a table to a nested one.
#[derive(Clone, Debug)]
enum Step {
    /// The table under a key.
    Key(String),
    /// An element of an array of tables.
    Element,
    /// The table under any name in a map of tables (`[parameters.<name>]`).
    Entry,
    /// The table of an array element tagged `tag = variant`.
    Tagged(String, String),
}

/// A table's place, as written in docs/scenes.md's headings (see [`heading_path`]): `` for the
/// top level, `scene`, `link[]`, `parameters.*`, `shape[] kind=rod`.
fn path_name(path: &[Step]) -> String {
    let mut out = String::new();
    for s in path {
        match s {
            Step::Key(k) => {
                if !out.is_empty() {
                    out.push('.');
                }
                out.push_str(k);
            }
            Step::Element => out.push_str("[]"),
            Step::Entry => out.push_str(".*"),
            Step::Tagged(tag, variant) => out.push_str(&format!("[] {tag}={variant}")),
        }
    }
    out
}

/// The document with `inner` as the table at `path`.
fn planted(path: &[Step], inner: Table) -> Table {
    let mut v = Value::Table(inner);
    for s in path.iter().rev() {
        v = match s {
            Step::Key(k) => Value::Table(Table::from_iter([(k.clone(), v)])),
            Step::Entry => Value::Table(Table::from_iter([(PROBE.to_string(), v)])),
            Step::Element => Value::Array(vec![v]),
            Step::Tagged(tag, variant) => {
                let mut t = match v {
                    Value::Table(t) => t,
                    other => Table::from_iter([(PROBE.to_string(), other)]),
                };
                t.insert(tag.clone(), Value::String(variant.clone()));
                Value::Array(vec![Value::Table(t)])
            }
        };
    }
    match v {
        Value::Table(t) => t,
        other => Table::from_iter([(PROBE.to_string(), other)]),
    }
}

/// The back-quoted words of `text` after `after`, on its line (the parser's message names the
/// table on the next line: "in `inner`").
fn quoted_after(text: &str, after: &str) -> Option<Vec<String>> {
    let rest = &text[text.find(after)? + after.len()..];
    let rest = rest.lines().next().unwrap_or("");
    Some(
        rest.split('`')
            .skip(1)
            .step_by(2)
            .map(str::to_string)
            .collect(),
    )
}

/// The keys a table at `path` accepts, if it is a table that rejects unknown keys.
fn table_keys(load: &dyn Fn(Table) -> Result<(), String>, path: &[Step]) -> Option<Vec<String>> {
    let message = load(planted(
        path,
        Table::from_iter([(PROBE.into(), Value::Integer(0))]),
    ))
    .err()?;
    let unknown = format!("unknown field `{PROBE}`");
    if !message.contains(&unknown) {
        return None;
    }
    if message.contains("there are no fields") {
        return Some(Vec::new());
    }
    quoted_after(&message, &format!("{unknown}, expected"))
}

/// What the loader accepts: for each table (by [`path_name`]), its keys that hold values (the
/// keys that hold tables have their own entry). Problems (a table that accepts any key) go to
/// `problems`.
struct Accepted {
    tables: BTreeMap<String, BTreeSet<String>>,
    problems: Vec<String>,
}

impl Accepted {
    /// Reads the tables of the type `load` deserialises, from the table at `path` down.
    fn read(load: &dyn Fn(Table) -> Result<(), String>, path: Vec<Step>) -> Self {
        let mut out = Self {
            tables: BTreeMap::new(),
            problems: Vec::new(),
        };
        out.walk(load, path);
        out
    }

    fn walk(&mut self, load: &dyn Fn(Table) -> Result<(), String>, path: Vec<Step>) {
        let name = path_name(&path);
        let Some(keys) = table_keys(load, &path) else {
            self.problems.push(format!(
                "table `{name}` does not reject an unknown key: its keys cannot be read"
            ));
            return;
        };
        let mut values = BTreeSet::new();
        for key in keys {
            let mut child = path.clone();
            child.push(Step::Key(key.clone()));
            let nested = [vec![], vec![Step::Element], vec![Step::Entry]]
                .into_iter()
                .map(|tail| child.iter().cloned().chain(tail).collect::<Vec<_>>())
                .find(|p| table_keys(load, p).is_some());
            if let Some(p) = nested {
                self.walk(load, p);
            } else if let Some((tag, variants)) = tagged(load, &child) {
                // The array's own table holds the tag; each variant's, the rest.
                let mut array = child.clone();
                array.push(Step::Element);
                self.tables
                    .insert(path_name(&array), BTreeSet::from([tag.clone()]));
                for v in variants {
                    let mut p = child.clone();
                    p.push(Step::Tagged(tag.clone(), v));
                    self.walk(load, p);
                }
            } else {
                values.insert(key);
            }
        }
        self.tables.insert(name, values);
    }
}

/// For an array of tables tagged by a key (`kind = "rod"`): the tag and its variants.
fn tagged(
    load: &dyn Fn(Table) -> Result<(), String>,
    path: &[Step],
) -> Option<(String, Vec<String>)> {
    let mut element = path.to_vec();
    element.push(Step::Element);
    let message = load(planted(&element, Table::new())).err()?;
    let tag = quoted_after(&message, "missing field")?
        .into_iter()
        .next()?;
    let probe = Table::from_iter([(tag.clone(), Value::String(PROBE.into()))]);
    let message = load(planted(&element, probe)).err()?;
    let variants = quoted_after(&message, &format!("unknown variant `{PROBE}`, expected"))?;
    Some((tag, variants))
}

/// Deserialises a document as `T`, the error as text.
fn loader<T: DeserializeOwned>() -> impl Fn(Table) -> Result<(), String> {
    |t: Table| t.try_into::<T>().map(drop).map_err(|e| e.to_string())
}

/// What the scene loader accepts: a [`SceneFile`], and a `[variant]` table ([`VariantDef`],
/// read by the loader before the rest of the file).
fn scene_loader_accepts() -> Accepted {
    let mut accepted = Accepted::read(&loader::<SceneFile>(), Vec::new());
    let variant = Accepted::read(&loader::<VariantDef>(), Vec::new());
    for (name, keys) in variant.tables {
        let name = if name.is_empty() {
            "variant".to_string()
        } else {
            format!("variant.{name}")
        };
        accepted.tables.insert(name, keys);
    }
    accepted.problems.extend(variant.problems);
    accepted
}

/// A heading's table in [`path_name`] form: `` `[[link]]` `` → `link[]`,
/// `` `[parameters.<name>]` `` → `parameters.*`, `` `[[shape]]` with `kind = "rod"` `` →
/// `shape[] kind=rod`, "Top-level keys" → ``; None for other headings.
fn heading_path(heading: &str) -> Option<String> {
    if heading.trim() == "Top-level keys" {
        return Some(String::new());
    }
    let mut code = heading.split('`').skip(1).step_by(2);
    let header = code.next()?;
    let (inner, array) = if let Some(h) = header.strip_prefix("[[") {
        (h.strip_suffix("]]")?, true)
    } else {
        (header.strip_prefix('[')?.strip_suffix(']')?, false)
    };
    let mut name = inner
        .split('.')
        .map(|s| if s.starts_with('<') { "*" } else { s })
        .collect::<Vec<_>>()
        .join(".");
    if array {
        name.push_str("[]");
    }
    if let Some(tag) = code.next() {
        let (k, v) = tag.split_once('=')?;
        name.push_str(&format!(" {}={}", k.trim(), v.trim().trim_matches('"')));
    }
    Some(name)
}

/// The tables and keys a reference documents: each heading naming a table (see
/// [`heading_path`]) and the first cells (`` `key` ``) of the table rows under it.
fn documented(markdown: &str) -> BTreeMap<String, BTreeSet<String>> {
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut current: Option<String> = None;
    let mut in_code = false;
    for line in markdown.lines() {
        if line.starts_with("```") {
            in_code = !in_code;
        }
        if in_code {
            continue;
        }
        if let Some(h) = line.strip_prefix('#') {
            current = heading_path(h.trim_start_matches('#'));
            if let Some(c) = &current {
                out.entry(c.clone()).or_default();
            }
            continue;
        }
        let (Some(c), Some(row)) = (&current, line.strip_prefix("| `")) else {
            continue;
        };
        if let Some((key, _)) = row.split_once('`') {
            out.entry(c.clone()).or_default().insert(key.to_string());
        }
    }
    out
}

/// Differences between what a reference documents and what a loader accepts, one line each.
fn check(accepted: &Accepted, markdown: &str) -> Vec<String> {
    let documented = documented(markdown);
    let mut out = accepted.problems.clone();
    let tables: BTreeSet<&String> = accepted.tables.keys().chain(documented.keys()).collect();
    let shown = |t: &str| {
        if t.is_empty() {
            "the top level".to_string()
        } else {
            format!("`{t}`")
        }
    };
    for t in tables {
        match (accepted.tables.get(t), documented.get(t)) {
            (Some(_), None) => {
                out.push(format!("table {} is accepted but not documented", shown(t)))
            }
            (None, Some(_)) => {
                out.push(format!("table {} is documented but not accepted", shown(t)))
            }
            (Some(a), Some(d)) => {
                for k in a.difference(d) {
                    out.push(format!(
                        "key `{k}` of {} is accepted but not documented",
                        shown(t)
                    ));
                }
                for k in d.difference(a) {
                    out.push(format!(
                        "key `{k}` of {} is documented but not accepted",
                        shown(t)
                    ));
                }
            }
            (None, None) => {}
        }
    }
    out
}

/// docs/scenes.md.
fn reference() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/scenes.md")).unwrap()
}

#[test]
fn the_reference_documents_exactly_what_the_loader_accepts() {
    let accepted = scene_loader_accepts();
    // The reading itself works: the tables every scene has, and a tagged one, were found.
    for t in [
        "",
        "scene",
        "link[]",
        "parameters.*",
        "shape[] kind=rod",
        "variant.joint.*",
    ] {
        assert!(
            accepted.tables.contains_key(t),
            "`{t}` not read: {:?}",
            accepted.tables
        );
    }
    assert!(accepted.tables["link[]"].contains("damping"));
    let problems = check(&accepted, &reference());
    assert!(
        problems.is_empty(),
        "docs/scenes.md:\n{}",
        problems.join("\n")
    );
}

#[test]
fn the_references_examples_load() {
    let text = reference();
    let blocks: Vec<String> = text
        .split("```toml\n")
        .skip(1)
        .filter_map(|b| b.split_once("```").map(|(code, _)| code.to_string()))
        .collect();
    assert_eq!(blocks.len(), 2, "a scene and a variant of a built-in one");
    let scene = Scene::parse("docs/scenes.md", &blocks[0]).unwrap();
    assert_eq!(scene.setup().unwrap().walker.model().dof(), 2);
    let variant = Scene::parse("docs/scenes.md", &blocks[1]).unwrap();
    assert_eq!(variant.values["slope_rad"], 0.04);
    let built = variant.build().unwrap();
    let model = built.model();
    let swing = model.link_index("swing_leg").unwrap();
    assert_eq!(model.links[swing.0].joint_force.damping, 0.3);
}

/// A small loader with a key its reference forgets: the check names it.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct Planted {
    documented: f64,
    inner: PlantedInner,
    #[serde(rename = "item")]
    items: Vec<PlantedItem>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct PlantedInner {
    also_documented: f64,
    undocumented: Option<f64>,
}

#[derive(Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
#[allow(dead_code)]
enum PlantedItem {
    Dot { size_m: f64 },
}

#[test]
fn a_key_the_reference_does_not_document_fails_the_check() {
    let accepted = Accepted::read(&loader::<Planted>(), Vec::new());
    let mut tables = accepted.tables.clone();
    assert_eq!(
        tables.remove("").unwrap(),
        BTreeSet::from(["documented".to_string()])
    );
    assert_eq!(tables["inner"].len(), 2);
    assert_eq!(tables["item[]"], BTreeSet::from(["kind".to_string()]));
    assert_eq!(
        tables["item[] kind=dot"],
        BTreeSet::from(["size_m".to_string()])
    );
    let reference = "# Planted\n\n## Top-level keys\n\n| key | meaning |\n| --- | --- |\n\
                     | `documented` | a number |\n\n## `[inner]`\n\n| key | meaning |\n\
                     | --- | --- |\n| `also_documented` | a number |\n| `gone` | no more |\n\n\
                     ## `[[item]]`\n\n| `kind` | `dot` |\n\n\
                     ### `[[item]]` with `kind = \"dot\"`\n\n| `size_m` | size |\n";
    assert_eq!(
        check(&accepted, reference),
        vec![
            "key `undocumented` of `inner` is accepted but not documented".to_string(),
            "key `gone` of `inner` is documented but not accepted".to_string(),
        ]
    );
}
