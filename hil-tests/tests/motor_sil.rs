//! The `wisse3d` walker with the firmware in the loop driving the board's actuator as
//! physics: the firmware's own `SpoolMotor` driver (PD loop on the *measured* ankle angle,
//! spool encoder, current limit) over a DC gear motor, spool and string model
//! (`sil::SpoolPlant`, `ActuatorChoice::SpoolMotor`). What a frozen ankle encoder during
//! `Hold` does there.
//!
//! Release builds only (seconds; minutes unoptimised).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{matched, setup, TICK_S};
use sil::{
    ActuatorChoice, DrivenPhase, FirmwareInTheLoop, SensorFault, Side, SilConfig, SilReport,
    StageOutput, SupplyDropInHold,
};
use sim::engine::control::{ActuatorSegment, AnkleController, AnkleSensing, ControlError};
use sim::stride::walk::{Walk, WalkRequest};

/// One tick as the walker and the left ankle's hardware saw it.
#[derive(Clone, Copy, Debug)]
struct Seen {
    t_s: f64,
    /// The left ankle is the stance ankle.
    left_stance: bool,
    /// True stance ankle angle [rad].
    ankle_rad: f64,
    left_stage: Option<StageOutput>,
    left_spool: Option<i32>,
}

/// Records what each tick saw around the firmware in the loop.
struct Recorder {
    inner: FirmwareInTheLoop,
    left_stance: bool,
    seen: Vec<Seen>,
}

impl AnkleController for Recorder {
    fn period_s(&self) -> f64 {
        self.inner.period_s()
    }
    fn tick(&mut self, sensing: &AnkleSensing) -> Result<ActuatorSegment, ControlError> {
        let seg = self.inner.tick(sensing)?;
        self.seen.push(Seen {
            t_s: sensing.t_walk_s,
            left_stance: self.left_stance,
            ankle_rad: sensing.stance_ankle_rad,
            left_stage: self.inner.stage_output(Side::Left),
            left_spool: self.inner.spool_counts(Side::Left),
        });
        Ok(seg)
    }
    fn heel_strike(&mut self, t_walk_s: f64) {
        self.left_stance = !self.left_stance;
        self.inner.heel_strike(t_walk_s);
    }
}

fn motor_config() -> SilConfig {
    SilConfig {
        actuator_choice: ActuatorChoice::SpoolMotor,
        ..matched()
    }
    .with_sensor_fault(SensorFault::StuckInPhase {
        side: Side::Left,
        phase: DrivenPhase::Hold,
    })
}

fn walk_recorded(config: SilConfig, steps: usize) -> (Walk, SilReport, Vec<Seen>) {
    let s = setup();
    let mut rec = Recorder {
        inner: FirmwareInTheLoop::new(config).unwrap(),
        left_stance: true,
        seen: Vec::new(),
    };
    let request = WalkRequest::new(&s.settings, steps).controlled(&mut rec);
    let walk = sim::stride::walk::walk(&s.walker, &s.q0, &s.qd0, request);
    let Recorder { inner, seen, .. } = rec;
    let report = inner.finish().unwrap();
    eprintln!("{}", common::summary(&walk, &report));
    (walk, report, seen)
}

/// One count of the ankle encoder [rad].
const COUNT_RAD: f64 = 2.0 * std::f64::consts::PI / 16384.0;

