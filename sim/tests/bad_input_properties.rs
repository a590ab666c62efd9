//! Property tests: arbitrary scene text and arbitrary expressions, however deeply nested,
//! never panic or overflow the stack; loading and building a scene is always `Ok` or a
//! `SceneError` (issue #14). Case counts are bounded so that the file runs in seconds.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use sim::scene::expr::{self, ExprError};
use sim::scene::{Scene, BUILTIN};
use std::collections::BTreeMap;

fn compass() -> &'static str {
    BUILTIN.iter().find(|(n, _)| *n == "compass").unwrap().1
}

/// Text from the characters of expressions, with long runs of openers and signs.
fn expression_text() -> impl Strategy<Value = String> {
    let piece = prop_oneof![
        "[-+*/^() .0-9eEa-z_]{0,12}",
        (1usize..5_000).prop_map(|n| "(".repeat(n)),
        (1usize..5_000).prop_map(|n| ")".repeat(n)),
        (1usize..20_000).prop_map(|n| "-".repeat(n)),
        (1usize..2_000).prop_map(|n| "sqrt(".repeat(n)),
        (1usize..2_000).prop_map(|n| vec!["2"; n].join("^")),
        Just("slope_rad".to_string()),
        Just("é".to_string()),
    ];
    prop::collection::vec(piece, 0..6).prop_map(|v| v.concat())
}

/// A scene text: the compass scene with one region replaced by arbitrary text.
fn mutated_scene() -> impl Strategy<Value = String> {
    let text = compass();
    let len = text.len();
    (
        0..len,
        0usize..200,
        "\\PC{0,40}|[\\[\\]{}=\"'.,#\n a-z0-9_-]{0,40}",
    )
        .prop_map(move |(at, cut, insert)| {
            let mut at = at;
            while !text.is_char_boundary(at) {
                at -= 1;
            }
            let mut end = (at + cut).min(len);
            while !text.is_char_boundary(end) {
                end -= 1;
            }
            format!("{}{}{}", &text[..at], insert, &text[end..])
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn expressions_evaluate_or_give_an_error(e in expression_text()) {
        let mut vars = BTreeMap::new();
        vars.insert("slope_rad".to_string(), 0.01);
        match expr::eval(&e, &vars) {
            Ok(_) => {}
            Err(ExprError::TooDeep { max_depth, .. }) => prop_assert_eq!(max_depth, expr::MAX_DEPTH),
            Err(ExprError::Syntax { .. } | ExprError::UnknownName { .. }) => {}
        }
    }

    #[test]
    fn any_expression_in_a_scene_builds_or_gives_a_scene_error(e in expression_text()) {
        let text = compass().replacen(
            r#"slope_rad = "slope_rad""#,
            &format!("slope_rad = {:?}", e),
            1,
        );
        if let Ok(scene) = Scene::parse("prop.toml", &text) {
            let _ = scene.setup();
        }
    }

    #[test]
    fn arbitrary_text_loads_or_gives_a_scene_error(text in "\\PC{0,300}") {
        if let Ok(scene) = Scene::parse("prop.toml", &text) {
            let _ = scene.setup();
        }
    }

    #[test]
    fn a_mutated_scene_loads_and_builds_or_gives_a_scene_error(text in mutated_scene()) {
        if let Ok(mut scene) = Scene::parse("prop.toml", &text) {
            if let Ok(setup) = scene.setup() {
                // A scene that builds has valid stride settings.
                prop_assert!(setup.settings.validate().is_ok());
            }
            let _ = scene.set_text("slope_rad=0.02");
        }
    }

    #[test]
    fn deep_toml_nesting_gives_a_file_error(open in "[\\[{]", n in 1usize..50_000) {
        let opener = if open == "[" { "[" } else { "{ a = " };
        let text = format!("x = {}", opener.repeat(n));
        prop_assert!(Scene::parse("prop.toml", &text).is_err());
    }
}
