//! The start state of `walker walk`: another scene's gait, a start-state file, perturbations.

use crate::input_error::InputError;
use crate::output;
use anyhow::Result;
use nalgebra::DVector;
use serde_json::Value;
use sim::analysis::homotopy::GaitRule;
use sim::engine::walker::Walker;
use sim::report::StartRecord;
use sim::scene::text_file::read_text_file;
use sim::scene::Scene;

/// The gait of scene `other` (with this scene's shared parameter values) by the one gait
/// rule, mapped onto this walker's stride-map entries by name, with where it came from
/// ([`sim::analysis::walk_start::other_scene_gait`]). `None` (after a message) if it has no
/// gait.
pub fn from_other_scene(
    other: &str,
    scene: &Scene,
    walker: &Walker,
    rule: &GaitRule<'_>,
) -> Result<Option<(DVector<f64>, StartRecord)>> {
    match sim::analysis::walk_start::other_scene_gait(other, scene, walker, rule)? {
        Ok(start) => Ok(Some((
            start.state,
            StartRecord::gait(start.scene.name(), &start.gait, start.source),
        ))),
        Err(e) => {
            output::note(format_args!(
                "error: scene `{other}` has no gait to start from: {e}"
            ));
            Ok(None)
        }
    }
}

/// The entries a start-state file sets, as (stride-map index, value); every problem with the
/// file is bad input naming it.
pub fn read_start_state(
    path: &std::path::Path,
    names: &[String],
) -> Result<Vec<(usize, f64)>, InputError> {
    let bad = |why: String| InputError::Other(format!("--start-state `{}`: {why}", path.display()));
    // A regular file of at most `MAX_START_STATE_BYTES`: a path to a huge file, `/dev/zero` or
    // a FIFO is refused instead of filling memory or blocking.
    let text = read_text_file(path, MAX_START_STATE_BYTES, "a start state")
        .map_err(|e| bad(e.to_string()))?;
    parse_start_state(&text, names).map_err(bad)
}

/// Largest start-state file read \[bytes\] (a `walker gait --json` output is a few kB).
pub const MAX_START_STATE_BYTES: u64 = 1 << 20;

/// The entries the text of a start-state file sets, as (stride-map index, value), or what is
/// wrong with it. Never panics, whatever the text.
pub fn parse_start_state(text: &str, names: &[String]) -> Result<Vec<(usize, f64)>, String> {
    // serde_json's `Value` keeps the last of two equal keys: a file that sets an entry twice
    // is refused first, naming the key.
    serde_json::from_str::<UniqueKeys>(text).map_err(|e| match e.classify() {
        serde_json::error::Category::Data => e.to_string(),
        _ => format!("not JSON: {e}"),
    })?;
    let doc: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    // A `walker gait --json` output also lists its scene's conventional outputs (e.g.
    // Goswami's angles) in `fixed_point`: there, only the stride-map entries are read.
    let (obj, from_gait) = match doc.get("fixed_point") {
        Some(f) => (f, true),
        None => (&doc, false),
    };
    let obj = obj
        .as_object()
        .ok_or_else(|| "expected an object of entry names to numbers".to_string())?;
    let mut out = Vec::with_capacity(obj.len());
    for (k, x) in obj {
        let Some(i) = names.iter().position(|n| n == k) else {
            if from_gait {
                continue;
            }
            return Err(format!("unknown entry `{k}` (known: {})", names.join(", ")));
        };
        let x = x
            .as_f64()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("`{k}` = {x} is not a finite number"))?;
        out.push((i, x));
    }
    if out.is_empty() {
        return Err("names no entry".into());
    }
    Ok(out)
}

/// A JSON document in which no object names a key twice; deserialising it fails with
/// "duplicate key `k`" otherwise. Holds nothing: it only checks.
struct UniqueKeys;

impl<'de> serde::Deserialize<'de> for UniqueKeys {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(UniqueKeysVisitor)
    }
}

struct UniqueKeysVisitor;

