//! The scripted scenarios pass their expectations on the host, are deterministic, and match
//! the committed golden digests (the same digests the QEMU run must print).
//!
//! Regenerate the golden file after an intended behaviour change with
//! `UPDATE_GOLDEN=1 cargo test -p firmware --test scenarios`.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use firmware::scenarios::{run, NoHook, SCENARIOS};

const GOLDEN: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/golden/scenario-digests.txt"
);

#[test]
fn every_scenario_meets_its_expectations() {
    for sc in SCENARIOS {
        let mut out = String::new();
        let s = run(sc, &mut out, &mut NoHook).unwrap();
        assert_eq!(sc.verdict(&s), Ok(()), "{}: {s:?}", sc.name);
        assert_eq!(out.lines().count() as u32, sc.ticks + 2);
    }
}

#[test]
fn runs_are_deterministic() {
    for sc in SCENARIOS {
        let (mut a, mut b) = (String::new(), String::new());
        run(sc, &mut a, &mut NoHook).unwrap();
        run(sc, &mut b, &mut NoHook).unwrap();
        assert_eq!(a, b);
    }
}

#[test]
fn digests_match_golden_file() {
    let mut digests = String::new();
    for sc in SCENARIOS {
        let mut out = String::new();
        run(sc, &mut out, &mut NoHook).unwrap();
        digests.push_str(out.lines().last().unwrap());
        digests.push('\n');
    }
    if std::env::var_os("UPDATE_GOLDEN").is_some() {
        std::fs::create_dir_all(std::path::Path::new(GOLDEN).parent().unwrap()).unwrap();
        std::fs::write(GOLDEN, &digests).unwrap();
    }
    let golden = std::fs::read_to_string(GOLDEN).expect("golden file; see module docs");
    assert_eq!(digests, golden);
}
