//! `walker walk --floor` (issue 26): a step at a chosen heel strike and a rough floor
//! reproducible from its seed; the floor in the report and on each step.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;
use common::{stderr, walker};
use serde_json::Value;

fn walk(args: &[&str]) -> Value {
    let out = walker(&[&["walk", "--json"], args].concat());
    serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{args:?}: {e}: {}", stderr(&out)))
}

#[test]
fn a_step_lands_where_it_is_asked_and_a_rough_floor_repeats_from_its_seed() {
    let base = ["--scene", "compass", "--steps", "4"];
    let plane = walk(&base);
    // a step of zero height is the plane, to the bit
    let zero = walk(&[&base[..], &["--floor", "step:at=2,height_m=0"]].concat());
    assert_eq!(plane["steps"], zero["steps"]);
    // a step down at the second heel strike: the first step is the plane's, the second lands
    // lower and changes what follows
    let down = walk(&[&base[..], &["--floor", "step:at=2,height_m=-0.01"]].concat());
    assert_eq!(down["floor"]["kind"], "step");
    assert_eq!(down["floor"]["height_m"], -0.01);
    let floors: Vec<f64> = down["steps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["floor_step_m"].as_f64().unwrap())
        .collect();
    assert_eq!(floors, vec![0.0, -0.01, 0.0, 0.0]);
    assert_eq!(down["steps"][0], plane["steps"][0]);
    assert_ne!(
        down["steps"][1]["duration_s"],
        plane["steps"][1]["duration_s"]
    );
    // rough: the same seed, the same walk; another seed, another
    let rough = |seed: &str| {
        walk(
            &[
                &base[..],
                &["--floor", &format!("rough:sigma_m=0.002,seed={seed}")],
            ]
            .concat(),
        )
    };
    let (a, b, c) = (rough("5"), rough("5"), rough("6"));
    assert_eq!(a["steps"], b["steps"]);
    assert_ne!(a["steps"], c["steps"]);
    assert!(a["steps"][0]["floor_step_m"].as_f64().unwrap() != 0.0);
    // bad floors: exit 2 naming the flag
    for bad in ["bumpy", "step:at=0,height_m=0.1", "rough:sigma_m=-1"] {
        let out = walker(&[&["walk"], &base[..], &["--floor", bad]].concat());
        assert_eq!(out.status.code(), Some(2), "{bad}: {}", stderr(&out));
        assert!(stderr(&out).contains("--floor"), "{}", stderr(&out));
    }
}

#[test]
fn sil_walks_the_same_floors_with_the_firmware_in_the_loop() {
    let sil = |floor: &str| -> Value {
        let out = walker(&[
            "sil", "--scene", "wisse3d", "--steps", "4", "--floor", floor, "--json",
        ]);
        serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|e| panic!("{floor}: {e}: {}", stderr(&out)))
    };
    let plane = sil("plane");
    assert_eq!(plane["floor"]["kind"], "plane");
    // a zero step is the plane to the bit, firmware and all
    assert_eq!(sil("step:at=2,height_m=0")["steps"], plane["steps"]);
    let down = sil("step:at=2,height_m=-0.001");
    let floors: Vec<f64> = down["steps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["floor_step_m"].as_f64().unwrap())
        .collect();
    assert_eq!(floors[..2], [0.0, -0.001]);
    assert_eq!(down["steps"][0], plane["steps"][0]);
    assert_ne!(
        down["steps"][1]["duration_s"],
        plane["steps"][1]["duration_s"]
    );
    // bad input names the option
    let out = walker(&[
        "sil", "--scene", "wisse3d", "--steps", "4", "--floor", "bumpy",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--floor `bumpy`"), "{}", stderr(&out));
}