impl<'de> serde::de::Visitor<'de> for UniqueKeysVisitor {
    type Value = UniqueKeys;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("any JSON value")
    }
    fn visit_bool<E>(self, _: bool) -> Result<UniqueKeys, E> {
        Ok(UniqueKeys)
    }
    fn visit_i64<E>(self, _: i64) -> Result<UniqueKeys, E> {
        Ok(UniqueKeys)
    }
    fn visit_u64<E>(self, _: u64) -> Result<UniqueKeys, E> {
        Ok(UniqueKeys)
    }
    fn visit_f64<E>(self, _: f64) -> Result<UniqueKeys, E> {
        Ok(UniqueKeys)
    }
    fn visit_str<E>(self, _: &str) -> Result<UniqueKeys, E> {
        Ok(UniqueKeys)
    }
    fn visit_unit<E>(self) -> Result<UniqueKeys, E> {
        Ok(UniqueKeys)
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<UniqueKeys, A::Error> {
        while seq.next_element::<UniqueKeys>()?.is_some() {}
        Ok(UniqueKeys)
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<UniqueKeys, A::Error> {
        let mut seen = std::collections::BTreeSet::new();
        while let Some(key) = map.next_key::<String>()? {
            map.next_value::<UniqueKeys>()?;
            if !seen.insert(key.clone()) {
                return Err(serde::de::Error::custom(format_args!(
                    "duplicate key `{key}`"
                )));
            }
        }
        Ok(UniqueKeys)
    }
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

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use proptest::prelude::*;

    fn names() -> Vec<String> {
        ["stance_leg", "swing_leg", "stance_leg_dot", "swing_leg_dot"]
            .map(String::from)
            .to_vec()
    }

    #[test]
    fn a_key_given_twice_is_named_not_silently_overwritten() {
        let e =
            parse_start_state(r#"{"stance_leg": 0.1, "stance_leg": 0.2}"#, &names()).unwrap_err();
        assert!(e.contains("duplicate key `stance_leg`"), "{e}");
        // Also inside a gait output's `fixed_point`, and in any nested object.
        let e = parse_start_state(
            r#"{"fixed_point": {"swing_leg": 0.1, "swing_leg": 0.2}}"#,
            &names(),
        )
        .unwrap_err();
        assert!(e.contains("`swing_leg`"), "{e}");
        let e = parse_start_state(r#"{"stance_leg": 0.1, "x": {"a": 1, "a": 2}}"#, &names())
            .unwrap_err();
        assert!(e.contains("`a`"), "{e}");
        // Distinct keys are fine.
        assert_eq!(
            parse_start_state(r#"{"stance_leg": 0.1, "swing_leg": 0.2}"#, &names()).unwrap(),
            vec![(0, 0.1), (1, 0.2)]
        );
    }

    /// Arbitrary JSON values, nested a few levels, with keys drawn mostly from the entry names
    /// (so that duplicates and valid entries both occur).
    fn json_value() -> impl Strategy<Value = String> {
        let key = prop_oneof![
            prop::sample::select(vec![
                "stance_leg",
                "swing_leg",
                "stance_leg_dot",
                "swing_leg_dot",
                "fixed_point",
            ])
            .prop_map(String::from),
            "[a-z_]{0,8}",
        ];
        let leaf = prop_oneof![
            Just("null".to_string()),
            any::<bool>().prop_map(|b| b.to_string()),
            any::<f64>().prop_map(|x| x.to_string()),
            any::<i64>().prop_map(|x| x.to_string()),
            "[ -~]{0,12}".prop_map(|s| serde_json::Value::from(s).to_string()),
        ];
        leaf.prop_recursive(4, 48, 6, move |inner| {
            prop_oneof![
                prop::collection::vec(inner.clone(), 0..6)
                    .prop_map(|v| format!("[{}]", v.join(","))),
                prop::collection::vec((key.clone(), inner), 0..6).prop_map(|v| {
                    let parts: Vec<String> = v
                        .into_iter()
                        .map(|(k, x)| format!("{}:{x}", serde_json::Value::from(k)))
                        .collect();
                    format!("{{{}}}", parts.join(","))
                }),
            ]
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        /// Whatever the text, the reader returns entries or a message; never panics.
        #[test]
        fn any_text_gives_entries_or_a_message(text in "\\PC{0,64}") {
            match parse_start_state(&text, &names()) {
                Ok(entries) => prop_assert!(!entries.is_empty()),
                Err(e) => prop_assert!(!e.is_empty()),
            }
        }

        /// Whatever the JSON, the reader returns finite values at known indices, each entry
        /// once, or a message; never panics.
        #[test]
        fn any_json_gives_valid_entries_or_a_message(text in json_value()) {
            match parse_start_state(&text, &names()) {
                Ok(entries) => {
                    prop_assert!(!entries.is_empty());
                    for (k, (i, x)) in entries.iter().enumerate() {
                        prop_assert!(*i < names().len() && x.is_finite());
                        prop_assert!(entries[..k].iter().all(|(j, _)| j != i));
                    }
                }
                Err(e) => prop_assert!(!e.is_empty()),
            }
        }
    }
}
