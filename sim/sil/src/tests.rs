//! The controller driven by synthetic sensing, without physics: the stance ankle falls at
//! 0.5 rad/s from 0.1 rad after each heel strike, and follows the string's limit once the
//! limit is above it (the string holds the ankle).

use super::*;
use sim::engine::control::{ActuatorSegment, AnkleController, AnkleSensing};

const DT_S: f64 = 1e-3;
const RAMP_START_RAD: f64 = 0.1;
const RAMP_RATE_RAD_S: f64 = -0.5;
/// The free ramp reaches the taut angle −0.08 rad at 0.36 s after the stride's start.
const TAUT_AFTER_S: f64 = 0.36;

#[derive(Clone, Debug, PartialEq)]
struct Tick {
    t_s: f64,
    stance: Side,
    angle_rad: f64,
    seg: ActuatorSegment,
}

/// Run from 0 to `until_s` with heel strikes at `strikes_s`.
fn run(sil: &mut FirmwareInTheLoop, until_s: f64, strikes_s: &[f64]) -> Vec<Tick> {
    let mut out = Vec::new();
    let mut stride_start = 0.0;
    let mut limit: Option<ActuatorSegment> = None;
    let mut strikes = strikes_s.iter().copied().peekable();
    let n = (until_s / DT_S).round() as usize;
    for k in 0..=n {
        let t_s = k as f64 * DT_S;
        if let Some(h) = strikes.next_if(|h| *h <= t_s) {
            sil.heel_strike(h);
            stride_start = h;
            limit = None;
        }
        let free = RAMP_START_RAD + RAMP_RATE_RAD_S * (t_s - stride_start);
        let angle = match limit {
            Some(s) if !s.released => free.max(s.eval(t_s).0),
            _ => free,
        };
        let sensing = AnkleSensing {
            t_walk_s: t_s,
            stance_ankle_rad: angle,
            stance_ankle_rate_rad_s: RAMP_RATE_RAD_S,
            stance_foot_on_floor: true,
            swing_foot_on_floor: false,
            string_engaged: limit.is_some_and(|s| !s.released && s.eval(t_s).0 >= free),
            string_torque_n_m: 0.0,
        };
        let seg = sil.tick(&sensing).unwrap();
        limit = Some(seg);
        out.push(Tick {
            t_s,
            stance: sil.stance_side(),
            angle_rad: angle,
            seg,
        });
    }
    out
}

fn first_phase(r: &SilReport, side: Side, phase: &str, from_s: f64) -> Option<f64> {
    r.phase_history
        .iter()
        .find(|p| p.side == side && p.phase == phase && p.t_s >= from_s)
        .map(|p| p.t_s)
}

fn sil(config: SilConfig) -> FirmwareInTheLoop {
    FirmwareInTheLoop::new(config).unwrap()
}

