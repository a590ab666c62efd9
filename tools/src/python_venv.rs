//! The project's Python venv (`scripts/python-venv`: python-can and cantools) for the tests
//! that run the Python bus monitor (`python/walker_monitor.py`) against a live bus.
//!
//! When the venv cannot be created such a test is skipped, saying so on stderr, unless
//! `WALKER_REQUIRE_PYTHON` is set (`scripts/test-all` sets it to 1): then it must fail.

use std::fmt;
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::repo_root;

/// The environment variable that makes a missing venv an error instead of a skipped test.
pub const REQUIRE_PYTHON_VAR: &str = "WALKER_REQUIRE_PYTHON";

/// A created venv.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PythonVenv {
    python: PathBuf,
}

/// The venv cannot be created and [`REQUIRE_PYTHON_VAR`] is set.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VenvRequired {
    /// Why it cannot be created (the script's exit status and output, or why it did not run).
    pub why: String,
}

impl fmt::Display for VenvRequired {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{REQUIRE_PYTHON_VAR} is set and the venv cannot be created: {}",
            self.why
        )
    }
}

impl std::error::Error for VenvRequired {}

impl PythonVenv {
    /// Create (or refresh) the venv for the test named `test`. `Ok(None)` when it cannot be
    /// created and the test is to be skipped (after printing `SKIPPED <test>: ...` on stderr).
    ///
    /// # Errors
    /// [`VenvRequired`] when it cannot be created and [`REQUIRE_PYTHON_VAR`] is set.
    pub fn for_test(test: &str) -> Result<Option<Self>, VenvRequired> {
        let root = repo_root();
        let out = Command::new(root.join("scripts/python-venv"))
            .current_dir(&root)
            .output();
        let why = match out {
            Ok(o) if o.status.success() => {
                return Ok(Some(PythonVenv {
                    python: root.join(".venv/bin/python"),
                }))
            }
            Ok(o) => format!(
                "scripts/python-venv exited with {}: {}{}",
                o.status,
                String::from_utf8_lossy(&o.stdout),
                String::from_utf8_lossy(&o.stderr)
            ),
            Err(e) => format!("scripts/python-venv could not run: {e}"),
        };
        if std::env::var_os(REQUIRE_PYTHON_VAR).is_some() {
            return Err(VenvRequired { why });
        }
        eprintln!("SKIPPED {test}: the Python venv cannot be created ({why})");
        Ok(None)
    }

    /// The venv's interpreter.
    pub fn python(&self) -> &Path {
        &self.python
    }

    /// `python python/walker_monitor.py`, run from the repository root; add its arguments.
    pub fn monitor(&self) -> Command {
        let root = repo_root();
        let mut c = Command::new(&self.python);
        c.arg(root.join("python/walker_monitor.py"))
            .current_dir(root);
        c
    }
}
