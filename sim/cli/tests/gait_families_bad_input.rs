//! Bad input to `walker gaits`, `walker orbit-diagram` and `walker stability-map`: refused
//! with exit code 2 and a message naming the option and the value, before any work.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;
use common::{stderr, walker};

fn od(extra: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = [
        "orbit-diagram",
        "--scene",
        "simplest",
        "--param",
        "slope",
        "--from",
        "0.015",
        "--to",
        "0.016",
        "--points",
        "3",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    // Later flags replace earlier ones of the same name.
    for pair in extra.chunks(2) {
        if let Some(i) = v.iter().position(|a| a == pair[0]) {
            v[i + 1] = pair[1].to_string();
        } else {
            v.extend(pair.iter().map(|s| s.to_string()));
        }
    }
    v
}

fn map(x: &str, y: &str) -> Vec<String> {
    ["stability-map", "--scene", "compass", "--x", x, "--y", y]
        .iter()
        .map(|s| s.to_string())
        .collect()
}

#[test]
fn bad_orbit_diagram_and_stability_map_options_are_named_and_exit_2() {
    let plot_file = std::env::temp_dir().join(format!("walker-maps-file-{}", std::process::id()));
    std::fs::write(&plot_file, "a file, not a folder").unwrap();
    let plot_file = plot_file.to_string_lossy().into_owned();
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        (od(&["--param", "nope"]), vec!["nope"]),
        (od(&["--points", "1"]), vec!["--points", "1"]),
        (od(&["--points", "5001"]), vec!["--points", "5001"]),
        (
            od(&["--points", "18446744073709551615"]),
            vec!["--points", "18446744073709551615"],
        ),
        (od(&["--from", "NaN"]), vec!["--from"]),
        (od(&["--to", "inf"]), vec!["--to"]),
        (od(&["--to", "0.015"]), vec!["--from and --to are equal"]),
        (
            [
                "sweep", "--scene", "simplest", "--param", "slope", "--from", "0.015", "--to",
                "0.015", "--points", "3",
            ]
            .iter()
            .map(|s| s.to_string())
            .collect(),
            vec!["--from and --to are equal"],
        ),
        (od(&["--to", "0.9"]), vec!["slope_rad", "0.9"]),
        (od(&["--chunk-points", "0"]), vec!["--chunk-points", "0"]),
        (
            od(&["--coordinate", "knee"]),
            vec!["--coordinate", "knee", "stance_leg"],
        ),
        (map("slope_rad", "leg_mass_kg=1:2:2"), vec!["--x", "="]),
        (
            map("slope=0.01:0.02", "leg_mass_kg=1:2:2"),
            vec!["--x", "three"],
        ),
        (
            map("slope=0.01:x:3", "leg_mass_kg=1:2:2"),
            vec!["--x", "TO", "x"],
        ),
        (
            map("slope=0.01:0.02:0", "leg_mass_kg=1:2:2"),
            vec!["--x N", "0"],
        ),
        (
            map("slope=0.01:0.02:501", "leg_mass_kg=1:2:2"),
            vec!["--x N", "501"],
        ),
        (
            map("slope=0.01:0.02:18446744073709551616", "leg_mass_kg=1:2:2"),
            vec!["--x", "18446744073709551616"],
        ),
        (map("slope=0.01:0.02:3", "nope=1:2:2"), vec!["nope"]),
        (
            map("slope=0.01:0.02:3", "slope_rad=0.01:0.03:2"),
            vec!["slope_rad", "--y"],
        ),
        (
            map("slope=0.01:0.01:3", "leg_mass_kg=1:2:2"),
            vec!["FROM and TO"],
        ),
        (
            map("slope=0.01:0.02:300", "leg_mass_kg=1:2:300"),
            vec!["90000"],
        ),
        (
            map("slope=0.01:0.9:3", "leg_mass_kg=1:2:2"),
            vec!["slope_rad", "0.9"],
        ),
        (
            map("slope=0.01:NaN:3", "leg_mass_kg=1:2:2"),
            vec!["--x", "NaN"],
        ),
        (
            ["gaits", "--scene", "compass", "--set", "leg_mass_kg=-1"]
                .iter()
                .map(|s| s.to_string())
                .collect(),
            vec!["leg_mass_kg"],
        ),
        (
            ["gaits", "--scene", "nosuch"]
                .iter()
                .map(|s| s.to_string())
                .collect(),
            vec!["nosuch"],
        ),
    ];
    for (args, needles) in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = walker(&args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        for n in needles {
            assert!(err.contains(n), "{args:?}: `{n}` not in {err}");
        }
        assert!(out.stdout.is_empty(), "{args:?}: nothing on stdout");
    }
    // A figure folder that cannot be created: exit 1 naming the option and the path (as for
    // `walker gait --plot`), before any work.
    let mut sm = map("slope=0.01:0.02:2", "leg_mass_kg=1:2:2");
    sm.extend(["--plot".to_string(), plot_file.clone()]);
    for args in [od(&["--plot", &plot_file]), sm] {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = walker(&args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("--plot") && err.contains(&plot_file), "{err}");
    }
    std::fs::remove_file(&plot_file).ok();
}