#[test]
fn host_enables_both_nodes_and_the_stance_node_engages_and_extends() {
    let mut c = sil(SilConfig::default());
    let ticks = run(&mut c, 0.75, &[]);
    let r = c.report();
    for side in Side::BOTH {
        assert_eq!(
            r.first_state_at_or_after(side, "Enabled", 0.0),
            Some(0.001),
            "Enable sent at 0, read at the next tick"
        );
    }
    assert_eq!(first_phase(&r, Side::Left, "Free", 0.0), Some(0.001));
    assert_eq!(first_phase(&r, Side::Right, "Swing", 0.0), Some(0.001));
    // Engagement: the estimate reaches -0.08 within a few ticks of the true angle.
    let push = first_phase(&r, Side::Left, "Push", 0.0).unwrap();
    assert!(
        (TAUT_AFTER_S..=TAUT_AFTER_S + 0.005).contains(&push),
        "{push}"
    );
    let hold = first_phase(&r, Side::Left, "Hold", 0.0).unwrap();
    assert!(
        (hold - push - 0.27).abs() <= 0.0015,
        "270 ms profile (the firmware's default): {hold}"
    );
    // Segments: released before the push, then C¹ and within the rate limit, reaching 0.2.
    let max_rate = ActuatorParams::default().max_rate_rad_per_s;
    let mut prev: Option<ActuatorSegment> = None;
    for t in &ticks {
        assert_eq!(t.stance, Side::Left);
        if t.t_s < push {
            assert!(t.seg.released, "released at {}", t.t_s);
            continue;
        }
        assert!(!t.seg.released, "held at {}", t.t_s);
        assert!(t.seg.v1_rad_s.abs() <= max_rate + 1e-9);
        assert!(t.seg.p1_rad <= 0.2 + 1e-6 && t.seg.p1_rad >= -0.1);
        if let Some(p) = prev.filter(|p| !p.released) {
            assert!((p.p1_rad - t.seg.p0_rad).abs() < 1e-12);
            assert!((p.v1_rad_s - t.seg.v0_rad_s).abs() < 1e-9);
            assert!(t.seg.p1_rad >= p.p1_rad - 1e-12, "monotone push");
        }
        prev = Some(t.seg);
    }
    let last = ticks.last().unwrap().seg;
    assert!((last.p1_rad - 0.2).abs() < 1e-3, "{}", last.p1_rad);
    let st = r.node(Side::Left).unwrap();
    assert_eq!(st.engagements, 1);
    // The contact switches were settled before the first tick: no spurious heel strike from
    // the firmware's debouncer starting open.
    assert_eq!(st.heel_strikes_sent, 0);
    assert_eq!(r.node(Side::Right).unwrap().heel_strikes_sent, 0);
    // The firmware's profile peaks at 1.875 × 0.28 / 0.27 = 1.94 rad/s: no saturation, a lag
    // of about τ × 1.94 rad/s = 10 mrad.
    assert_eq!(st.actuator.saturated_ticks, 0);
    assert!(st.actuator.max_tracking_error_rad < 0.012);
    assert!(st.actuator.max_rate_rad_per_s < 2.0);
    // The parameters in force, as both nodes reported them over the bus: the defaults.
    for side in Side::BOTH {
        let p = r.node(side).unwrap().parameters;
        assert_eq!(p.taut_angle_rad, Some(-0.08));
        assert_eq!(p.extended_angle_rad, Some(0.2));
        assert_eq!(p.push_duration_s, Some(0.27));
        assert_eq!(p.max_push_rate_rad_per_s, Some(4.0));
        assert_eq!(p.effective_push_duration_s, Some(0.27));
    }
    assert!(r.faults.is_empty(), "{:?}", r.faults);
    assert_eq!(r.nodes[&Side::Right].engagements, 0);
}

#[test]
fn written_parameters_are_in_force_and_reported_as_the_nodes_read_them_back() {
    let config = SilConfig::default()
        .with_firmware_param_str("taut_angle_rad=-0.07")
        .and_then(|c| c.with_firmware_param_str("push_duration_s=0.2"))
        .unwrap();
    let mut c = sil(config);
    // Later: a write while enabled is refused (the value stays), one after a Disable taken;
    // the host reads each back.
    let set = |v: f32| {
        protocol::Command::set_param(
            protocol::Target::Broadcast,
            protocol::ParamId::ExtendedAngle,
            v,
        )
        .unwrap()
    };
    c.host_command_at(0.4, set(0.25));
    c.host_command_at(
        0.45,
        protocol::Command {
            target: protocol::Target::Broadcast,
            kind: protocol::CommandKind::Disable,
        },
    );
    c.host_command_at(0.45, set(0.3));
    run(&mut c, 0.5, &[]);
    let r = c.report();
    // The free ramp reaches −0.07 rad 20 ms before −0.08: the written taut angle is in force.
    let push = first_phase(&r, Side::Left, "Push", 0.0).unwrap();
    let at = TAUT_AFTER_S - 0.02;
    assert!((at..=at + 0.005).contains(&push), "{push}");
    assert!(r
        .host
        .param_acks
        .iter()
        .any(|a| a.contains("ExtendedAngle NotWhileEnabled 0.2")));
    for side in Side::BOTH {
        let p = r.node(side).unwrap().parameters;
        assert_eq!(p.taut_angle_rad, Some(-0.07), "{side:?}");
        assert_eq!(p.push_duration_s, Some(0.2));
        assert_eq!(p.effective_push_duration_s, Some(0.2));
        assert_eq!(p.extended_angle_rad, Some(0.3), "taken while disabled");
    }
    // Each SetParam the host sent is followed by a GetParam of it.
    let sent = &r.host.commands_sent;
    let gets = sent
        .iter()
        .filter(|(_, c)| c.contains("GetParam { param: ExtendedAngle }"))
        .count();
    assert_eq!(gets, 3, "{sent:?}");
}

