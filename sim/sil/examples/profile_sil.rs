//! Walks the 3D walker with both ankle nodes' firmware and the simulated bus in the loop, for
//! profilers: real-time factor and right-hand-side evaluations per control tick
//! (`cargo run --release -p sim --example profile_sil -- 50 [dopri5|rk4] [tolerance|step_s]`;
//! without an integrator, `walker sil`'s own, `sil::SIL_INTEGRATOR`).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use sil::config::SilConfig;
use sil::FirmwareInTheLoop;
use sim::integrators::IntegratorChoice;
use sim::walk::WalkOptions;

fn main() {
    let mut args = std::env::args().skip(1);
    let steps: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(30);
    let kind = args.next().unwrap_or_else(|| "sil".into());
    let x: Option<f64> = args.next().and_then(|s| s.parse().ok());
    let scene = sim::scene::Scene::load("wisse3d").expect("scene");
    let mut w = scene.build().expect("build");
    let g = w
        .find_gait(&w.pack(&w.guess_q, &w.guess_qd), &Default::default())
        .expect("gait");
    let (q, qd) = w.unpack(&g.fixed_point);
    w.integrator = match kind.as_str() {
        "rk4" => IntegratorChoice::Rk4 {
            h_s: x.unwrap_or(1e-3),
        },
        "dopri5" => IntegratorChoice::Dopri5 {
            rtol: x.unwrap_or(1e-6),
            atol: x.unwrap_or(1e-6),
            h_max_s: 0.01,
        },
        _ => sil::SIL_INTEGRATOR,
    };
    let reflex = w.ankle.clone().unwrap();
    let mut ctl =
        FirmwareInTheLoop::new(SilConfig::default().with_reflex(&reflex).unwrap()).unwrap();
    let mut evals = 0usize;
    let start = std::time::Instant::now();
    let walk = w.walk_streaming(
        &q,
        &qd,
        steps,
        WalkOptions::default(),
        Some(&mut ctl),
        &mut |s| evals += s.evaluations,
    );
    let wall = start.elapsed().as_secs_f64();
    let report = ctl.finish().unwrap();
    let walked: f64 = walk.steps.iter().map(|s| s.duration_s).sum();
    println!(
        "{} steps ({:?}), {walked:.2} s walked in {wall:.3} s: {:.1} x real time; {} ticks, {:.2} evaluations per tick, {:.2} µs per tick",
        walk.steps_completed,
        walk.failure.map(|f| f.kind),
        walked / wall,
        report.ticks,
        evals as f64 / report.ticks as f64,
        wall * 1e6 / report.ticks as f64
    );
}
