//! Soak: 10,000 steps of the `wisse3d` walker with both ankle nodes' firmware in the loop, in
//! bounded memory and without drift of the bus statistics.
//!
//! Minutes even in a release build, so ignored; run it with
//! `cargo test --release -p hil-tests --test soak -- --ignored --nocapture`.
//! Every 1,000 steps it samples the process's resident memory (VmRSS, VmHWM from
//! `/proc/self/status`; the test fails when that file cannot be read, so that the memory check
//! cannot pass vacuously) and the bus statistics, prints a table, and checks:
//!
//! * the walk completes with no node fault and no bus error;
//! * the controller's histories are bounded at [`HISTORY_CAPACITY`] entries, so that every one
//!   of them is full well before step 2,000 (the phase history at step 250, the landings at
//!   step 1,000), and the resident memory grows by less than [`RSS_GROWTH_BOUND_KB`] from step
//!   2,000 to 10,000 (the walk keeps only the last [`KEEP_STEPS`] step summaries): a leak of
//!   32 bytes per step would exceed it;
//! * the bus load of every 1,000-step window is within [`LOAD_TOLERANCE`] (relative) of the
//!   first window's, its frame rate within [`FRAME_RATE_TOLERANCE`] and its mean step period
//!   within [`PERIOD_TOLERANCE`]: each about four times the spread measured (docs/sil.md).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{matched, setup};
use sil::FirmwareInTheLoop;
use sim::engine::control::{ActuatorSegment, AnkleController, AnkleSensing, ControlError};
use sim::stride::walk::{WalkOptions, WalkRequest};

const STEPS: usize = 10_000;
const EVERY: usize = 1_000;
/// Step summaries the walk keeps (the rest are streamed to the callback).
const KEEP_STEPS: usize = 10;
/// Entries each history of the controller keeps (`SilConfig::history_capacity`).
const HISTORY_CAPACITY: usize = 1_000;
/// Largest growth of VmRSS from step 2,000 to step 10,000 [kB] (measured: 8 kB; 256 kB over
/// 8,000 steps is 32 bytes per step).
const RSS_GROWTH_BOUND_KB: u64 = 256;
/// Largest relative difference of a window's bus load from the first window's (measured:
/// 7.6e-4).
const LOAD_TOLERANCE: f64 = 3e-3;
/// Largest relative difference of a window's frame rate from the first window's (measured:
/// 3.3e-5).
const FRAME_RATE_TOLERANCE: f64 = 1.3e-4;
/// Largest relative difference of a window's mean step period from the first window's
/// (measured: 1.07e-5).
const PERIOD_TOLERANCE: f64 = 4e-5;

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

/// Forwards to the firmware in the loop and samples memory and the bus every [`EVERY`] heel
/// strikes (one per step).
struct Sampler<'a> {
    inner: &'a mut FirmwareInTheLoop,
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
        if self.strikes == self.samples.len() * EVERY {
            self.sample(t_s);
        }
    }
}

#[test]
#[ignore = "minutes in release: cargo test --release -p hil-tests --test soak -- --ignored --nocapture"]
fn ten_thousand_steps_in_bounded_memory_without_drift() {
    let s = setup();
    let mut config = matched();
    config.history_capacity = HISTORY_CAPACITY;
    let cap = config.history_capacity;
    let mut ctl = FirmwareInTheLoop::new(config).unwrap();
    let mut sampler = Sampler {
        inner: &mut ctl,
        strikes: 0,
        start: std::time::Instant::now(),
        samples: Vec::new(),
    };
    sampler.sample(0.0);
    // Per window: sum, min and max of the step durations.
    let mut windows: Vec<(f64, f64, f64)> = Vec::new();
    let mut on_step = |step: &sim::stride::walk::StepSummary| {
        let w = step.step / EVERY;
        if windows.len() <= w {
            windows.push((0.0, f64::INFINITY, 0.0));
        }
        if let Some(x) = windows.get_mut(w) {
            x.0 += step.duration_s;
            x.1 = x.1.min(step.duration_s);
            x.2 = x.2.max(step.duration_s);
        }
    };
    let request = WalkRequest::new(&s.settings, STEPS)
        .options(WalkOptions {
            record: false,
            keep_steps: Some(KEEP_STEPS),
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
                .get(b.step / EVERY - 1)
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
            sum / EVERY as f64,
            min,
            max
        );
        loads.push((load, fps, sum / EVERY as f64));
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
    assert_eq!(walk.steps_completed, STEPS);
    assert_eq!(walk.steps.len(), KEEP_STEPS);
    assert!(r.faults.is_empty(), "{:?}", r.faults);
    assert_eq!(r.bus.error_frames, 0);
    assert_eq!(samples.len(), STEPS / EVERY + 1);
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
    // Memory: no growth after step 2,000 beyond the bound.
    let at = |step: usize| samples.iter().find(|s| s.step == step).unwrap();
    assert!(at(2_000).rss_kb > 0 && at(STEPS).rss_kb > 0);
    let growth = at(STEPS).rss_kb.saturating_sub(at(2_000).rss_kb);
    let max_after = samples
        .iter()
        .filter(|s| s.step >= 2_000)
        .map(|s| s.rss_kb)
        .max()
        .unwrap();
    println!(
        "VmRSS growth from step 2,000 to {STEPS}: {growth} kB (largest sample from 2,000 on: {max_after} kB, at 2,000: {} kB)",
        at(2_000).rss_kb
    );
    assert!(
        growth < RSS_GROWTH_BOUND_KB,
        "VmRSS grew by {growth} kB from step 2,000 to {STEPS}"
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
            (load / load0 - 1.0).abs() < LOAD_TOLERANCE,
            "window {k}: load {load} vs {load0}"
        );
        assert!(
            (fps / fps0 - 1.0).abs() < FRAME_RATE_TOLERANCE,
            "window {k}: {fps} frames/s vs {fps0}"
        );
        assert!(
            (period / period0 - 1.0).abs() < PERIOD_TOLERANCE,
            "window {k}: mean step period {period} s vs {period0} s"
        );
    }
}