#[test]
fn the_other_foots_heel_strike_message_releases_the_string() {
    let mut c = sil(SilConfig::default());
    let ticks = run(&mut c, 1.5, &[0.7, 1.4]);
    let r = c.report();
    // The right foot lands at 0.7: its node announces it at the third debounced sample
    // (0.700, 0.701, 0.702), the left node reads the message at the next tick.
    let hs = r
        .phase_history
        .iter()
        .find(|p| p.side == Side::Right && p.phase == "Free" && p.t_s > 0.7)
        .unwrap()
        .t_s;
    assert!((hs - 0.702).abs() < 1e-9, "{hs}");
    let released = first_phase(&r, Side::Left, "Swing", 0.7).unwrap();
    assert!((released - 0.703).abs() < 1e-9, "{released}");
    let left = r.node(Side::Left).unwrap();
    assert_eq!(left.releases_by_peer_heel_strike, 1);
    assert_eq!(left.releases_by_lift_off, 0);
    assert_eq!(r.node(Side::Right).unwrap().heel_strikes_sent, 1);
    // The right node engages in its own stance and is released by the left's heel strike.
    assert_eq!(r.node(Side::Right).unwrap().engagements, 1);
    assert_eq!(r.node(Side::Right).unwrap().releases_by_peer_heel_strike, 1);
    assert!(r.faults.is_empty(), "{:?}", r.faults);
    // The stance segment after the swap is the right ankle's, released until its push.
    assert!(ticks
        .iter()
        .filter(|t| t.t_s > 0.7 && t.t_s < 0.7 + TAUT_AFTER_S)
        .all(|t| t.stance == Side::Right && t.seg.released));
    assert_eq!(r.heel_strikes, 2);
    assert_eq!(r.stance, Side::Left);
    // Determinism: a second run gives the same ticks and the same report.
    let mut c2 = sil(SilConfig::default());
    assert_eq!(run(&mut c2, 1.5, &[0.7, 1.4]), ticks);
    assert_eq!(
        serde_json::to_string(&c2.report()).unwrap(),
        serde_json::to_string(&r).unwrap()
    );
}

#[test]
fn without_the_heel_strike_frames_the_contact_switch_releases() {
    let config = SilConfig::default()
        .with_fault_str("drop:id=0x022")
        .unwrap()
        .with_fault_str("drop:id=0x023")
        .unwrap();
    let mut c = sil(config);
    run(&mut c, 1.0, &[0.7]);
    let r = c.report();
    // Trailing contact held 10 ms (to 0.709), then 3 debounced samples (0.710 to 0.712).
    let released = first_phase(&r, Side::Left, "Swing", 0.7).unwrap();
    assert!((released - 0.712).abs() < 1e-9, "{released}");
    let left = r.node(Side::Left).unwrap();
    assert_eq!(left.releases_by_lift_off, 1);
    assert_eq!(left.releases_by_peer_heel_strike, 0);
    assert_eq!(
        r.first_raise(Side::Left, "PeerHeelStrikeLate"),
        Some(released)
    );
    assert_eq!(left.state, "Enabled", "not safety-relevant");
    assert_eq!(r.node(Side::Right).unwrap().frames_dropped, 1);
    assert_eq!(r.bus.dropped, 1);
}

#[test]
fn an_instant_lift_off_beats_the_message_by_one_tick() {
    let config = SilConfig {
        trailing_contact_s: 0.0,
        ..SilConfig::default()
    };
    let mut c = sil(config);
    run(&mut c, 1.0, &[0.7]);
    let r = c.report();
    let released = first_phase(&r, Side::Left, "Swing", 0.7).unwrap();
    assert!((released - 0.702).abs() < 1e-9, "{released}");
    assert_eq!(r.node(Side::Left).unwrap().releases_by_lift_off, 1);
    assert!(r.first_raise(Side::Left, "PeerHeelStrikeLate").is_some());
}

