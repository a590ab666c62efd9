//! Walks the 3D walker with both ankle nodes' firmware and the simulated bus in the loop, for
//! profilers: real-time factor and right-hand-side evaluations per control tick
//! (`cargo run --release -p sil --example profile_sil -- 50 [dopri5|rk4|every_tick]
//! [tolerance|step_s] [h_max_s]`; without an integrator, `walker sil`'s own,
//! `sil::SIL_INTEGRATOR`; `every_tick`: `SIL_INTEGRATOR` with every step ending at a control
//! tick, `TickStepping::EndAtEveryTick`, the scheme before steps ran across held ticks).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use sil::config::SilConfig;
use sil::FirmwareInTheLoop;
use sim::engine::control::TickStepping;
use sim::engine::integrators::IntegratorChoice;
use sim::stride::walk::WalkRequest;

fn main() {
    let mut args = std::env::args().skip(1);
    let steps: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(30);
    let kind = args.next().unwrap_or_else(|| "sil".into());
    let x: Option<f64> = args.next().and_then(|s| s.parse().ok());
    let h_max_s: f64 = args.next().and_then(|s| s.parse().ok()).unwrap_or(0.01);
    let scene = sim::scene::Scene::load("wisse3d").expect("scene");
    let setup = scene.setup().expect("build");
    let g = setup.find_gait(&Default::default()).expect("gait");
    let w = &setup.walker;
    let (q, qd) = w.unpack(&g.fixed_point);
    let integrator = match kind.as_str() {
        "rk4" => IntegratorChoice::Rk4 {
            h_s: x.unwrap_or(1e-3),
        },
        "dopri5" => IntegratorChoice::Dopri5 {
            rtol: x.unwrap_or(1e-6),
            atol: x.unwrap_or(1e-6),
            h_max_s,
        },
        _ => sil::SIL_INTEGRATOR,
    };
    let stepping = match kind.as_str() {
        "every_tick" => TickStepping::EndAtEveryTick,
        _ => TickStepping::HeldAcrossTicks,
    };
    let settings = setup
        .settings
        .with_integrator(integrator)
        .with_tick_stepping(stepping);
    let mut ctl = FirmwareInTheLoop::new(SilConfig::default()).unwrap();
    let mut evals = 0usize;
    let start = std::time::Instant::now();
    let mut count = |s: &sim::stride::walk::StepSummary| evals += s.evaluations;
    let request = WalkRequest::new(&settings, steps)
        .controlled(&mut ctl)
        .on_step(&mut count);
    let walk = sim::stride::walk::walk(w, &q, &qd, request);
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
