//! The committed DBC file, test vectors and docs bus-load table match the protocol definition.
//! Regenerate with `cargo run -p walker-tools -- gen`.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use walker_tools::{generated, repo_root, splice_busload};

#[test]
fn committed_generated_files_are_fresh() {
    for g in generated() {
        let committed = std::fs::read_to_string(repo_root().join(g.path))
            .unwrap_or_else(|e| panic!("{}: {e}", g.path));
        assert!(
            committed == g.content,
            "{} is stale: run `cargo run -p walker-tools -- gen`",
            g.path
        );
    }
}

#[test]
fn docs_busload_table_is_fresh() {
    let doc = std::fs::read_to_string(repo_root().join("docs/protocol.md")).unwrap();
    let spliced = splice_busload(&doc).expect("bus-load markers in docs/protocol.md");
    assert!(
        spliced == doc,
        "docs/protocol.md bus-load table is stale: run `cargo run -p walker-tools -- gen`"
    );
}