#[test]
fn emergency_stop_releases_both_strings_within_two_ticks() {
    let mut c = sil(SilConfig::default());
    c.emergency_stop_at(0.45);
    let ticks = run(&mut c, 0.8, &[]);
    let r = c.report();
    for side in Side::BOTH {
        let t = r
            .first_state_at_or_after(side, "EmergencyStop", 0.0)
            .unwrap();
        assert!(t > 0.45 && t <= 0.45 + 2.0 * DT_S + 1e-9, "{side:?} {t}");
        assert_eq!(r.node(side).unwrap().state, "EmergencyStop");
        assert_eq!(r.node(side).unwrap().phase, "Inactive");
    }
    assert!(ticks
        .iter()
        .filter(|t| t.t_s > 0.45 + 2.0 * DT_S)
        .all(|t| t.seg.released));
    assert!(ticks
        .iter()
        .any(|t| t.t_s > 0.36 && t.t_s < 0.45 && !t.seg.released));
    assert_eq!(
        r.host.commands_sent.len(),
        6,
        "Enable, four GetParam and the stop"
    );
}

/// The left node must reach `Safe` with `PeerHeartbeatLost` no later than 0.3 s + one tick
/// after the last heartbeat of the right node it received.
fn check_heartbeat_bound(r: &SilReport, last_heartbeat_sent_s: f64) {
    let lost = r.first_raise(Side::Left, "PeerHeartbeatLost").unwrap();
    let safe = r.first_state_at_or_after(Side::Left, "Safe", 0.0).unwrap();
    assert_eq!(lost, safe);
    // Received at the tick after it was sent.
    let bound = last_heartbeat_sent_s + DT_S + 0.3 + DT_S;
    assert!(
        safe > last_heartbeat_sent_s + 0.3 && safe <= bound + 1e-9,
        "{safe} vs {bound}"
    );
}

#[test]
fn a_bus_off_peer_puts_both_nodes_in_the_safe_state() {
    let config = SilConfig::default()
        .with_fault_str("busoff:node=right,from_ms=200")
        .unwrap();
    let mut c = sil(config);
    let ticks = run(&mut c, 0.8, &[]);
    let r = c.report();
    assert_eq!(r.bus_off.len(), 1);
    assert_eq!(r.bus_off[0].1, "right");
    // The right node's controller is bus-off: CanBus fault, safe at once.
    let right_safe = r.first_state_at_or_after(Side::Right, "Safe", 0.0).unwrap();
    assert!(right_safe > 0.2 && right_safe < 0.2 + 0.012, "{right_safe}");
    assert!(r.first_raise(Side::Right, "CanBus").is_some());
    // Its last heartbeat to get through was the one at 0.15 s (the one at 0.2 s is lost in the
    // errors).
    check_heartbeat_bound(&r, 0.15);
    assert!(ticks
        .iter()
        .filter(|t| t.t_s > 0.452)
        .all(|t| t.seg.released));
}

#[test]
fn dropped_peer_heartbeats_put_the_node_in_the_safe_state() {
    let config = SilConfig::default()
        .with_fault_str("drop:id=0x063,from_ms=200")
        .unwrap();
    let mut c = sil(config);
    let ticks = run(&mut c, 0.8, &[]);
    let r = c.report();
    check_heartbeat_bound(&r, 0.15);
    // The right node follows into its safe state when the left one's heartbeat reports Safe
    // (PeerSafe): one ankle cannot walk alone.
    assert_eq!(r.node(Side::Right).unwrap().state, "Safe");
    assert!(r.first_raise(Side::Right, "PeerSafe").is_some());
    let safe = r.first_state_at_or_after(Side::Left, "Safe", 0.0).unwrap();
    // 0.451 s: the left node was pushing; the string is released at once.
    assert!(ticks.iter().any(|t| t.t_s < safe && !t.seg.released));
    assert!(ticks
        .iter()
        .filter(|t| t.t_s >= safe)
        .all(|t| t.seg.released));
}

