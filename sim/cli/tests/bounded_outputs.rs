//! `walker walk --out/--plot/--animate` in bounded memory (issue 25): the CSV is written as
//! the strides complete, and the figure and the page keep the path at their own resolution,
//! so memory follows neither the walk's length nor the integrator's step. Each run is under a
//! data-segment limit (`ulimit -d`) the old binary passed by far: it kept every integrator
//! sample (`--out` of 20 simplest-walker steps at a fixed step of 2e-5 s reached 1 GB; a
//! 2,000-step page at 1e-4 s, 20 GB).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::PathBuf;
use std::process::Command;

/// The data-segment limit of each run [KiB]. Measured on this project's 2-core VM: the old
/// binary peaked at 67 MB (`--out` case) and 140 MB (`--animate` case) of resident memory and
/// aborted ("memory allocation failed") under this limit; the new one peaks near 34 MB.
const LIMIT_KIB: u64 = 48 * 1024;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("walker-bounded-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `walker args` under the limit: its exit code and stderr.
fn limited(args: &[&str]) -> (Option<i32>, String) {
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -d {LIMIT_KIB} && exec '{}' {} > /dev/null",
            env!("CARGO_BIN_EXE_walker"),
            quoted.join(" ")
        ))
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn the_csv_of_a_fine_fixed_step_walk_streams_every_sample() {
    let dir = scratch("csv");
    let csv = dir.join("walk.csv");
    let (code, err) = limited(&[
        "walk",
        "--scene",
        "simplest",
        "--steps",
        "1",
        "--integrator",
        "rk4",
        "--step-s",
        "2e-5",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<&str> = text.lines().collect();
    assert!(rows[0].starts_with("step,time_s,"), "{}", rows[0]);
    // every integrator sample: one per 2e-5 s over a step of about 3.9 s
    let last_t: f64 = rows
        .last()
        .unwrap()
        .split(',')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    let expected = last_t / 2e-5;
    let n = (rows.len() - 1) as f64;
    assert!(
        n >= expected * 0.99 && n <= expected * 1.01 + 10.0,
        "{n} rows for {last_t} s"
    );
    // in time order, no row lost between strides
    let times: Vec<f64> = rows[1..]
        .iter()
        .map(|r| r.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert!(times.windows(2).all(|w| w[1] >= w[0]));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_page_and_a_figure_of_a_fine_fixed_step_walk_stay_in_bounds() {
    let dir = scratch("page");
    let page = dir.join("walk.html");
    let plot = dir.join("plot");
    let (code, err) = limited(&[
        "walk",
        "--scene",
        "wisse3d",
        "--steps",
        "120",
        "--integrator",
        "rk4",
        "--step-s",
        "1e-4",
        "--animate",
        page.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(
        html.len() > 100_000 && html.contains("</html>"),
        "{}",
        html.len()
    );
    assert!(plot.join("floor_path.svg").is_file());
    std::fs::remove_dir_all(&dir).unwrap();
}
