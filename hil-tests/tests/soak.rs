//! Soak: the `wisse3d` walker with both ankle nodes' firmware in the loop, in bounded memory
//! and without drift of the bus statistics. Two runs of the same checks ([`Soak`]):
//!
//! * [`SHORT`], 1,000 steps in windows of 100, histories of 50 entries: seconds in a release
//!   build, so it runs with every `cargo test --release` (and `scripts/test-all`);
//! * [`LONG`], 10,000 steps in windows of 1,000, histories of 1,000 entries: minutes even in a
//!   release build, so ignored; run it on its own with
//!   `cargo test --release -p hil-tests --test soak -- --ignored --nocapture` (not with
//!   `--include-ignored`: the two would share the process whose memory each measures).
//!
//! Every window it samples the process's resident memory (VmRSS, VmHWM from
//! `/proc/self/status`; the test fails when that file cannot be read, so that the memory check
//! cannot pass vacuously) and the bus statistics, prints a table, and checks:
//!
//! * the walk completes with no node fault and no bus error;
//! * the controller's histories are bounded at [`Soak::history_capacity`] entries, so that every
//!   one of them is full well before [`Soak::rss_from`] (the phase history, three entries a
//!   step, after a third of the capacity in steps, the landings after the capacity), and the
//!   resident memory grows by less than [`Soak::rss_growth_bound_kb`] from there to the end
//!   (the walk keeps only the last [`KEEP_STEPS`] step summaries): a leak of 32 bytes per step
//!   would exceed the long run's bound, of 80 bytes per step the short run's;
//! * the bus load of every window is within [`Soak::load_tolerance`] (relative) of the first
//!   window's, its frame rate within [`Soak::frame_rate_tolerance`] and its mean step period
//!   within [`Soak::period_tolerance`]: each about four times the spread measured
//!   (docs/sil.md).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{matched, setup};
use sil::FirmwareInTheLoop;
use sim::engine::control::{ActuatorSegment, AnkleController, AnkleSensing, ControlError};
use sim::stride::walk::{WalkOptions, WalkRequest};

/// Step summaries the walk keeps (the rest are streamed to the callback).
const KEEP_STEPS: usize = 10;

/// One soak: its length, its windows and its bounds.
#[derive(Clone, Copy, Debug)]
struct Soak {
    /// Steps walked.
    steps: usize,
    /// Steps per window (memory and bus sampled at each window's end).
    every: usize,
    /// Entries each history of the controller keeps (`SilConfig::history_capacity`).
    history_capacity: usize,
    /// The step from which nothing may grow (every history full well before it).
    rss_from: usize,
    /// Largest growth of VmRSS from step `rss_from` to the end [kB].
    rss_growth_bound_kb: u64,
    /// Largest relative difference of a window's bus load from the first window's.
    load_tolerance: f64,
    /// Largest relative difference of a window's frame rate from the first window's.
    frame_rate_tolerance: f64,
    /// Largest relative difference of a window's mean step period from the first window's.
    period_tolerance: f64,
}

/// 10,000 steps (measured: VmRSS growth 8 kB from step 2,000 on, against 256 kB, 32 bytes per
/// step over 8,000 steps; window spreads 7.6e-4 load, 3.3e-5 frame rate, 1.07e-5 mean step
/// period; re-run on today's gait: 12 kB, 7.5e-4, 5.2e-5, 1.34e-5).
const LONG: Soak = Soak {
    steps: 10_000,
    every: 1_000,
    history_capacity: 1_000,
    rss_from: 2_000,
    rss_growth_bound_kb: 256,
    load_tolerance: 3e-3,
    frame_rate_tolerance: 1.3e-4,
    period_tolerance: 4e-5,
};

/// 1,000 steps (about 4 s in release), the same checks at a tenth of the length: histories of
/// 50 entries (full at steps 17 and 50), memory from step 200 on (measured: no growth, in
/// 4 kB pages; 64 kB over 800 steps is 80 bytes per step), windows of 100 steps (measured
/// spreads 1.43e-3 load, 5.1e-4 frame rate, 4.7e-5 mean step period: a window of 100 steps
/// scatters more than one of 1,000).
const SHORT: Soak = Soak {
    steps: 1_000,
    every: 100,
    history_capacity: 50,
    rss_from: 200,
    rss_growth_bound_kb: 64,
    load_tolerance: 6e-3,
    frame_rate_tolerance: 2e-3,
    period_tolerance: 2e-4,
};