/// The firmware's stuck timeout, its default (50 ms) [s].
fn stuck_timeout_s() -> f64 {
    f64::from(protocol::ParamId::StuckTimeout.default_si())
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn with_the_motor_a_still_hold_leaves_a_frozen_reading_right_and_raises_nothing() {
    // The 0.15 s push reaches Hold (the default 0.27 s push is released before it). The
    // board's PD loop has settled the ankle on the extended angle when Hold begins; with the
    // reading frozen there it keeps the duty it had, the load stays as it was, the gearbox's
    // friction holds: the ankle stays within one count of the frozen reading, the reading is
    // *right*, and no check can tell it from a healthy encoder sitting on one code.
    let config = motor_config()
        .with_firmware_param_str("push_duration_s=0.15")
        .unwrap();
    let (_walk, r, seen) = walk_recorded(config, 2);
    let frozen_at = r.sensor_faults_applied[0].t_s;
    let during: Vec<&Seen> = seen
        .iter()
        .filter(|s| s.left_stance && s.t_s >= frozen_at)
        .collect();
    assert!(during.len() >= 30, "a hold of {} ticks", during.len());
    let first = during[0].ankle_rad;
    let drift = during
        .iter()
        .map(|s| (s.ankle_rad - first).abs())
        .fold(0.0, f64::max);
    assert!(
        drift < COUNT_RAD,
        "the ankle moved {drift} rad under the frozen reading"
    );
    let spool_ticks = during
        .windows(2)
        .filter(|w| w[0].left_spool != w[1].left_spool)
        .count();
    eprintln!(
        "frozen {frozen_at:.3} s at {first:.4} rad, hold {} ticks, drift {drift:.2e} rad, spool turned in {spool_ticks} ticks",
        during.len()
    );
    assert!(spool_ticks < 10, "the spool turned in {spool_ticks} ticks");
    assert_eq!(r.first_raise(Side::Left, "EncoderStuck"), None);
    assert!(r.faults.is_empty(), "{:?}", r.faults);
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn with_the_motor_a_load_change_under_a_frozen_reading_is_caught_and_the_stage_stops_within_50_ms()
{
    // The same frozen reading, and at the same tick the stage's supply drops from 12 V to
    // 6 V (a load change: the same duty now gives half the torque). The walker's load
    // back-drives the spool and the ankle sinks, while the frozen reading says it has not
    // moved: the spool turns every tick (after its first count from rest), and the stuck
    // check, which counts hold ticks with the spool turning, raises `EncoderStuck` when that
    // evidence has lasted the stuck timeout, 50 ms (the node's host test
    // `stuck_encoder_during_hold_releases_within_50_ms`): measured 52 ms from the first tick
    // of the spool's unbroken run (0.746 → 0.798 s), 54 ms after the freeze (0.744 s; the
    // spool's first count from rest took two ticks). The node goes Safe and the stage stops
    // winding that tick: it pays out at once, and is off when the re-spool is done.
    // A push of 0.131 s (the rate bound's shortest) leaves a hold long enough for the 50 ms.
    let config = SilConfig {
        supply_drops: vec![SupplyDropInHold {
            side: Side::Left,
            supply_v: 6.0,
        }],
        ..motor_config()
    }
    .with_firmware_param_str("push_duration_s=0.131")
    .unwrap();
    let (_walk, r, seen) = walk_recorded(config, 2);
    let frozen_at = r.sensor_faults_applied[0].t_s;
    let stuck = r
        .first_raise(Side::Left, "EncoderStuck")
        .expect("EncoderStuck raised");
    // The evidence: hold ticks from the freeze in which the spool turned.
    let window: Vec<&Seen> = seen
        .iter()
        .filter(|s| s.t_s >= frozen_at - TICK_S && s.t_s < stuck)
        .collect();
    let turning = window
        .windows(2)
        .filter(|w| w[0].left_spool != w[1].left_spool)
        .count();
    let still: Vec<f64> = window
        .windows(2)
        .filter(|w| w[0].left_spool == w[1].left_spool)
        .map(|w| w[1].t_s)
        .collect();
    // The load starts the spool from rest: its first count may take more than a tick, after
    // that it turns every tick.
    assert!(
        still.iter().all(|&t| t <= frozen_at + 2.0 * TICK_S + 1e-9),
        "the spool stood still at {still:?}"
    );
    assert!(
        turning >= 50,
        "{turning} ticks with the spool turning before the fault"
    );
    // 50 ms of evidence, as the name says: from the first tick of the spool's unbroken run to
    // the fault, no less than the stuck timeout (the node does not raise on less) and no more
    // than the timeout and two ticks of the loop's sensing (the driver compares successive
    // spool readings and hands the node its finding at the next tick).
    let run_from = window
        .windows(2)
        .rev()
        .take_while(|w| w[0].left_spool != w[1].left_spool)
        .last()
        .map(|w| w[1].t_s)
        .expect("the spool turned in the last tick before the fault");
    let evidence_s = stuck - run_from;
    eprintln!(
        "frozen {frozen_at:.3} s, spool turning every tick from {run_from:.3} s, EncoderStuck {stuck:.3} s: {:.0} ms of evidence, {turning} ticks turning",
        evidence_s * 1e3
    );
    assert!(
        evidence_s >= stuck_timeout_s() - 1e-6
            && evidence_s <= stuck_timeout_s() + 2.0 * TICK_S + 1e-6,
        "EncoderStuck {evidence_s} s after the spool began turning every tick (at {run_from} s)"
    );
    // From the freeze: the two ticks the spool took to start, then the same.
    assert!(
        stuck > frozen_at && stuck <= frozen_at + stuck_timeout_s() + 4.0 * TICK_S + 1e-9,
        "frozen at {frozen_at}, raised at {stuck}"
    );
    assert_eq!(
        r.first_state_at_or_after(Side::Left, "Safe", 0.0),
        Some(stuck)
    );
    // The true ankle moved away from the frozen reading by more than a count before that.
    let first = seen.iter().find(|s| s.t_s >= frozen_at).unwrap().ankle_rad;
    let moved = seen
        .iter()
        .filter(|s| s.left_stance && s.t_s >= frozen_at && s.t_s < stuck)
        .map(|s| (s.ankle_rad - first).abs())
        .fold(0.0, f64::max);
    assert!(moved > COUNT_RAD, "{moved}");
    // The stage stops winding in the fault's tick: until then it winds (positive duty against
    // the load), from then on it pays out (negative duty, measured −0.3, the re-spool's
    // largest) and the string is never wound in past where it was (the re-spool's braking may
    // use a small positive duty, towards the rest geometry below); then it is off and stays
    // off (measured: off at 1.090 s, 0.29 s after the fault).
    let before = seen.iter().rfind(|s| s.t_s < stuck).unwrap();
    assert!(
        matches!(before.left_stage, Some(StageOutput::Duty(d)) if d > 0.0),
        "{before:?}"
    );
    let after: Vec<&Seen> = seen.iter().filter(|s| s.t_s >= stuck).collect();
    assert!(
        matches!(after[0].left_stage, Some(StageOutput::Duty(d)) if d < 0.0),
        "{:?}",
        after[0]
    );
    let at_fault = after[0].left_spool.unwrap();
    assert!(after.iter().all(|s| s.left_spool.unwrap() <= at_fault));
    let off = after
        .iter()
        .position(|s| s.left_stage == Some(StageOutput::Off))
        .expect("the stage is off once the re-spool is done");
    eprintln!("stage off (re-spool done) at {:.3} s", after[off].t_s);
    assert!(after[off].t_s - stuck < 0.35, "{:?}", after[off]);
    assert!(
        after[off..]
            .iter()
            .all(|s| s.left_stage == Some(StageOutput::Off)),
        "{:?}",
        after[off..]
            .iter()
            .find(|s| s.left_stage != Some(StageOutput::Off))
    );
}

/// The string's limit as an ankle angle for a spool count, on the plant's default gearing
/// (the power-up limit plus the count over the plant's counts per ankle radian).
fn limit_rad(counts: i32) -> f64 {
    let p = sil::SpoolPlantParams::default();
    p.initial_limit_rad + f64::from(counts) / p.counts_per_ankle_rad()
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn with_the_motor_the_nominal_walk_goes_200_steps_like_the_servo_s() {
    // The board's driver over the motor plant walks the nominal 200 steps (it fell backward
    // in step 45 while the driver re-spooled the string 3 mrad below the push's start: the
    // walker fell onto it 8 ms after the setpoint profile began, and the slow pelvic roll
    // grew step by step, docs/sil.md "The motor plant"), and its gait is the servo's within
    // a few per cent.
    const STEPS: usize = 200;
    const LAST: usize = 50;
    let s = setup();
    let motor = SilConfig {
        actuator_choice: ActuatorChoice::SpoolMotor,
        ..matched()
    };
    let (walk, r, seen) = walk_recorded(motor, STEPS);
    assert!(walk.failure.is_none(), "{:?}", walk.failure);
    assert_eq!(walk.steps.len(), STEPS);
    assert!(r.faults.is_empty(), "{:?}", r.faults);
    for (side, n) in &r.nodes {
        let p = n.spool_plant.expect("motor plant stats");
        assert_eq!((p.slack_ticks, p.overlap_ticks), (0, 0), "{side:?}");
        assert!(p.peak_current_a < 4.0, "{side:?}: {}", p.peak_current_a);
    }
    // Where the left string rests when its foot lands (its re-spool long done): at the
    // push's start geometry, within the pay-out's tolerance and the anchor's error, never
    // the former 4–5 mrad below the taut angle (−0.08 rad).
    let rests: Vec<f64> = seen
        .windows(2)
        .filter(|w| !w[0].left_stance && w[1].left_stance)
        .map(|w| limit_rad(w[1].left_spool.unwrap()))
        .collect();
    assert!(rests.len() >= 90, "{} landings", rests.len());
    let lowest = rests.iter().copied().fold(f64::INFINITY, f64::min);
    let highest = rests.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    eprintln!("left string at landing: {lowest:.5} … {highest:.5} rad");
    assert!(lowest > -0.0835 && highest < -0.0795, "{lowest} {highest}");
    // The slow pelvic roll (its stride-map value at each step's end) stays bounded; on the
    // way to the fall it passed 0.30 rad in step 24 and 0.9 rad before it.
    let roll = |w: &sim::stride::walk::Walk| {
        w.steps
            .iter()
            .filter_map(|st| st.state.iter().find(|(n, _)| n == "pelvis_roll"))
            .map(|(_, v)| *v)
            .fold(f64::NEG_INFINITY, f64::max)
    };
    // Against the servo's walk (the default actuator), the last 50 steps of each.
    let (servo_walk, _) = common::walk(matched(), STEPS);
    assert!(servo_walk.failure.is_none(), "{:?}", servo_walk.failure);
    let (m_roll, s_roll) = (roll(&walk), roll(&servo_walk));
    eprintln!("largest pelvis roll at a step's end: motor {m_roll:.4}, servo {s_roll:.4} rad");
    assert!(m_roll < s_roll + 0.03, "{m_roll} {s_roll}");
    let m = sim::report::WalkGaitRecord::of(&s.walker, &walk, LAST).unwrap();
    let v = sim::report::WalkGaitRecord::of(&s.walker, &servo_walk, LAST).unwrap();
    let rel = |a: f64, b: f64| (a - b) / b;
    let cot = |g: &sim::report::WalkGaitRecord| g.cost_of_transport.j_per_kg_m;
    eprintln!(
        "last {LAST} steps, motor / servo: period {:.5} / {:.5} s, speed {:.5} / {:.5} m/s, cost of transport {:.5} / {:.5} J/(kg m)",
        m.step_period_s, v.step_period_s, m.speed_m_s, v.speed_m_s, cot(&m), cot(&v)
    );
    assert!(rel(m.step_period_s, v.step_period_s).abs() < 0.01);
    assert!(rel(m.speed_m_s, v.speed_m_s).abs() < 0.02);
    assert!(rel(cot(&m), cot(&v)).abs() < 0.05);
}
