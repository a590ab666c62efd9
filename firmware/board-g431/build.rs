//! The build identifier: the first 8 hex digits of the git commit (`GIT_HASH`), sent in the
//! `Version` message; `00000000` when git is not available (e.g. a source tarball). Also puts
//! this board's memory.x (code in the first 120 KiB, the parameter pages reserved) where
//! cortex-m-rt's link.x finds it.
use std::process::Command;
use std::{env, fs, path::PathBuf};

fn main() {
    if let Some(out) = env::var_os("OUT_DIR").map(PathBuf::from) {
        if let Err(e) = fs::write(out.join("memory.x"), include_bytes!("memory.x")) {
            println!("cargo:warning=memory.x not written: {e}");
        }
        println!("cargo:rustc-link-search={}", out.display());
    }
    println!("cargo:rerun-if-changed=memory.x");
    let hash = Command::new("git")
        .args(["rev-parse", "--short=8", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .filter(|s| s.len() == 8 && s.chars().all(|c| c.is_ascii_hexdigit()))
        .unwrap_or_else(|| "00000000".to_string());
    println!("cargo:rustc-env=GIT_HASH={hash}");
    println!("cargo:rerun-if-changed=../../.git/HEAD");
    println!("cargo:rerun-if-changed=../../.git/index");
}