#[test]
fn an_encoder_glitch_raises_a_rate_fault() {
    let config = SilConfig::default().with_sensor_fault(SensorFault::Glitch {
        side: Side::Left,
        at_s: 0.1,
        delta_rad: 0.1,
    });
    let mut c = sil(config);
    let ticks = run(&mut c, 0.8, &[]);
    let r = c.report();
    assert_eq!(r.first_raise(Side::Left, "EncoderRate"), Some(0.1));
    assert_eq!(
        r.first_state_at_or_after(Side::Left, "Safe", 0.0),
        Some(0.1)
    );
    // Cleared two samples later; the clear event waits for the fault's inhibit time (50 ms,
    // as CANopen's EMCY); the node stays safe until the host enables it again.
    assert!(r
        .faults
        .iter()
        .any(|f| f.code == "EncoderRate" && !f.raised && f.t_s <= 0.151));
    assert_eq!(r.node(Side::Left).unwrap().state, "Safe");
    assert!(ticks.iter().all(|t| t.seg.released));
    // The right node follows (PeerSafe) once the left one's heartbeat says Safe.
    assert_eq!(r.node(Side::Right).unwrap().state, "Safe");
    assert!(r.first_raise(Side::Right, "PeerSafe").is_some());
}

#[test]
fn a_stuck_encoder_is_caught_while_pushing() {
    let config = SilConfig::default().with_sensor_fault(SensorFault::Stuck {
        side: Side::Left,
        from_s: 0.37,
    });
    let mut c = sil(config);
    let ticks = run(&mut c, 0.8, &[]);
    let r = c.report();
    let push = first_phase(&r, Side::Left, "Push", 0.0).unwrap();
    let stuck = r.first_raise(Side::Left, "EncoderStuck").unwrap();
    // Frozen at the reading of 0.369 s: 50 ms from its last change, plus one tick.
    assert!(
        stuck > push + 0.05 && stuck <= 0.37 + 0.051 + 1e-9,
        "50 ms stuck timeout: push {push}, stuck {stuck}"
    );
    assert_eq!(
        r.first_state_at_or_after(Side::Left, "Safe", 0.0),
        Some(stuck)
    );
    assert!(ticks
        .iter()
        .filter(|t| t.t_s >= stuck)
        .all(|t| t.seg.released));
}

#[test]
fn bad_configurations_and_times_are_refused() {
    let bad = SilConfig {
        period_s: 1.5e-7,
        ..SilConfig::default()
    };
    assert!(matches!(
        FirmwareInTheLoop::new(bad),
        Err(SilError::Period { .. })
    ));
    let unknown = SilConfig::default()
        .with_fault_str("busoff:node=middle")
        .unwrap();
    let e = FirmwareInTheLoop::new(unknown).err().unwrap();
    assert!(e.to_string().contains("middle"), "{e}");
    let mut c = sil(SilConfig::default());
    run(&mut c, 0.01, &[]);
    let s = AnkleSensing {
        t_walk_s: 0.005,
        stance_ankle_rad: 0.0,
        stance_ankle_rate_rad_s: 0.0,
        stance_foot_on_floor: true,
        swing_foot_on_floor: false,
        string_engaged: false,
        string_torque_n_m: 0.0,
    };
    assert!(c.tick(&s).is_err());
    assert!(c
        .tick(&AnkleSensing {
            t_walk_s: f64::NAN,
            ..s
        })
        .is_err());
}

