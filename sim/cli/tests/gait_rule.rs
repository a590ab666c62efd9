//! One gait everywhere: at parameter values drawn at random, `walker gait`, `walk`,
//! `stability-map` and `tune` (and `sil`, for a walker with actuated ankles) report the same
//! gait — the same largest |eigenvalue| and step period to the bit, from the same source — or
//! all report none. Each runs the release binary as a user would.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::walker;
use proptest::prelude::*;
use serde_json::Value;

/// `walker <args> --json`, parsed (whatever the exit code: no gait is an answer too); `null`
/// when the command printed nothing (a walk with no gait to start from).
fn json(args: &[&str]) -> Value {
    let out = walker(&[args, &["--json"]].concat());
    if out.stdout.is_empty() {
        return Value::Null;
    }
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "walker {args:?}: {e}\n{}",
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

/// The gait one command reports: (max |λ|, step period [s], source), `None` for no gait.
type Reported = Option<(f64, f64, String)>;

fn reported(max_abs: &Value, period: &Value, source: &Value) -> Reported {
    Some((
        max_abs.as_f64()?,
        period.as_f64()?,
        source.as_str()?.to_string(),
    ))
}

/// What `walker gait`, `stability-map`, `tune` and `walk` (its start's period and source)
/// report at `p1 = v1`, `p2 = v2`.
fn every_command(
    scene: &str,
    (p1, v1): (&str, f64),
    (p2, v2): (&str, f64),
) -> ([Reported; 3], Option<(f64, String)>) {
    let (s1, s2) = (format!("{p1}={v1:?}"), format!("{p2}={v2:?}"));
    let set = ["--scene", scene, "--set", &s1, "--set", &s2];
    let gait = json(&[&["gait"], &set[..]].concat());
    let gait = reported(
        &gait["max_abs_eigenvalue"],
        &gait["step_period_s"],
        &gait["gait_source"],
    );
    let walk = json(&[&["walk", "--steps", "1"], &set[..]].concat());
    let start = &walk["start"];
    let walk = start["gait_step_period_s"]
        .as_f64()
        .zip(start["gait_source"].as_str().map(str::to_string));
    let (x, y) = (
        format!("{p1}={v1:?}:{v1:?}:1"),
        format!("{p2}={v2:?}:{v2:?}:1"),
    );
    let map = json(&["stability-map", "--scene", scene, "--x", &x, "--y", &y]);
    let map = reported(
        &map["max_abs_eigenvalue"][0][0],
        &map["step_period_s"][0][0],
        &map["gait_source"][0][0],
    );
    // One evaluation: tune's first point is the scene's values (inside the bounds).
    let vary = format!("{p1}={:?}:{:?}", v1 - 1e-3, v1 + 1e-3);
    let tune = json(&[&["tune", "--vary", &vary, "--evaluations", "1"], &set[..]].concat());
    let first = &tune["history"][0];
    assert_eq!(first["values"][0].as_f64(), Some(v1), "{tune}");
    let tune = reported(
        &first["max_abs_eigenvalue"],
        &first["step_period_s"],
        &first["gait_source"],
    );
    ([gait, map, tune], walk)
}

fn agree(scene: &str, p1: (&str, f64), p2: (&str, f64)) -> Result<(), TestCaseError> {
    let ([gait, map, tune], walk) = every_command(scene, p1, p2);
    let at = format!("{scene} at {p1:?}, {p2:?}");
    prop_assert_eq!(&map, &gait, "stability-map against gait, {}", at);
    prop_assert_eq!(&tune, &gait, "tune against gait, {}", at);
    prop_assert_eq!(
        walk,
        gait.map(|g| (g.1, g.2)),
        "walk's start against gait, {}",
        at
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn compass(slope in 0.0f64..0.12, leg_mass in 0.5f64..20.0) {
        agree("compass", ("slope_rad", slope), ("leg_mass_kg", leg_mass))?;
    }

    #[test]
    fn simplest(slope in 0.0005f64..0.03, hip_mass in 0.5f64..2.0) {
        agree("simplest", ("slope_rad", slope), ("hip_mass_kg", hip_mass))?;
    }

    #[test]
    fn kneed2d(slope in 0.03f64..0.07, hip_mass in 0.3f64..0.8) {
        agree("kneed2d", ("slope_rad", slope), ("hip_mass_kg", hip_mass))?;
    }
}

#[test]
fn sil_starts_from_the_gait_walker_gait_reports() {
    // The firmware in the loop walks from the ideal-actuator gait: the one `walker gait`
    // reports at the same values (here off the defaults, on a slope).
    for slope in ["0.002", "-0.001"] {
        let set = format!("slope_rad={slope}");
        let gait = json(&["gait", "--scene", "wisse2d", "--set", &set]);
        let sil = json(&["sil", "--scene", "wisse2d", "--set", &set, "--steps", "1"]);
        assert_eq!(
            sil["start"]["gait_step_period_s"], gait["step_period_s"],
            "{slope}"
        );
        assert_eq!(sil["start"]["gait_source"], gait["gait_source"], "{slope}");
        assert_eq!(
            sil["ideal_gait"]["max_abs_eigenvalue"], gait["max_abs_eigenvalue"],
            "{slope}"
        );
    }
}

#[test]
fn the_issue_s_reproductions_agree_and_find_a_gait() {
    // Where the stability map once followed its row onto a short-period gait (compass, heavy
    // legs) and the walk started from another gait than `walker gait` (simplest at 0.015,
    // Garcia's long-period gait of 3.912 s): every command reports the one gait.
    for (scene, p1, p2) in [
        ("compass", ("slope_rad", 0.01), ("leg_mass_kg", 19.2)),
        ("compass", ("slope_rad", 0.004015), ("leg_mass_kg", 19.2)),
        ("simplest", ("slope_rad", 0.015), ("hip_mass_kg", 1.0)),
        ("kneed2d", ("slope_rad", 0.05), ("hip_mass_kg", 0.5)),
    ] {
        let ([gait, map, tune], walk) = every_command(scene, p1, p2);
        let g = gait.clone().unwrap_or_else(|| panic!("{scene}: a gait"));
        assert_eq!(map, gait, "{scene} {p1:?}");
        assert_eq!(tune, gait, "{scene} {p1:?}");
        assert_eq!(walk, Some((g.1, g.2.clone())), "{scene} {p1:?}");
        if scene == "simplest" {
            assert!(
                (g.1 - 3.912).abs() < 1e-3,
                "Garcia's long-period gait: {}",
                g.1
            );
        }
    }
}

/// `walker gait` at `p1 = v1`, `p2 = v2`.
fn gait_at(scene: &str, (p1, v1): (&str, f64), (p2, v2): (&str, f64)) -> Reported {
    let (s1, s2) = (format!("{p1}={v1:?}"), format!("{p2}={v2:?}"));
    let g = json(&["gait", "--scene", scene, "--set", &s1, "--set", &s2]);
    reported(
        &g["max_abs_eigenvalue"],
        &g["step_period_s"],
        &g["gait_source"],
    )
}

/// Every cell of a multi-cell map is `walker gait`'s gait at the cell's values: a map that
/// followed its row from the neighbouring cell (the issue's bug) crossed a fold onto the
/// short-period gait there, which a 1×1 map cannot show.
fn map_cells_agree(
    scene: &str,
    (p1, a1, b1, n1): (&str, f64, f64, usize),
    (p2, a2, b2, n2): (&str, f64, f64, usize),
) -> Result<(), TestCaseError> {
    let (x, y) = (
        format!("{p1}={a1:?}:{b1:?}:{n1}"),
        format!("{p2}={a2:?}:{b2:?}:{n2}"),
    );
    let map = json(&["stability-map", "--scene", scene, "--x", &x, "--y", &y]);
    let xs: Vec<f64> = map["x"]["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let ys: Vec<f64> = map["y"]["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    prop_assert_eq!((xs.len(), ys.len()), (n1, n2), "{}", map);
    for (j, &vy) in ys.iter().enumerate() {
        for (i, &vx) in xs.iter().enumerate() {
            let cell = reported(
                &map["max_abs_eigenvalue"][j][i],
                &map["step_period_s"][j][i],
                &map["gait_source"][j][i],
            );
            let gait = gait_at(scene, (p1, vx), (p2, vy));
            prop_assert_eq!(
                cell,
                gait,
                "{} cell {},{} at {}={}, {}={}",
                scene,
                i,
                j,
                p1,
                vx,
                p2,
                vy
            );
        }
    }
    Ok(())
}

/// Every point of a tune with several evaluations is `walker gait`'s gait at its values (the
/// issue's tune warm-started each point from the last fixed point and reported other gaits).
fn tune_points_agree(
    scene: &str,
    (p1, lo, hi): (&str, f64, f64),
    evaluations: usize,
) -> Result<(), TestCaseError> {
    let vary = format!("{p1}={lo:?}:{hi:?}");
    let n = evaluations.to_string();
    let tune = json(&[
        "tune",
        "--scene",
        scene,
        "--vary",
        &vary,
        "--evaluations",
        &n,
    ]);
    let history = tune["history"].as_array().unwrap();
    prop_assert!(history.len() >= 3, "{}", tune);
    for point in history {
        let v = point["values"][0].as_f64().unwrap();
        let s = format!("{p1}={v:?}");
        let g = json(&["gait", "--scene", scene, "--set", &s]);
        prop_assert_eq!(
            reported(
                &point["max_abs_eigenvalue"],
                &point["step_period_s"],
                &point["gait_source"]
            ),
            reported(
                &g["max_abs_eigenvalue"],
                &g["step_period_s"],
                &g["gait_source"]
            ),
            "{} tune point {}={}",
            scene,
            p1,
            v
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn compass_maps_and_tunes(slope in 0.0f64..0.1, width in 0.002f64..0.02, leg_mass in 1.0f64..19.0) {
        map_cells_agree("compass", ("slope_rad", slope, slope + width, 3), ("leg_mass_kg", leg_mass, leg_mass + 1.0, 2))?;
        tune_points_agree("compass", ("slope_rad", slope, slope + width), 6)?;
    }

    #[test]
    fn simplest_maps_and_tunes(slope in 0.002f64..0.017, hip_mass in 0.5f64..1.5) {
        map_cells_agree("simplest", ("slope_rad", slope, slope + 0.002, 3), ("hip_mass_kg", hip_mass, hip_mass + 0.2, 2))?;
        tune_points_agree("simplest", ("slope_rad", slope, slope + 0.002), 5)?;
    }

    #[test]
    fn kneed2d_maps_and_tunes(slope in 0.035f64..0.06, hip_mass in 0.3f64..0.7) {
        map_cells_agree("kneed2d", ("slope_rad", slope, slope + 0.005, 2), ("hip_mass_kg", hip_mass, hip_mass + 0.1, 2))?;
        tune_points_agree("kneed2d", ("slope_rad", slope, slope + 0.005), 4)?;
    }
}

/// The issue's map row, whose cells followed the row across a fold: every cell is `walker
/// gait`'s.
#[test]
fn the_issue_s_map_row_is_walker_gait_cell_by_cell() {
    map_cells_agree(
        "compass",
        ("slope_rad", 0.00202, 0.01, 5),
        ("leg_mass_kg", 19.2, 19.2, 1),
    )
    .unwrap();
}
