//! Flags `canbus-demo` would have ignored, or taken at a value where its answer means
//! nothing, are refused with exit 2 naming the flag.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::process::{Command, Output};

fn demo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_canbus-demo"))
        .args(args)
        .output()
        .unwrap()
}

fn assert_refused(args: &[&str], names: &[&str]) {
    let out = demo(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    for n in names {
        assert!(err.contains(n), "{args:?}: `{n}` not in {err}");
    }
}

#[test]
fn server_flags_without_a_server_are_refused() {
    assert_refused(
        &["--seconds", "0.01", "--wait-client", "1"],
        &["--wait-client", "needs --socketcand"],
    );
    assert_refused(
        &["--seconds", "0.01", "--socketcand-allow-send"],
        &["--socketcand-allow-send", "needs --socketcand"],
    );
}

/// `--bitrate 1` reported a bus load of 0.00 %: no frame ends within a run.
#[test]
fn bit_rates_outside_classic_can_are_refused() {
    for bad in ["1", "9999", "1000001", "4294967295"] {
        assert_refused(
            &["--seconds", "0.01", "--bitrate", bad],
            &["--bitrate", bad, "10000", "1000000"],
        );
    }
    for good in ["10000", "125000", "1000000"] {
        let out = demo(&["--seconds", "0.01", "--bitrate", good]);
        assert!(
            out.status.success(),
            "{good}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// `drop:…,count=0` did nothing, silently; a count past u32 was called "not a non-negative
/// integer".
#[test]
fn fault_counts_that_hit_nothing_or_overflow_are_refused() {
    for (count, shown) in [
        ("0", "`0`"),
        ("18446744073709551615", "18446744073709551615"),
    ] {
        let spec = format!("drop:id=0x072,count={count}");
        assert_refused(
            &["--seconds", "0.01", "--fault", &spec],
            &["count", shown, "from 1 to 4294967295"],
        );
    }
}