/// `VmRSS` and `VmHWM` of this process [kB]. Panics when `/proc/self/status` cannot be read or
/// lacks them: without them the memory bound cannot be checked.
fn memory_kb() -> (u64, u64) {
    let status = std::fs::read_to_string("/proc/self/status")
        .unwrap_or_else(|e| panic!("the soak needs /proc/self/status to measure its memory: {e}"));
    let field = |name: &str| -> u64 {
        status
            .lines()
            .find_map(|l| l.strip_prefix(name))
            .and_then(|rest| rest.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no `{name}` in /proc/self/status:\n{status}"))
    };
    (field("VmRSS:"), field("VmHWM:"))
}

#[derive(Clone, Copy, Debug)]
struct Sample {
    step: usize,
    t_s: f64,
    wall_s: f64,
    rss_kb: u64,
    hwm_kb: u64,
    busy_ns: u64,
    elapsed_ns: u64,
    frames: u64,
    error_frames: u64,
    queue_overflows: u64,
}

/// Forwards to the firmware in the loop and samples memory and the bus every `every` heel
/// strikes (one per step).
struct Sampler<'a> {
    inner: &'a mut FirmwareInTheLoop,
    every: usize,
    strikes: usize,
    start: std::time::Instant,
    samples: Vec<Sample>,
}

impl Sampler<'_> {
    fn sample(&mut self, t_s: f64) {
        let (rss_kb, hwm_kb) = memory_kb();
        let b = self.inner.bus().stats();
        self.samples.push(Sample {
            step: self.strikes,
            t_s,
            wall_s: self.start.elapsed().as_secs_f64(),
            rss_kb,
            hwm_kb,
            busy_ns: b.busy_ns,
            elapsed_ns: b.elapsed_ns,
            frames: b.frames,
            error_frames: b.error_frames,
            queue_overflows: b.queue_overflows,
        });
    }
}

impl AnkleController for Sampler<'_> {
    fn period_s(&self) -> f64 {
        self.inner.period_s()
    }

    fn tick(&mut self, sensing: &AnkleSensing) -> Result<ActuatorSegment, ControlError> {
        self.inner.tick(sensing)
    }

    fn heel_strike(&mut self, t_s: f64) {
        self.inner.heel_strike(t_s);
        self.strikes += 1;
        if self.strikes == self.samples.len() * self.every {
            self.sample(t_s);
        }
    }
}