#[test]
fn candump_log_and_socketcand_server_see_the_traffic() {
    let dir = std::env::temp_dir().join(format!("sil-candump-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("run.log");
    let config = SilConfig {
        candump: Some(path.clone()),
        socketcand: Some("127.0.0.1:0".into()),
        ..SilConfig::default()
    };
    let mut c = sil(config);
    assert!(c.socketcand_addr().is_some_and(|a| a.ip().is_loopback()));
    run(&mut c, 0.2, &[]);
    let r = c.finish().unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let (records, bad) = canbus::candump::read_log(text.as_bytes()).unwrap();
    assert!(bad.is_empty());
    assert_eq!(records.len() as u64, r.frames_delivered);
    assert!(r.socketcand.is_some());
    std::fs::remove_dir_all(&dir).unwrap();
    // 200 Hz AnkleState ×2, 20 Hz heartbeats ×2, the Enable, four GetParam and their eight
    // answers, and two versions in 0.2 s.
    assert!(
        r.frames_delivered > 92 && r.frames_delivered < 112,
        "{}",
        r.frames_delivered
    );
    let refused = SilConfig {
        socketcand: Some("0.0.0.0:0".into()),
        ..SilConfig::default()
    };
    assert!(matches!(
        FirmwareInTheLoop::new(refused),
        Err(SilError::Socketcand(_))
    ));
}

#[test]
fn a_fixed_swing_ankle_angle_trips_the_rate_check_at_heel_strike() {
    // A fixed neutral reading (the sensor model's default): the stance ankle holds 0.2 rad when the other foot
    // lands; its reading then steps to 0 (200 rad/s) and the new stance ankle's from 0 to
    // 0.1 rad (100 rad/s), both above the firmware's 40 rad/s plausibility limit.
    let config = SilConfig {
        swing_ankle: SwingAnkleModel::Fixed { angle_rad: 0.0 },
        ..SilConfig::default()
    };
    let mut c = sil(config);
    run(&mut c, 0.8, &[0.7]);
    let r = c.report();
    for side in Side::BOTH {
        let t = r.first_raise(side, "EncoderRate").unwrap();
        assert!((t - 0.7).abs() < 1e-9, "{side:?} {t}");
        assert_eq!(r.node(side).unwrap().state, "Safe");
    }
}

#[test]
fn a_socketcand_client_sees_the_frames_and_its_emergency_stop_reaches_the_nodes() {
    use std::io::{Read, Write};
    use std::net::TcpStream;
    use std::time::{Duration, Instant as WallClock};

    fn read_until(c: &mut TcpStream, pat: &str, buf: &mut String) -> bool {
        let deadline = WallClock::now() + Duration::from_secs(5);
        let mut chunk = [0u8; 4096];
        while !buf.contains(pat) {
            if WallClock::now() > deadline {
                return false;
            }
            if let Ok(n) = c.read(&mut chunk) {
                buf.push_str(&String::from_utf8_lossy(&chunk[..n]));
            }
        }
        true
    }

    let config = SilConfig {
        socketcand: Some("127.0.0.1:0".into()),
        socketcand_allow_send: true,
        ..SilConfig::default()
    };
    let mut c = sil(config);
    let mut client = TcpStream::connect(c.socketcand_addr().unwrap()).unwrap();
    client
        .set_read_timeout(Some(Duration::from_millis(20)))
        .unwrap();
    let mut buf = String::new();
    assert!(read_until(&mut client, "< hi >", &mut buf));
    client.write_all(b"< open vcan0 >< rawmode >").unwrap();
    assert!(read_until(&mut client, "< ok >< ok >", &mut buf));
    // Tick the controller (simulated time, paced by nothing) until the client has seen a
    // frame, then send the emergency stop (0x01F, opcode 3) and tick until it arrives.
    let mut t_ms = 0u64;
    let tick = |c: &mut FirmwareInTheLoop, t_ms: &mut u64| {
        let s = AnkleSensing {
            t_walk_s: *t_ms as f64 * DT_S,
            stance_ankle_rad: 0.05,
            stance_ankle_rate_rad_s: 0.0,
            stance_foot_on_floor: true,
            swing_foot_on_floor: false,
            string_engaged: false,
            string_torque_n_m: 0.0,
        };
        c.tick(&s).unwrap();
        *t_ms += 1;
    };
    let deadline = WallClock::now() + Duration::from_secs(10);
    while !buf.contains("< frame 072") && WallClock::now() < deadline {
        tick(&mut c, &mut t_ms);
        std::thread::sleep(Duration::from_millis(1));
        let mut chunk = [0u8; 4096];
        if let Ok(n) = client.read(&mut chunk) {
            buf.push_str(&String::from_utf8_lossy(&chunk[..n]));
        }
    }
    assert!(buf.contains("< frame 072"), "left AnkleState: {buf}");
    client.write_all(b"< send 01F 1 03 >").unwrap();
    while c.node(Side::Right).state() != protocol::NodeState::EmergencyStop
        && WallClock::now() < deadline
    {
        tick(&mut c, &mut t_ms);
        std::thread::sleep(Duration::from_millis(1));
    }
    let r = c.finish().unwrap();
    for side in Side::BOTH {
        assert_eq!(r.node(side).unwrap().state, "EmergencyStop", "{side:?}");
    }
    assert_eq!(r.host.frames_from_clients, 1);
    let s = r.socketcand.unwrap();
    assert_eq!((s.clients_accepted, s.frames_received), (1, 1));
    assert!(s.frames_sent > 0);
}

#[test]
fn spi_failures_and_parity_errors_raise_the_encoder_comms_fault() {
    let config = SilConfig::default().with_sensor_fault(SensorFault::SpiFailure {
        side: Side::Left,
        from_s: 0.1,
        until_s: 0.103,
    });
    let mut c = sil(config);
    run(&mut c, 0.2, &[]);
    let r = c.report();
    assert_eq!(r.first_raise(Side::Left, "EncoderComms"), Some(0.1));
    assert_eq!(
        r.first_state_at_or_after(Side::Left, "Safe", 0.0),
        Some(0.1)
    );
    let comms = r.faults.iter().find(|f| f.code == "EncoderComms").unwrap();
    assert_eq!(comms.detail, 1, "bus error");
    // The right node follows (PeerSafe) once the left one's heartbeat says Safe.
    assert_eq!(r.node(Side::Right).unwrap().state, "Safe");
    assert!(r.first_raise(Side::Right, "PeerSafe").unwrap() >= 0.1);
    let config = SilConfig::default().with_sensor_fault(SensorFault::Parity {
        side: Side::Right,
        at_s: 0.05,
    });
    let mut c = sil(config);
    run(&mut c, 0.2, &[]);
    let r = c.report();
    let comms = r.faults.iter().find(|f| f.code == "EncoderComms").unwrap();
    assert_eq!(
        (comms.side, comms.t_s, comms.detail),
        (Side::Right, 0.05, 2)
    );
    assert_eq!(
        r.node(Side::Left).unwrap().state,
        "Safe",
        "follows its peer"
    );
    assert!(r.first_raise(Side::Left, "PeerSafe").is_some());
}

#[test]
fn babble_frames_reach_the_firmware_as_malformed_frames() {
    let config = SilConfig::default()
        .with_fault_str("babble:node=host,id=0x7FF,from_ms=100")
        .unwrap();
    let mut c = sil(config);
    run(&mut c, 0.3, &[]);
    let r = c.report();
    for side in Side::BOTH {
        let n = r.node(side).unwrap();
        // About 4 babble frames per millisecond for 0.2 s; the port reads up to 16 frames a
        // tick, so none is lost and the FIFO never holds more than a tick's worth.
        assert!(n.frames_malformed > 700, "{side:?} {}", n.frames_malformed);
        assert_eq!(n.rx_overflows, 0);
        assert!(n.max_rx_backlog < 8, "{}", n.max_rx_backlog);
        assert_eq!(n.state, "Enabled");
    }
}

#[test]
fn histories_are_bounded_and_count_what_they_leave_out() {
    let config = SilConfig {
        history_capacity: 6,
        ..SilConfig::default()
    };
    let mut c = sil(config);
    run(&mut c, 3.0, &[0.7, 1.4, 2.1, 2.8]);
    let bounded = c.report();
    let mut full = sil(SilConfig::default());
    run(&mut full, 3.0, &[0.7, 1.4, 2.1, 2.8]);
    let full = full.report();
    assert_eq!(full.history_elided.total(), 0);
    let n = full.phase_history.len();
    assert!(n > 6, "{n}");
    assert_eq!(bounded.phase_history.len(), 6);
    assert_eq!(bounded.history_elided.phase_history, (n - 6) as u64);
    // The first three and the last three.
    assert_eq!(bounded.phase_history[..3], full.phase_history[..3]);
    assert_eq!(bounded.phase_history[3..], full.phase_history[n - 3..]);
    assert_eq!(bounded.landings.len(), full.landings.len().min(6));
    assert_eq!(
        bounded.history_elided.landings,
        full.landings.len().saturating_sub(6) as u64
    );
}

/// With the servo model (`ActuatorChoice::Servo`, synthetic sensing): the servo tracks the
/// *setpoint*, not the measured angle, so a frozen reading changes nothing it does — this
/// test cannot show whether the board would notice. Once settled in Hold its spool stands
/// still, and the stuck check (which counts only hold ticks where the spool turns) raises
/// nothing. What the board's own driver does with a frozen reading, over a motor, spool and
/// string, is in `hil-tests/tests/motor_sil.rs`: in a still hold the frozen reading stays
/// right (the ankle within one count of it) and nothing is raised either; a load change
/// under it turns the spool and raises `EncoderStuck`.
#[test]
fn with_the_servo_model_a_stuck_encoder_during_a_still_hold_raises_no_fault() {
    let config = SilConfig::default().with_sensor_fault(SensorFault::StuckInPhase {
        side: Side::Left,
        phase: crate::DrivenPhase::Hold,
    });
    let mut c = sil(config);
    let ticks = run(&mut c, 0.9, &[]);
    let r = c.report();
    let hold = first_phase(&r, Side::Left, "Hold", 0.0).expect("the left node reaches Hold");
    let applied = &r.sensor_faults_applied;
    assert_eq!(applied.len(), 1, "{applied:?}");
    assert_eq!((applied[0].side, applied[0].kind), (Side::Left, "stuck"));
    // Frozen at the first read of a tick that starts in Hold: the tick after the one that
    // entered it.
    let frozen_at = applied[0].t_s;
    assert!(
        frozen_at > hold && frozen_at <= hold + 0.001 + 1e-9,
        "{hold} {frozen_at}"
    );
    // Held on: the run goes on past 4 × the stuck timeout with the string held.
    assert!(
        ticks.last().is_some_and(|t| t.t_s > frozen_at + 0.2),
        "{frozen_at}"
    );
    assert_eq!(r.first_raise(Side::Left, "EncoderStuck"), None);
    assert_eq!(r.node(Side::Left).unwrap().state, "Enabled");
    assert!(ticks
        .iter()
        .filter(|t| t.t_s > frozen_at && t.t_s < frozen_at + 0.2)
        .all(|t| !t.seg.released));
}

#[test]
fn no_heel_strike_is_announced_for_the_foot_down_at_power_up() {
    let mut c = sil(SilConfig::default());
    // Long enough for the stance node to push, not long enough for the swing foot to land.
    run(&mut c, 0.3, &[]);
    let r = c.report();
    for side in Side::BOTH {
        assert_eq!(r.node(side).unwrap().state, "Enabled", "{side:?}");
    }
    assert!(
        r.faults.is_empty(),
        "a healthy start raises no fault: {:?}",
        r.faults
    );
    assert_eq!(
        r.host.per_class.get("HeelStrike"),
        None,
        "no HeelStrike frame before any foot landed: {:?}",
        r.host.per_class
    );
    assert!(r.host.per_class.get("Heartbeat").is_some_and(|n| *n > 0));
}

#[test]
fn one_corrupted_frame_is_one_error_per_controller_and_no_safe_state() {
    let config = SilConfig::default()
        .with_fault_str("corrupt:count=1")
        .unwrap();
    let mut c = sil(config);
    run(&mut c, 0.3, &[]);
    let r = c.report();
    for side in Side::BOTH {
        let n = r.node(side).unwrap();
        // Each controller saw the error frame and its driver reported it once through the
        // receive path; the port counted it; no fault.
        assert_eq!(n.port_bus_errors, 1, "{side:?}");
        assert_eq!(n.state, "Enabled", "{side:?}");
    }
    assert!(r.faults.is_empty(), "{:?}", r.faults);
    assert!(r.bus_off.is_empty());
}
