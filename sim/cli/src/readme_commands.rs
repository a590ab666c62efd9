//! The README's example `walker …` commands parse: each line of a fenced code block of
//! README.md that runs `walker` (or `cargo run … -p walker-cli -- …`) goes through the same
//! clap parser as the binary, its optional parts (`[--json]`, `[--set k=v]...`) included, so
//! that a renamed or removed flag fails the test, naming the line.

#![allow(clippy::expect_used, clippy::panic)]

use crate::Cli;
use clap::Parser;

/// README.md at the repository's root.
const README: &str = include_str!("../../../README.md");

/// The `walker` arguments of each command line in the README's fenced code blocks, with the
/// line's number and text: `walker ARGS` and `cargo run … -- ARGS` (a `cargo install` line
/// runs nothing). Optional parts are kept (their brackets and `...` removed), trailing
/// `# comments` dropped, `\` continuations joined.
fn readme_commands(readme: &str) -> Vec<(usize, String, Vec<String>)> {
    let mut out = Vec::new();
    let mut in_block = false;
    let mut pending: Option<(usize, String)> = None;
    for (i, line) in readme.lines().enumerate() {
        let trimmed = line.trim();
        if trimmed.starts_with("```") {
            in_block = !in_block;
            continue;
        }
        if !in_block {
            continue;
        }
        let (number, text) = match pending.take() {
            Some((n, start)) => (n, format!("{start} {trimmed}")),
            None => (i + 1, trimmed.to_owned()),
        };
        if let Some(start) = text.strip_suffix('\\') {
            pending = Some((number, start.trim_end().to_owned()));
            continue;
        }
        let command = text.split(" #").next().unwrap_or("").trim();
        let args = if let Some(rest) = command.strip_prefix("walker ") {
            rest
        } else if command.starts_with("cargo run") && command.contains("walker-cli") {
            match command.split_once(" -- ") {
                Some((_, rest)) => rest,
                None => continue,
            }
        } else {
            continue;
        };
        let words = args
            .replace(['[', ']'], " ")
            .replace("...", " ")
            .split_whitespace()
            .map(str::to_owned)
            .collect();
        out.push((number, text.clone(), words));
    }
    out
}

#[test]
fn every_walker_command_of_the_readme_parses() {
    let commands = readme_commands(README);
    // The main job, the scene list and the software-in-the-loop walk at least: an extraction
    // that finds nothing must not pass.
    for needed in ["gait --scene wisse3d", "scenes", "sil --scene wisse3d"] {
        assert!(
            commands
                .iter()
                .any(|(_, _, w)| w.join(" ").starts_with(needed)),
            "no README command `walker {needed} …` found in its code blocks"
        );
    }
    let failures: Vec<String> = commands
        .iter()
        .filter_map(|(number, text, words)| {
            let argv = std::iter::once("walker".to_owned()).chain(words.iter().cloned());
            Cli::try_parse_from(argv)
                .err()
                .map(|e| format!("README.md:{number}: `{text}`: {}", e.kind()))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_renamed_flag_fails_and_names_its_line() {
    let readme = "text\n```sh\nwalker gait --scene compass [--json]\nwalker gait --sceen compass   # typo\n```\nwalker gait --nonsense\n";
    let commands = readme_commands(readme);
    // The line outside a code block is not a command.
    assert_eq!(commands.len(), 2);
    assert_eq!(commands[0].0, 3);
    assert_eq!(commands[0].2, ["gait", "--scene", "compass", "--json"]);
    let argv = |w: &[String]| {
        std::iter::once("walker".to_owned())
            .chain(w.iter().cloned())
            .collect::<Vec<_>>()
    };
    assert!(Cli::try_parse_from(argv(&commands[0].2)).is_ok());
    assert_eq!(commands[1].0, 4);
    assert!(Cli::try_parse_from(argv(&commands[1].2)).is_err());
}

#[test]
fn continuations_and_cargo_run_lines_are_read() {
    let readme = "```sh\ncargo run --release -p walker-cli -- gait --scene wisse3d\nwalker sil --scene wisse3d \\\n    --steps 3 --json\ncargo install --path sim/cli\n```\n";
    let commands = readme_commands(readme);
    let words: Vec<String> = commands.iter().map(|c| c.2.join(" ")).collect();
    assert_eq!(
        words,
        [
            "gait --scene wisse3d",
            "sil --scene wisse3d --steps 3 --json"
        ]
    );
    assert_eq!(commands[1].0, 3);
}
