//! The Rust side of the Python package's benchmark (`sim/python/bench/gait_loop.py`): the
//! work of `walker.gait(scene)` — the gait by the one gait rule, the contact stride from its
//! fixed point, the report and its JSON form — `N` times in a loop, timed. Prints one JSON
//! object: scene, loops, total and per-gait seconds, and the last gait's max |λ|.
//!
//! `cargo run --release -p sim --example gait_loop -- compass 100`
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use sim::analysis::homotopy::{GaitRule, HomotopySettings};
use sim::analysis::limit_cycle::NewtonSettings;
use sim::report::GaitReport;
use sim::scene::Scene;
use std::error::Error;
use std::time::Instant;

fn main() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "compass".to_owned());
    let loops: usize = args.next().map_or(Ok(100), |n| n.parse())?;
    let scene = Scene::load(&name)?;
    let (newton, homotopy) = (NewtonSettings::default(), HomotopySettings::default());
    let setup_for = |s: &Scene| s.setup();
    let started = Instant::now();
    let mut max_abs = f64::NAN;
    for _ in 0..loops {
        let rule = GaitRule::new(&setup_for, &newton, &homotopy);
        let result = rule.gait(&scene)?.map(|(g, _)| g);
        let setup = scene.setup()?;
        let (report, _) = GaitReport::of_setup(&setup, &scene, &result, false);
        let json = sim::report::to_json(&report)?;
        max_abs = json["max_abs_eigenvalue"].as_f64().unwrap_or(f64::NAN);
    }
    let total_s = started.elapsed().as_secs_f64();
    println!(
        "{}",
        serde_json::json!({
            "scene": name,
            "loops": loops,
            "total_s": total_s,
            "per_gait_s": total_s / loops as f64,
            "max_abs_eigenvalue": max_abs,
        })
    );
    Ok(())
}