#[test]
#[ignore = "minutes in release: cargo test --release -p hil-tests --test soak -- --ignored --nocapture"]
fn ten_thousand_steps_in_bounded_memory_without_drift() {
    soak(LONG);
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn a_thousand_steps_in_bounded_memory_without_drift() {
    soak(SHORT);
}

fn soak(plan: Soak) {
    let Soak { steps, every, .. } = plan;
    let s = setup();
    let mut config = matched();
    config.history_capacity = plan.history_capacity;
    let cap = config.history_capacity;
    let mut ctl = FirmwareInTheLoop::new(config).unwrap();
    let mut sampler = Sampler {
        inner: &mut ctl,
        every,
        strikes: 0,
        start: std::time::Instant::now(),
        samples: Vec::new(),
    };
    sampler.sample(0.0);
    // Per window: sum, min and max of the step durations.
    let mut windows: Vec<(f64, f64, f64)> = Vec::new();
    let mut on_step = |step: &sim::stride::walk::StepSummary| {
        let w = step.step / every;
        if windows.len() <= w {
            windows.push((0.0, f64::INFINITY, 0.0));
        }
        if let Some(x) = windows.get_mut(w) {
            x.0 += step.duration_s;
            x.1 = x.1.min(step.duration_s);
            x.2 = x.2.max(step.duration_s);
        }
    };
    let request = WalkRequest::new(&s.settings, steps)
        .options(WalkOptions {
            record: false,
            keep_steps: Some(KEEP_STEPS),
            path_interval_s: None,
            max_path_samples: None,
        })
        .controlled(&mut sampler)
        .on_step(&mut on_step);
    let walk = sim::stride::walk::walk(&s.walker, &s.q0, &s.qd0, request);
    let samples = std::mem::take(&mut sampler.samples);
    drop(sampler);
    let r = ctl.finish().unwrap();

    println!(
        "| steps | walking time | wall time | real-time factor | VmRSS | VmHWM | bus load (window) | frames/s (window) | step period (window mean, min–max) |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    let mut loads = Vec::new();
    for pair in samples.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let dt_ns = (b.elapsed_ns - a.elapsed_ns) as f64;
        let load = (b.busy_ns - a.busy_ns) as f64 / dt_ns;
        let fps = (b.frames - a.frames) as f64 / (dt_ns * 1e-9);
        let (sum, min, max) =
            windows
                .get(b.step / every - 1)
                .copied()
                .unwrap_or((f64::NAN, f64::NAN, f64::NAN));
        println!(
            "| {} | {:.0} s | {:.1} s | {:.0} × | {} kB | {} kB | {:.4} % | {:.3} | {:.7} s ({:.6}–{:.6}) |",
            b.step,
            b.t_s,
            b.wall_s,
            b.t_s / b.wall_s,
            b.rss_kb,
            b.hwm_kb,
            100.0 * load,
            fps,
            sum / every as f64,
            min,
            max
        );
        loads.push((load, fps, sum / every as f64));
    }
    println!(
        "end: {} steps, failure {:?}; {} ticks, {} frames delivered, bus load {:.3} % over the run, {} error frames; histories: phase {} kept / {} elided, landings {} / {}, state {}, faults {}",
        walk.steps_completed,
        walk.failure.as_ref().map(|f| (f.kind, f.step)),
        r.ticks,
        r.frames_delivered,
        100.0 * r.bus.load,
        r.bus.error_frames,
        r.phase_history.len(),
        r.history_elided.phase_history,
        r.landings.len(),
        r.history_elided.landings,
        r.state_history.len(),
        r.faults.len()
    );

    assert!(walk.failure.is_none(), "{:?}", walk.failure);
    assert_eq!(walk.steps_completed, steps);
    assert_eq!(walk.steps.len(), KEEP_STEPS);
    assert!(r.faults.is_empty(), "{:?}", r.faults);
    assert_eq!(r.bus.error_frames, 0);
    assert_eq!(samples.len(), steps / every + 1);
    assert!(samples
        .iter()
        .all(|s| s.error_frames == 0 && s.queue_overflows == 0));
    for n in r.nodes.values() {
        assert_eq!(n.state, "Enabled");
        assert_eq!(n.rx_overflows + n.port_dropped + n.frames_lost_at_bus, 0);
        assert_eq!(n.frames_refused_queue_full, 0);
    }
    // The histories stayed within their capacity, and the ones that grow per step are full.
    println!("history capacity {cap}");
    assert!(r.phase_history.len() == cap && r.history_elided.phase_history > 0);
    assert!(r.landings.len() == cap && r.history_elided.landings > 0);
    // Memory: no growth after `rss_from` beyond the bound.
    let at = |step: usize| samples.iter().find(|s| s.step == step).unwrap();
    let from = plan.rss_from;
    assert!(at(from).rss_kb > 0 && at(steps).rss_kb > 0);
    let growth = at(steps).rss_kb.saturating_sub(at(from).rss_kb);
    let max_after = samples
        .iter()
        .filter(|s| s.step >= from)
        .map(|s| s.rss_kb)
        .max()
        .unwrap();
    println!(
        "VmRSS growth from step {from} to {steps}: {growth} kB (largest sample from {from} on: {max_after} kB, at {from}: {} kB)",
        at(from).rss_kb
    );
    assert!(
        growth < plan.rss_growth_bound_kb,
        "VmRSS grew by {growth} kB from step {from} to {steps}"
    );
    // Bus statistics and gait: every window like the first.
    let (load0, fps0, period0) = loads[0];
    let spread = |f: &dyn Fn(&(f64, f64, f64)) -> f64, x0: f64| {
        loads
            .iter()
            .map(|x| (f(x) / x0 - 1.0).abs())
            .fold(0.0, f64::max)
    };
    println!(
        "largest relative difference from the first window: load {:.2e}, frame rate {:.2e}, mean step period {:.2e}",
        spread(&|x| x.0, load0),
        spread(&|x| x.1, fps0),
        spread(&|x| x.2, period0)
    );
    for (k, (load, fps, period)) in loads.iter().enumerate() {
        assert!(
            (load / load0 - 1.0).abs() < plan.load_tolerance,
            "window {k}: load {load} vs {load0}"
        );
        assert!(
            (fps / fps0 - 1.0).abs() < plan.frame_rate_tolerance,
            "window {k}: {fps} frames/s vs {fps0}"
        );
        assert!(
            (period / period0 - 1.0).abs() < plan.period_tolerance,
            "window {k}: mean step period {period} s vs {period0} s"
        );
    }
}
