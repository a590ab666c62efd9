//! Helpers shared by the `walker` command's tests: run the binary, read its output.
#![allow(dead_code, clippy::expect_used)]

use std::process::{Command, Output};

/// Runs `walker` with `args` and waits for it.
pub fn walker(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_walker"))
        .args(args)
        .output()
        .expect("walker runs")
}

/// Its standard error as text.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}
