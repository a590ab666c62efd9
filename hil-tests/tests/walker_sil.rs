//! The `wisse3d` walker with both ankle nodes' firmware in the loop, on the simulated CAN bus:
//! nominal walking, and what each bus or sensor fault does to the nodes and to the robot.
//!
//! Each test walks the 3D walker for up to 200 strides with a control tick every millisecond:
//! seconds in a release build, many minutes unoptimised, so they are ignored in debug builds
//! (`scripts/test-all` runs `cargo test --workspace --release`).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{matched, setup, walk, walk_with, TICK_S};
use sil::{FirmwareInTheLoop, SensorFault, Side, SilReport};

/// Time of the stride `k`'s start on the nominal gait, plus `frac` of a stride [s].
fn in_stride(k: usize, frac: f64) -> f64 {
    (k as f64 + frac) * setup().period_s
}

fn safe_at(r: &SilReport, side: Side) -> Option<f64> {
    r.first_state_at_or_after(side, "Safe", 0.0)
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn nominal_200_steps_with_the_firmware_in_the_loop() {
    let (walk, r) = walk(matched(), 200);
    assert!(walk.failure.is_none(), "{:?}", walk.failure);
    assert_eq!(walk.steps.len(), 200);
    let ideal = setup().period_s;
    // The mean period is the ideal one within 0.5 ms (measured +0.30 ms).
    let mean = walk.steps.iter().map(|s| s.duration_s).sum::<f64>() / 200.0;
    assert!(
        (mean - ideal).abs() < 5e-4,
        "mean period {mean}, ideal {ideal}"
    );
    for s in &walk.steps {
        // Engagement is detected by the firmware (quantised encoder, estimator, 1 kHz): with
        // the lightly damped pelvic roll of the Table I gait (|λ| 0.988) the period moves
        // from step to step by up to 6.3 ms (measured: 0.79544–0.80591 s, ideal 0.79963 s).
        assert!(
            (s.duration_s - ideal).abs() < 8e-3,
            "step {} lasted {} s, ideal {ideal}",
            s.step,
            s.duration_s
        );
        assert!(s.events.iter().any(|e| e.name == "string_engaged"));
    }
    assert!(r.faults.is_empty(), "{:?}", r.faults);
    assert_eq!(r.heel_strikes, 200);
    for side in Side::BOTH {
        let n = r.node(side).unwrap();
        assert_eq!(n.state, "Enabled");
        assert!(n.active_faults.is_empty());
        assert_eq!(n.engagements, 100, "{side:?}");
        assert_eq!(n.releases_by_lift_off, 0);
        assert_eq!(n.firmware_dropped_tx, 0);
        assert_eq!(n.frames_dropped + n.frames_refused_queue_full, 0);
        assert_eq!(n.actuator.saturated_ticks, 0);
    }
    // Every stance but the last ends with a release by the other foot's message (the walk
    // stops at the 200th heel strike, before that message is read).
    let by_message: u32 = Side::BOTH
        .iter()
        .map(|s| r.node(*s).unwrap().releases_by_peer_heel_strike)
        .sum();
    assert_eq!(by_message, 199);
    // Nothing written; the host read the profile's four parameters back from both nodes.
    assert_eq!(r.host.param_acks.len(), 8);
    assert!(r.host.param_acks.iter().all(|a| a.contains(" Read ")));
    for side in Side::BOTH {
        let p = r.node(side).unwrap().parameters;
        assert_eq!(p.taut_angle_rad, Some(-0.08));
        assert_eq!(p.extended_angle_rad, Some(0.2));
        assert_eq!(p.push_duration_s, Some(0.27));
        assert_eq!(p.effective_push_duration_s, Some(0.27));
    }
    // 200 Hz AnkleState and 20 Hz heartbeats per ankle, heel strikes, versions: about 10 %.
    assert!(r.bus.load > 0.08 && r.bus.load < 0.12, "{}", r.bus.load);
    assert_eq!(r.bus.error_frames, 0);
    // The host's own frames: the Enable and four GetParam.
    assert_eq!(r.frames_delivered, r.host.frames_seen + 5);
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn heel_strike_frames_dropped_the_contact_switches_release() {
    let config = matched()
        .with_fault_str("drop:id=0x022")
        .unwrap()
        .with_fault_str("drop:id=0x023")
        .unwrap();
    let (walk, r) = walk(config, 40);
    // The release of the trailing foot's string happens after the stride's heel strike,
    // when that foot is the (massless) swing foot: the robot walks as before.
    assert!(walk.failure.is_none(), "{:?}", walk.failure);
    assert_eq!(r.host.per_class.get("HeelStrike"), None, "none got through");
    let mut fallbacks = 0;
    for side in Side::BOTH {
        let n = r.node(side).unwrap();
        assert_eq!(n.state, "Enabled");
        assert_eq!(n.releases_by_peer_heel_strike, 0);
        assert_eq!(n.frames_dropped, u64::from(n.heel_strikes_sent));
        assert!(n.heel_strikes_sent >= 19);
        // Raised at the first fallback, cleared only by a normal release: once.
        assert_eq!(n.fault_raises.get("PeerHeelStrikeLate"), Some(&1));
        fallbacks += n.releases_by_lift_off;
    }
    assert_eq!(fallbacks, 39, "every heel strike's but the last");
    // The fallback comes 10 ms (trailing contact) + 3 debounced samples after the strike.
    let strike = r.landings.get(1).unwrap().t_s;
    let late = r.first_raise(Side::Left, "PeerHeelStrikeLate").unwrap();
    assert!(late - strike <= 0.013 + 1e-9, "{strike} {late}");
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn peer_heartbeat_lost_puts_the_node_in_the_safe_state_and_the_robot_falls() {
    let from_s = in_stride(10, 0.3);
    let config = matched()
        .with_fault_str(&format!("drop:id=0x063,from_ms={}", (from_s * 1e3) as u64))
        .unwrap();
    let (walk, r) = walk(config, 40);
    let lost = r.first_raise(Side::Left, "PeerHeartbeatLost").unwrap();
    let safe = safe_at(&r, Side::Left).unwrap();
    assert_eq!(lost, safe);
    // Heartbeats every 50 ms: the last one before the drop went out at most 50 ms before it;
    // lost 0.3 s after the last one received, plus delivery and one tick.
    assert!(
        safe > from_s + 0.3 - 0.05 && safe <= from_s + 0.3 + 2.0 * TICK_S,
        "{safe}"
    );
    // The right node follows once the left one's heartbeat reports Safe (PeerSafe): the
    // right node still receives the left's heartbeats (only 0x063 is dropped).
    assert_eq!(r.node(Side::Right).unwrap().state, "Safe");
    let follows = r.first_raise(Side::Right, "PeerSafe").unwrap();
    assert!(
        follows > safe && follows <= safe + 0.05 + 2.0 * TICK_S,
        "{follows}"
    );
    // Without the left ankle's push-off the walker does not keep going.
    let f = walk.failure.expect("typed failure");
    assert!(f.t_walk_s > safe, "{f:?}");
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn a_bus_off_node_goes_safe_at_once_and_its_peer_within_the_heartbeat_timeout() {
    let from_s = in_stride(10, 0.3);
    let config = matched()
        .with_fault_str(&format!(
            "busoff:node=right,from_ms={}",
            (from_s * 1e3) as u64
        ))
        .unwrap();
    let (walk, r) = walk(config, 40);
    assert_eq!(r.bus_off.len(), 1);
    let right = safe_at(&r, Side::Right).unwrap();
    // 32 error frames of the right node's own transmissions: 13 ms measured.
    assert!(right >= from_s && right < from_s + 0.016, "{right}");
    assert!(r.first_raise(Side::Right, "CanBus").is_some());
    let left = safe_at(&r, Side::Left).unwrap();
    assert!(
        left > from_s + 0.25 && left <= from_s + 0.3 + 2.0 * TICK_S,
        "{left}"
    );
    let f = walk.failure.expect("typed failure");
    assert!(f.t_walk_s > right, "{f:?}");
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn a_low_priority_babbler_fills_the_bus_but_the_robot_walks() {
    let from_s = in_stride(5, 0.0);
    let config = matched()
        .with_fault_str(&format!(
            "babble:node=right,id=0x7FF,from_ms={}",
            (from_s * 1e3) as u64
        ))
        .unwrap();
    let (walk, r) = walk(config, 30);
    assert!(walk.failure.is_none(), "{:?}", walk.failure);
    assert!(r.faults.is_empty(), "{:?}", r.faults);
    // 100 % from the fifth stride on.
    assert!(r.bus.load > 0.8, "{}", r.bus.load);
    assert!(r.host.undecodable_frames > 10_000);
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn a_high_priority_babbler_starves_the_nodes_into_the_safe_state() {
    let from_s = in_stride(5, 0.0);
    let config = matched()
        .with_fault_str(&format!(
            "babble:node=right,id=0x000,from_ms={}",
            (from_s * 1e3) as u64
        ))
        .unwrap();
    let (walk, r) = walk(config, 30);
    // Nothing else gets through: the transmit queues fill (a CanBus fault) and the peer's
    // heartbeats stop (PeerHeartbeatLost); both nodes end safe.
    for side in Side::BOTH {
        let safe = safe_at(&r, side).unwrap();
        assert!(
            safe > from_s && safe <= from_s + 0.3 + 2.0 * TICK_S,
            "{side:?} {safe}"
        );
        assert!(r.node(side).unwrap().frames_refused_queue_full > 0);
    }
    let f = walk.failure.expect("typed failure");
    assert!(f.t_walk_s > from_s);
    // Busy all the time from the babble's start.
    let share = (r.t_end_s - from_s) / r.t_end_s;
    assert!(r.bus.load > 0.9 * share, "{} vs {share}", r.bus.load);
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn an_encoder_glitch_raises_a_rate_fault_and_the_node_goes_safe() {
    let at_s = in_stride(10, 0.3);
    let config = matched().with_sensor_fault(SensorFault::Glitch {
        side: Side::Left,
        at_s,
        delta_rad: 0.1,
    });
    let (walk, r) = walk(config, 40);
    let raised = r.first_raise(Side::Left, "EncoderRate").unwrap();
    assert!(raised >= at_s && raised < at_s + TICK_S + 1e-9);
    assert_eq!(safe_at(&r, Side::Left), Some(raised));
    // The fault clears two samples later, but the node stays safe until re-enabled.
    assert_eq!(r.node(Side::Left).unwrap().state, "Safe");
    assert!(r.node(Side::Left).unwrap().active_faults.is_empty());
    let f = walk.failure.expect("typed failure");
    assert!(f.t_walk_s > raised);
}

/// Time of the string's engagement in stride `k` of the nominal walk [s].
fn engagement_in_stride(k: usize) -> f64 {
    let (walk, _) = walk(matched(), k + 1);
    let s = &walk.steps[k];
    let e = s
        .events
        .iter()
        .find(|e| e.name == "string_engaged")
        .unwrap();
    s.start_t_walk_s + e.t_stride_s
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn a_stuck_encoder_is_caught_in_the_push_and_the_node_goes_safe() {
    // Frozen 20 ms into stride 10's push (left stance, even strides): caught 50 ms after the
    // reading last changed (a tick or two before the freeze), within a tick.
    let from_s = engagement_in_stride(10) + 0.02;
    let config = matched().with_sensor_fault(SensorFault::Stuck {
        side: Side::Left,
        from_s,
    });
    let (walk, r) = walk(config, 40);
    let stuck = r.first_raise(Side::Left, "EncoderStuck").unwrap();
    assert!(
        stuck > from_s + 0.05 - 3.0 * TICK_S && stuck <= from_s + 0.05 + 2.0 * TICK_S,
        "{from_s} {stuck}"
    );
    assert_eq!(safe_at(&r, Side::Left), Some(stuck));
    // Released mid-push: the string goes slack at the fault's tick and stride 10 goes on
    // without the rest of the push; the node stays safe, and without its pushes the walker
    // falls within a few strides.
    let released = released_in(&walk, 10).expect("string released in stride 10");
    assert!(
        released >= stuck && released < stuck + TICK_S + 1e-9,
        "{stuck} {released}"
    );
    let f = walk.failure.expect("typed failure");
    assert!(f.step > 10 && f.step <= 14, "{f:?}");
    assert_eq!(r.node(Side::Left).unwrap().state, "Safe");
}

/// Walk time at which the stance string went slack during stride `k`, if it did.
fn released_in(walk: &sim::stride::walk::Walk, k: usize) -> Option<f64> {
    let s = walk.steps.iter().find(|s| s.step == k)?;
    s.events
        .iter()
        .find(|e| e.name == "string_released")
        .map(|e| s.start_t_walk_s + e.t_stride_s)
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn an_encoder_stuck_before_the_push_is_caught_in_the_stance_and_names_the_fall() {
    // Frozen at 30 % of stride 10, above the taut angle, in the left's walking stance
    // (`Free` after its heel strike): the stance must turn the ankle (the stride check), so
    // the reading that stopped is `EncoderStuck` 50 ms later (it used to go unseen: the
    // firmware never pushed, the stuck check ran only while pushing, and the walk fell with
    // the node enabled). The node goes `Safe`, and the fall is put down to that fault.
    let from_s = in_stride(10, 0.3);
    let config = matched().with_sensor_fault(SensorFault::Stuck {
        side: Side::Left,
        from_s,
    });
    let (walk, r) = walk(config, 40);
    let stuck = r.first_raise(Side::Left, "EncoderStuck").expect("caught");
    let timeout = f64::from(protocol::ParamId::StuckTimeout.default_si());
    assert!(
        // The frozen counts repeat the last reading before the freeze: up to a tick early.
        stuck >= from_s + timeout - 0.0011 && stuck <= from_s + timeout + 0.0021,
        "{stuck} vs {from_s}"
    );
    assert_eq!(
        r.first_state_at_or_after(Side::Left, "Safe", from_s),
        Some(stuck)
    );
    let f = walk.failure.expect("typed failure");
    assert!(f.t_walk_s > stuck, "{f:?}");
    let cause = r.fall_cause(f.t_walk_s).expect("a cause");
    assert_eq!(
        (cause.side, cause.code.as_str()),
        (Side::Left, "EncoderStuck")
    );
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn emergency_stop_mid_push_releases_both_strings_within_two_ticks() {
    let mut ctl = FirmwareInTheLoop::new(matched()).unwrap();
    // Stride 12 (left stance), 80 % through: in the push.
    let at_s = in_stride(12, 0.8);
    ctl.emergency_stop_at(at_s);
    let (walk, r) = walk_with(ctl, 40);
    let phase_before = r
        .phase_history
        .iter()
        .rfind(|p| p.side == Side::Left && p.t_s < at_s)
        .map(|p| p.phase.clone());
    assert!(
        matches!(phase_before.as_deref(), Some("Push" | "Hold")),
        "{phase_before:?}"
    );
    for side in Side::BOTH {
        let t = r
            .first_state_at_or_after(side, "EmergencyStop", 0.0)
            .unwrap();
        assert!(t > at_s && t <= at_s + 2.0 * TICK_S + 1e-9, "{side:?} {t}");
        assert_eq!(r.node(side).unwrap().state, "EmergencyStop");
    }
    // Both strings slack within two ticks; stride 12 goes on without the rest of its push
    // and ends in a heel strike; without pushes the walker then falls within a few strides.
    let released = released_in(&walk, 12).expect("string released in stride 12");
    assert!(
        released > at_s && released <= at_s + 2.0 * TICK_S + 1e-9,
        "{at_s} {released}"
    );
    // The foot, pivoting about its toe, puts its heel back down before the heel strike.
    let s12 = walk.steps.iter().find(|s| s.step == 12).unwrap();
    let names: Vec<&str> = s12.events.iter().map(|e| e.name.as_str()).collect();
    let (rel, down, hs) = (
        names.iter().position(|n| *n == "string_released"),
        names.iter().position(|n| *n == "heel_down"),
        names.iter().position(|n| *n == "heel_strike"),
    );
    assert!(rel < down && down < hs, "{names:?}");
    let f = walk.failure.expect("typed failure");
    assert!(f.step > 12 && f.step <= 16, "{f:?}");
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes unoptimised: cargo test --release -p hil-tests"
)]
fn the_same_faults_give_the_same_walk_and_report() {
    let config = || {
        matched()
            .with_fault_str("corrupt:prob=0.01")
            .unwrap()
            .with_fault_str("drop:id=0x072,prob=0.1")
            .unwrap()
    };
    let (a, ra) = walk(config(), 20);
    let (b, rb) = walk(config(), 20);
    assert!(ra.bus.error_frames > 10 && ra.bus.dropped > 10);
    assert_eq!(
        format!(
            "{:?}",
            a.steps.iter().map(|s| s.duration_s).collect::<Vec<_>>()
        ),
        format!(
            "{:?}",
            b.steps.iter().map(|s| s.duration_s).collect::<Vec<_>>()
        )
    );
    assert_eq!(a.failure.is_none(), b.failure.is_none());
    assert_eq!(
        serde_json::to_string(&ra).unwrap(),
        serde_json::to_string(&rb).unwrap()
    );
}
