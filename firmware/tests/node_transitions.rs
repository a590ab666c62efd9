//! Every node-state transition, every fault (raised and cleared) and the reflex through the
//! node, driven tick by tick.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use firmware::node::{AnkleNode, DriverHealth, NodeConfig, TickInputs, TickOutputs};
use firmware::scenarios::CALIBRATION;
use firmware::sensors::{with_simulated_noise, AngleSample, EncoderError};
use firmware::{ActuatorCommand, Instant};
use protocol::*;

const ME: NodeId = NodeId::LeftAnkle;
const PEER: NodeId = NodeId::RightAnkle;

struct Bench {
    node: AnkleNode,
    ms: u64,
    angle: f32,
    contact: bool,
    encoder_error: Option<EncoderError>,
    frozen: Option<u16>,
    drivers: DriverHealth,
    heartbeats: bool,
    peer_state: NodeState,
    reversed_motor: bool,
}

fn cmd(kind: CommandKind) -> Message {
    Message::Command(Command {
        target: Target::Node(ME),
        kind,
    })
}

impl Bench {
    fn new() -> Self {
        Bench {
            node: AnkleNode::new(NodeConfig::nominal(ME)).unwrap(),
            ms: 0,
            angle: 0.1,
            contact: false,
            encoder_error: None,
            frozen: None,
            drivers: DriverHealth::default(),
            heartbeats: true,
            peer_state: NodeState::Enabled,
            reversed_motor: false,
        }
    }

    fn tick_with(&mut self, extra: &[Message]) -> TickOutputs {
        let mut rx: Vec<Message> = extra.to_vec();
        if self.heartbeats && self.ms.is_multiple_of(50) {
            rx.push(Message::Heartbeat(Heartbeat {
                node: PEER,
                state: self.peer_state,
                faults: FaultFlags::NONE,
                uptime_ms: self.ms as u32,
            }));
        }
        let angle = match self.encoder_error {
            Some(e) => Err(e),
            None => {
                let counts = self.frozen.unwrap_or_else(|| {
                    with_simulated_noise(CALIBRATION.counts(self.angle), self.ms as u32)
                });
                Ok(AngleSample {
                    counts,
                    angle_rad: CALIBRATION.angle_rad(counts),
                })
            }
        };
        let out = self.node.tick(
            Instant::from_millis(self.ms),
            &TickInputs {
                angle,
                contact_closed: self.contact,
                received: &rx,
                drivers: self.drivers,
            },
        );
        self.ms += 1;
        // The plant: a taut string holds the ankle at or above the setpoint; a reversed
        // motor pays the string out instead (the ankle sinks at 2 rad/s).
        if let ActuatorCommand::Position { ankle_angle_rad } = out.actuator {
            if self.reversed_motor {
                self.angle -= 0.002;
            } else if ankle_angle_rad > self.angle {
                self.angle = ankle_angle_rad;
            }
        }
        out
    }

    fn tick(&mut self) -> TickOutputs {
        self.tick_with(&[])
    }

    fn run(&mut self, n: u32) -> Vec<Message> {
        (0..n)
            .flat_map(|_| self.tick().transmit.into_iter())
            .collect()
    }

    fn enabled() -> Self {
        let mut b = Bench::new();
        b.tick();
        let o = b.tick_with(&[cmd(CommandKind::Enable)]);
        assert_eq!(o.state, NodeState::Enabled);
        assert_eq!(o.phase, ReflexPhase::Swing);
        b
    }

    /// Move the ankle at 10 rad/s (below the rate limit) to `target`.
    fn move_to(&mut self, target: f32) {
        // Bounded: the plant may hold the angle above the target once the string pulls.
        for _ in 0..1000 {
            if (self.angle - target).abs() <= 1e-6 {
                break;
            }
            self.angle += (target - self.angle).clamp(-0.01, 0.01);
            self.tick();
        }
    }

    /// Heel strike and ride the angle down to the taut angle: ends in Push.
    fn drive_to_push(&mut self) {
        self.contact = true;
        for _ in 0..3 {
            self.tick();
        }
        assert_eq!(self.node.phase(), ReflexPhase::Free);
        while self.node.phase() == ReflexPhase::Free {
            self.angle -= 0.001;
            self.tick();
            assert!(self.angle > -0.2);
        }
        assert_eq!(self.node.phase(), ReflexPhase::Push);
    }
}

fn fault_events(msgs: &[Message], code: FaultCode) -> Vec<FaultTransition> {
    msgs.iter()
        .filter_map(|m| match m {
            Message::Fault(f) if f.code == code => Some(f.transition),
            _ => None,
        })
        .collect()
}

#[test]
fn not_an_ankle_is_refused() {
    assert!(AnkleNode::new(NodeConfig::nominal(NodeId::Host)).is_err());
    let mut c = NodeConfig::nominal(ME);
    c.state_period_us = 0;
    assert!(AnkleNode::new(c).is_err());
}

#[test]
fn starts_disabled_and_sends_version_heartbeat_and_state() {
    let mut b = Bench::new();
    let o = b.tick();
    assert_eq!(o.state, NodeState::Disabled);
    assert_eq!(o.phase, ReflexPhase::Inactive);
    assert_eq!(o.actuator, ActuatorCommand::Released);
    let classes: Vec<_> = o.transmit.iter().map(|m| m.class()).collect();
    assert_eq!(
        classes,
        [
            MessageClass::Heartbeat,
            MessageClass::AnkleState,
            MessageClass::Version,
            MessageClass::Identity,
            MessageClass::BootInfo,
            MessageClass::ClockInfo
        ]
    );
    // Over one second: 200 states, 20 heartbeats, one version.
    let msgs = b.run(1000);
    let count = |c| msgs.iter().filter(|m| m.class() == c).count();
    assert_eq!(count(MessageClass::AnkleState), 200);
    assert_eq!(count(MessageClass::Heartbeat), 20);
    assert_eq!(count(MessageClass::Version), 0);
    assert_eq!(b.node.dropped_tx(), 0);
}

#[test]
fn enable_disable_and_addressing() {
    let mut b = Bench::new();
    b.tick();
    // To the other ankle: ignored; broadcast: taken.
    let other = Message::Command(Command {
        target: Target::Node(PEER),
        kind: CommandKind::Enable,
    });
    assert_eq!(b.tick_with(&[other]).state, NodeState::Disabled);
    let all = Message::Command(Command {
        target: Target::Broadcast,
        kind: CommandKind::Enable,
    });
    assert_eq!(b.tick_with(&[all]).state, NodeState::Enabled);
    assert_eq!(
        b.tick_with(&[cmd(CommandKind::Disable)]).state,
        NodeState::Disabled
    );
    // Enable with the foot on the floor starts in Free.
    b.contact = true;
    let o = b.tick_with(&[cmd(CommandKind::Enable)]);
    assert_eq!((o.state, o.phase), (NodeState::Enabled, ReflexPhase::Free));
}

#[test]
fn full_reflex_cycle_through_the_node() {
    let mut b = Bench::enabled();
    b.contact = true;
    let o = b.tick();
    let hs: Vec<_> = o
        .transmit
        .iter()
        .filter(|m| matches!(m, Message::HeelStrike(h) if h.node == ME && h.step_count == 1))
        .collect();
    assert_eq!(hs.len(), 1, "own heel strike announced");
    // Debounce is the driver's job: the node reacts on the first closed tick.
    assert_eq!(o.phase, ReflexPhase::Free);
    assert_eq!(o.actuator, ActuatorCommand::Released);
    b.drive_to_push();
    let mut last = -1.0;
    // The default profile lasts 0.27 s: 300 ticks of 1 ms reach Hold.
    for _ in 0..300 {
        let o = b.tick();
        if let ActuatorCommand::Position { ankle_angle_rad } = o.actuator {
            assert!(ankle_angle_rad >= last - 1e-6);
            last = ankle_angle_rad;
        }
    }
    assert_eq!(b.node.phase(), ReflexPhase::Hold);
    assert_eq!(last, 0.2);
    let peer_hs = Message::HeelStrike(HeelStrike {
        node: PEER,
        step_count: 9,
        time_us: 0,
    });
    let o = b.tick_with(&[peer_hs]);
    assert_eq!(
        (o.phase, o.actuator),
        (ReflexPhase::Swing, ActuatorCommand::Released)
    );
    assert!(fault_events(&o.transmit, FaultCode::PeerHeelStrikeLate).is_empty());
    // Our own heel strike echoed back (or the host's) does not release. (A swing back to
    // the landing angle first: a heel strike sooner than 0.2 s after the lift-off is a
    // stuck contact switch.)
    b.contact = false;
    b.tick();
    b.move_to(0.1);
    b.run(250);
    b.drive_to_push();
    let own = Message::HeelStrike(HeelStrike {
        node: ME,
        step_count: 1,
        time_us: 0,
    });
    assert_eq!(b.tick_with(&[own]).phase, ReflexPhase::Push);
}

#[test]
fn late_peer_message_falls_back_to_lift_off_and_clears_next_stride() {
    let mut b = Bench::enabled();
    b.drive_to_push();
    b.contact = false;
    let o = b.tick();
    assert_eq!(
        (o.phase, o.actuator),
        (ReflexPhase::Swing, ActuatorCommand::Released)
    );
    assert_eq!(
        fault_events(&o.transmit, FaultCode::PeerHeelStrikeLate),
        [FaultTransition::Raised]
    );
    assert_eq!(o.state, NodeState::Enabled, "not safety-relevant");
    b.move_to(0.1);
    b.run(250);
    b.drive_to_push();
    let peer_hs = Message::HeelStrike(HeelStrike {
        node: PEER,
        step_count: 1,
        time_us: 0,
    });
    let o = b.tick_with(&[peer_hs]);
    assert_eq!(
        fault_events(&o.transmit, FaultCode::PeerHeelStrikeLate),
        [FaultTransition::Cleared]
    );
}

#[test]
fn emergency_stop_from_every_state_latches_until_disable() {
    // From Disabled, Enabled (in push) and Safe.
    for start in 0..3 {
        let mut b = Bench::enabled();
        match start {
            0 => {
                b.tick_with(&[cmd(CommandKind::Disable)]);
            }
            1 => b.drive_to_push(),
            _ => {
                b.drivers.actuator_error = true;
                assert_eq!(b.tick().state, NodeState::Safe);
                b.drivers.actuator_error = false;
            }
        }
        let estop = Message::Command(Command {
            target: Target::Broadcast,
            kind: CommandKind::EmergencyStop,
        });
        let o = b.tick_with(&[estop]);
        assert_eq!(o.state, NodeState::EmergencyStop);
        assert_eq!(o.actuator, ActuatorCommand::Released);
        assert_eq!(o.phase, ReflexPhase::Inactive);
        assert_eq!(
            b.tick_with(&[cmd(CommandKind::Enable)]).state,
            NodeState::EmergencyStop
        );
        assert_eq!(
            b.tick_with(&[cmd(CommandKind::Disable)]).state,
            NodeState::Disabled
        );
        assert_eq!(
            b.tick_with(&[cmd(CommandKind::Enable)]).state,
            NodeState::Enabled
        );
    }
}

/// Raise a fault while pushing: safe state, released, fault event; clear it: cleared event,
/// still safe until Enable; Enable then works; Disable from Safe works too.
fn check_safety_fault(
    code: FaultCode,
    raise: impl Fn(&mut Bench),
    clear: impl Fn(&mut Bench),
    ticks_to_raise: u32,
) {
    let mut b = Bench::enabled();
    b.drive_to_push();
    raise(&mut b);
    let mut msgs = Vec::new();
    let mut last = None;
    for _ in 0..ticks_to_raise {
        let o = b.tick();
        msgs.extend(o.transmit.iter().copied());
        last = Some(o);
    }
    let o = last.unwrap();
    assert_eq!(o.state, NodeState::Safe, "{code:?}");
    assert_eq!(o.actuator, ActuatorCommand::Released, "{code:?}");
    assert_eq!(
        fault_events(&msgs, code),
        [FaultTransition::Raised],
        "{code:?}"
    );
    assert!(b.node.faults().contains(code));
    // Enable is refused while the fault is present (commands are read before the sensors,
    // so a one-sample fault is still set here).
    let o = b.tick_with(&[cmd(CommandKind::Enable)]);
    assert_eq!(o.state, NodeState::Safe);
    let mut msgs: Vec<Message> = o.transmit.iter().copied().collect();
    clear(&mut b);
    msgs.extend(b.run(60));
    assert_eq!(
        fault_events(&msgs, code),
        [FaultTransition::Cleared],
        "{code:?}"
    );
    assert_eq!(b.node.state(), NodeState::Safe, "latched until Enable");
    assert!(b.node.faults().is_empty(), "{:?}", b.node.faults());
    assert_eq!(
        b.tick_with(&[cmd(CommandKind::Enable)]).state,
        NodeState::Enabled
    );
    assert_eq!(
        b.tick_with(&[cmd(CommandKind::Disable)]).state,
        NodeState::Disabled
    );
}

#[test]
fn encoder_comms_fault() {
    check_safety_fault(
        FaultCode::EncoderComms,
        |b| b.encoder_error = Some(EncoderError::Parity { word: 1 }),
        |b| b.encoder_error = None,
        1,
    );
}

#[test]
fn encoder_range_fault() {
    check_safety_fault(
        FaultCode::EncoderRange,
        |b| {
            // Creep out of range slowly (no rate fault).
            b.angle = 0.99;
            b.frozen = Some(CALIBRATION.counts(1.05));
        },
        |b| {
            b.frozen = None;
            b.angle = 0.99;
        },
        1,
    );
}

#[test]
fn encoder_rate_fault() {
    check_safety_fault(
        FaultCode::EncoderRate,
        |b| b.angle += 0.2, // 0.2 rad in 1 ms: 200 rad/s
        |_| {},
        1,
    );
}

#[test]
fn encoder_stuck_fault() {
    check_safety_fault(
        FaultCode::EncoderStuck,
        |b| b.frozen = Some(CALIBRATION.counts(b.angle)),
        |b| {
            b.frozen = None;
            b.angle += 0.005;
        },
        60,
    );
}

#[test]
fn peer_heartbeat_lost_fault() {
    check_safety_fault(
        FaultCode::PeerHeartbeatLost,
        |b| b.heartbeats = false,
        |b| b.heartbeats = true,
        352,
    );
}

#[test]
fn actuator_fault() {
    check_safety_fault(
        FaultCode::Actuator,
        |b| b.drivers.actuator_error = true,
        |b| b.drivers.actuator_error = false,
        1,
    );
}

#[test]
fn can_bus_fault() {
    check_safety_fault(
        FaultCode::CanBus,
        |b| b.drivers.can_error = true,
        |b| b.drivers.can_error = false,
        1,
    );
}

#[test]
fn faults_while_disabled_are_reported_and_block_enable() {
    let mut b = Bench::new();
    b.tick();
    b.encoder_error = Some(EncoderError::ErrorFlag { word: 0x4000 });
    let o = b.tick();
    assert_eq!(o.state, NodeState::Disabled);
    assert_eq!(
        fault_events(&o.transmit, FaultCode::EncoderComms),
        [FaultTransition::Raised]
    );
    assert_eq!(
        b.tick_with(&[cmd(CommandKind::Enable)]).state,
        NodeState::Disabled
    );
    let hb = b.run(60).into_iter().find_map(|m| match m {
        Message::Heartbeat(h) => Some(h),
        _ => None,
    });
    assert!(hb.unwrap().faults.contains(FaultCode::EncoderComms));
}

#[test]
fn peer_lost_counts_from_start_up() {
    let mut b = Bench::new();
    b.heartbeats = false;
    let msgs = b.run(300);
    assert!(fault_events(&msgs, FaultCode::PeerHeartbeatLost).is_empty());
    let msgs = b.run(2);
    assert_eq!(
        fault_events(&msgs, FaultCode::PeerHeartbeatLost),
        [FaultTransition::Raised]
    );
}

#[test]
fn parameters_are_range_checked_and_acknowledged() {
    let mut b = Bench::new();
    b.tick();
    let set = |p: ParamId, raw: i32| {
        cmd(CommandKind::SetParam {
            param: p,
            value: ParamValue(raw),
        })
    };
    let ack = |o: TickOutputs| {
        o.transmit
            .iter()
            .find_map(|m| match m {
                Message::ParamAck(a) => Some(*a),
                _ => None,
            })
            .unwrap()
    };
    let a = ack(b.tick_with(&[set(ParamId::TautAngle, -100_000)]));
    assert_eq!(
        (a.status, a.value),
        (ParamStatus::Accepted, ParamValue(-100_000))
    );
    assert_eq!(b.node.params().taut_angle_rad(), -0.1);
    let a = ack(b.tick_with(&[set(ParamId::TautAngle, 100_000)]));
    assert_eq!(
        (a.status, a.value),
        (ParamStatus::OutOfRange, ParamValue(-100_000))
    );
    let a = ack(b.tick_with(&[set(ParamId::ExtendedAngle, -80_000)]));
    assert_eq!(a.status, ParamStatus::OutOfRange);
    let a = ack(b.tick_with(&[set(ParamId::ExtendedAngle, 0)]));
    assert_eq!(a.status, ParamStatus::Accepted);
    let a = ack(b.tick_with(&[set(ParamId::TautAngle, -30_000)]));
    assert_eq!(
        (a.status, a.value),
        (ParamStatus::Inconsistent, ParamValue(-100_000))
    );
    let a = ack(b.tick_with(&[set(ParamId::ExtendedAngle, 200_000)]));
    assert_eq!(a.status, ParamStatus::Accepted);
    b.tick_with(&[cmd(CommandKind::Enable)]);
    let a = ack(b.tick_with(&[set(ParamId::PushDuration, 200_000)]));
    assert_eq!(a.status, ParamStatus::NotWhileEnabled);
    // The new taut angle is the one that engages.
    b.contact = true;
    b.tick();
    b.move_to(-0.09);
    assert_eq!(b.node.phase(), ReflexPhase::Free);
    // Quantisation (0.38 mrad) and the filter: go a little past the threshold.
    b.move_to(-0.102);
    assert!(matches!(
        b.node.phase(),
        ReflexPhase::Push | ReflexPhase::Hold
    ));
}

#[test]
fn receive_work_is_bounded() {
    let mut b = Bench::new();
    b.tick();
    let set = cmd(CommandKind::SetParam {
        param: ParamId::StuckTimeout,
        value: ParamValue(100_000),
    });
    let many = vec![set; 50];
    let o = b.tick_with(&many);
    let acks = o
        .transmit
        .iter()
        .filter(|m| matches!(m, Message::ParamAck(_)))
        .count();
    assert_eq!(acks, firmware::node::MAX_RX_PER_TICK);
    assert_eq!(b.node.dropped_tx(), 0);
}

#[test]
fn estimator_reports_angle_and_rate_in_telemetry() {
    let mut b = Bench::new();
    let mut state = None;
    for k in 0..500 {
        b.angle = 0.1 - 0.5e-3 * k as f32; // −0.5 rad/s
        for m in b.tick().transmit {
            if let Message::AnkleState(s) = m {
                state = Some(s);
            }
        }
    }
    let s = state.unwrap();
    assert!((s.rate.to_si() + 0.5).abs() < 0.02, "{:?}", s.rate);
    assert!((s.angle.to_si() - (0.1 - 0.5e-3 * 495.0)).abs() < 0.01);
}

/// Runs an enabled node through its push into Hold.
fn bench_in_hold() -> Bench {
    let mut b = Bench::enabled();
    b.drive_to_push();
    for _ in 0..300 {
        if b.node.phase() == ReflexPhase::Hold {
            break;
        }
        b.tick();
    }
    assert_eq!(b.node.phase(), ReflexPhase::Hold);
    // Hold for a while with a healthy (noisy) encoder: no stuck fault.
    for _ in 0..200 {
        assert_eq!(b.tick().state, NodeState::Enabled);
    }
    b
}

#[test]
fn stuck_encoder_during_hold_releases_within_50_ms() {
    let mut b = bench_in_hold();
    b.frozen = Some(CALIBRATION.counts(b.angle));
    // The spool keeps turning (the hold loop drives) while the reading stays frozen.
    b.drivers.string_moving = true;
    let mut released_after = None;
    let mut msgs = Vec::new();
    // Tick k (from 0) runs k ms after the first frozen sample.
    for k in 0..=60 {
        let o = b.tick();
        msgs.extend(o.transmit.iter().copied());
        if o.actuator == ActuatorCommand::Released {
            assert_eq!(o.state, NodeState::Safe);
            released_after = Some(k);
            break;
        }
    }
    let ms = released_after.expect("released");
    assert!(ms <= 50, "released {ms} ms after the freeze");
    assert_eq!(
        fault_events(&msgs, FaultCode::EncoderStuck),
        [FaultTransition::Raised]
    );
}

#[test]
fn a_quiet_still_encoder_in_hold_with_a_still_spool_raises_nothing() {
    // A healthy encoder that sits on one code (no noise at all) while the ankle is held and
    // the spool does not turn: no evidence of a stuck sensor.
    let mut b = bench_in_hold();
    b.frozen = Some(CALIBRATION.counts(b.angle));
    b.drivers.string_moving = false;
    for _ in 0..1000 {
        let o = b.tick();
        assert_eq!(o.state, NodeState::Enabled);
        assert_eq!(o.phase, ReflexPhase::Hold);
    }
    assert!(b.node.faults().is_empty(), "{:?}", b.node.faults());
    // The same still reading while the spool turns for 50 ms is a stuck encoder.
    b.drivers.string_moving = true;
    let safe = (0..=60).find(|_| b.tick().state == NodeState::Safe);
    assert!(safe.is_some_and(|k| k <= 51), "{safe:?}");
    assert!(b.node.faults().contains(FaultCode::EncoderStuck));
}

#[test]
fn following_error_catches_a_reversed_motor() {
    let mut b = Bench::enabled();
    b.drive_to_push();
    b.reversed_motor = true;
    let mut msgs = Vec::new();
    let mut safe_after = None;
    for ms in 1..=200 {
        let o = b.tick();
        msgs.extend(o.transmit.iter().copied());
        if o.state == NodeState::Safe {
            assert_eq!(o.actuator, ActuatorCommand::Released);
            safe_after = Some(ms);
            break;
        }
    }
    let ms = safe_after.expect("the following error stops a reversed motor");
    // The setpoint rises while the ankle sinks: 0.05 rad of shortfall within ~10 ms, then
    // 30 ms of it.
    assert!(ms <= 60, "{ms} ms");
    assert_eq!(
        fault_events(&msgs, FaultCode::FollowingError),
        [FaultTransition::Raised]
    );
    assert!(!b.node.faults().contains(FaultCode::EncoderStuck));
}

#[test]
fn a_healthy_push_and_hold_raise_no_following_error() {
    let b = bench_in_hold();
    assert!(b.node.faults().is_empty(), "{:?}", b.node.faults());
}

#[test]
fn a_peer_in_its_safe_state_makes_this_node_safe_until_enabled_again() {
    let mut b = Bench::enabled();
    b.drive_to_push();
    b.peer_state = NodeState::Safe;
    let msgs = b.run(150);
    assert_eq!(b.node.state(), NodeState::Safe);
    assert_eq!(
        fault_events(&msgs, FaultCode::PeerSafe),
        [FaultTransition::Raised, FaultTransition::Cleared],
        "raised, then cleared once this node left Enabled"
    );
    // Both re-enabled: the peer's heartbeats say Enabled again, and so does this node.
    b.peer_state = NodeState::Enabled;
    assert_eq!(
        b.tick_with(&[cmd(CommandKind::Enable)]).state,
        NodeState::Enabled
    );
    b.run(200);
    assert_eq!(b.node.state(), NodeState::Enabled);
    // A peer that is merely disabled is no fault.
    b.peer_state = NodeState::Disabled;
    b.run(200);
    assert_eq!(b.node.state(), NodeState::Enabled);
}

#[test]
fn after_a_safe_event_the_ankles_can_be_enabled_one_at_a_time() {
    let mut b = Bench::enabled();
    b.drive_to_push();
    b.peer_state = NodeState::Safe;
    b.run(150);
    assert_eq!(b.node.state(), NodeState::Safe);
    // Enable this (left) ankle first while the peer (right) still reports Safe: no fault.
    assert_eq!(
        b.tick_with(&[cmd(CommandKind::Enable)]).state,
        NodeState::Enabled
    );
    let msgs = b.run(300);
    assert_eq!(b.node.state(), NodeState::Enabled);
    assert!(fault_events(&msgs, FaultCode::PeerSafe).is_empty());
    // Then the right one: its heartbeats say Enabled.
    b.peer_state = NodeState::Enabled;
    b.run(100);
    assert_eq!(b.node.state(), NodeState::Enabled);
    // A new drop of the peer from Enabled to EmergencyStop is an event again.
    b.peer_state = NodeState::EmergencyStop;
    let msgs = b.run(100);
    assert_eq!(b.node.state(), NodeState::Safe);
    assert_eq!(
        fault_events(&msgs, FaultCode::PeerSafe).first(),
        Some(&FaultTransition::Raised)
    );
}

#[test]
fn a_flapping_fault_is_reported_at_most_once_per_inhibit_time() {
    let mut b = Bench::enabled();
    let mut msgs = Vec::new();
    for k in 0..200 {
        b.drivers.actuator_error = k % 2 == 0;
        msgs.extend(b.tick().transmit);
    }
    let events = fault_events(&msgs, FaultCode::Actuator);
    assert!(
        (2..=5).contains(&events.len()),
        "{} events in 200 ms",
        events.len()
    );
    assert!(b.node.suppressed_fault_events() > 100);
}

#[test]
fn identity_at_boot_and_on_request() {
    let mut config = NodeConfig::nominal(ME);
    config.uid = [0x11, 0x22, 0x33];
    config.build_id = 0xC0FFEE;
    config.reset_cause = ResetCause::IndependentWatchdog;
    let mut b = Bench::new();
    b.node = AnkleNode::new(config).unwrap();
    let boot = b.tick().transmit;
    let versions = boot
        .iter()
        .filter(|m| matches!(m, Message::Version(v) if v.build == 0xC0FFEE))
        .count();
    assert_eq!(versions, 1, "one Version at boot, with the identity");
    assert!(boot.contains(&Message::Identity(Identity {
        node: ME,
        uid_low: 0x11,
        uid_mid: 0x22
    })));
    assert!(boot.iter().any(|m| matches!(m,
        Message::BootInfo(i) if i.uid_high == 0x33
            && i.reset_cause == ResetCause::IndependentWatchdog)));
    assert!(!b
        .tick()
        .transmit
        .iter()
        .any(|m| matches!(m, Message::Identity(_))));
    let again = b.tick_with(&[cmd(CommandKind::GetIdentity), cmd(CommandKind::GetIdentity)]);
    let n = again
        .transmit
        .iter()
        .filter(|m| matches!(m, Message::Identity(_)))
        .count();
    assert_eq!(n, 1, "answered once per tick");
}

#[test]
fn get_param_reads_the_value_in_force() {
    let mut b = Bench::new();
    b.tick();
    let o = b.tick_with(&[cmd(CommandKind::GetParam {
        param: ParamId::ExtendedAngle,
    })]);
    assert!(o.transmit.contains(&Message::ParamAck(ParamAck {
        node: ME,
        param: ParamId::ExtendedAngle,
        status: ParamStatus::Read,
        value: ParamValue(200_000),
    })));
}

#[test]
fn fault_history_says_why_the_node_went_safe_and_clear_errors_empties_it() {
    let mut b = Bench::enabled();
    b.drive_to_push();
    b.encoder_error = Some(EncoderError::Parity { word: 1 });
    assert_eq!(b.tick().state, NodeState::Safe);
    b.encoder_error = None;
    b.run(10);
    let o = b.tick_with(&[cmd(CommandKind::GetFaultHistory)]);
    let entries: Vec<FaultHistoryEntry> = o
        .transmit
        .iter()
        .filter_map(|m| match m {
            Message::FaultHistory(e) => Some(*e),
            _ => None,
        })
        .collect();
    assert_eq!(entries.len(), 1, "{entries:?}");
    assert_eq!(entries[0].entry, 0);
    assert_eq!(entries[0].code, FaultCode::EncoderComms);
    assert_eq!(entries[0].state_after, NodeState::Safe, "the cause of Safe");
    assert_eq!(entries[0].detail, 2);
    let o = b.tick_with(&[cmd(CommandKind::ClearErrors)]);
    assert!(o.transmit.contains(&Message::CommandAck(CommandAck {
        node: ME,
        opcode: Opcode::ClearErrors,
        result: CommandResult::Done,
    })));
    assert_eq!(b.node.fault_history().count(), 0);
}

#[test]
fn save_params_asks_the_board_and_acknowledges_its_outcome() {
    let mut b = Bench::new();
    b.tick();
    let o = b.tick_with(&[cmd(CommandKind::SaveParams)]);
    assert_eq!(o.request, Some(firmware::node::NodeRequest::SaveParams));
    assert!(!o
        .transmit
        .iter()
        .any(|m| matches!(m, Message::CommandAck(_))));
    b.node.storage_done(false);
    let o = b.tick();
    assert!(o.transmit.contains(&Message::CommandAck(CommandAck {
        node: ME,
        opcode: Opcode::SaveParams,
        result: CommandResult::Failed,
    })));
    // Not while enabled.
    let mut b = Bench::enabled();
    let o = b.tick_with(&[cmd(CommandKind::SaveParams)]);
    assert_eq!(o.request, None);
    assert!(o.transmit.iter().any(|m| matches!(m,
        Message::CommandAck(a) if a.result == CommandResult::NotWhileEnabled)));
}

#[test]
fn encoder_zero_calibration_takes_the_current_reading() {
    let mut b = Bench::new();
    b.tick();
    b.angle = 0.3;
    b.frozen = Some(5000);
    let o = b.tick_with(&[cmd(CommandKind::CalibrateEncoderZero)]);
    assert_eq!(
        o.request,
        Some(firmware::node::NodeRequest::SetEncoderZero { zero_counts: 5000 })
    );
    assert!(o.transmit.iter().any(|m| matches!(m,
        Message::CommandAck(a) if a.opcode == Opcode::CalibrateEncoderZero
            && a.result == CommandResult::Done)));
    b.encoder_error = Some(EncoderError::Parity { word: 1 });
    let o = b.tick_with(&[cmd(CommandKind::CalibrateEncoderZero)]);
    assert_eq!(o.request, None, "no reading, no calibration");
}

#[test]
fn every_lost_frame_is_counted_and_reported_without_a_safe_state() {
    let mut b = Bench::enabled();
    let mut msgs = Vec::new();
    b.drivers.rx_lost = 3;
    msgs.extend(b.tick().transmit);
    b.drivers.rx_lost = 0;
    msgs.extend(b.run(100));
    b.drivers.rx_lost = 2;
    msgs.extend(b.tick().transmit);
    b.drivers.rx_lost = 0;
    msgs.extend(b.run(100));
    let raised: Vec<i16> = msgs
        .iter()
        .filter_map(|m| match m {
            Message::Fault(f)
                if f.code == FaultCode::CanRxOverflow
                    && f.transition == FaultTransition::Raised =>
            {
                Some(f.detail)
            }
            _ => None,
        })
        .collect();
    // Each event carries the total of frames lost since start-up: 3, then 3 + 2.
    assert_eq!(raised, [3, 5]);
    assert_eq!(
        b.node.state(),
        NodeState::Enabled,
        "reported, not a safe state"
    );
    assert!(
        !b.node.faults().contains(FaultCode::CanRxOverflow),
        "cleared"
    );
}

/// The fault events of `code` in `msgs`, with their details.
fn fault_details(msgs: &[Message], code: FaultCode) -> Vec<(FaultTransition, i16)> {
    msgs.iter()
        .filter_map(|m| match m {
            Message::Fault(f) if f.code == code => Some((f.transition, f.detail)),
            _ => None,
        })
        .collect()
}

#[test]
fn a_reading_frozen_in_a_walking_stance_is_stuck_within_50_ms() {
    // After an own heel strike the stance turns the ankle: a reading that stops changing
    // there (no push, no spool) is `EncoderStuck` 50 ms later, sent with the frozen counts,
    // and the node goes `Safe`. Before the first heel strike (enabled with the foot down)
    // nothing says the walker walks: the same frozen reading raises nothing.
    let mut b = Bench::new();
    b.contact = true;
    b.tick();
    b.tick_with(&[cmd(CommandKind::Enable)]);
    assert_eq!(b.node.phase(), ReflexPhase::Free);
    b.frozen = Some(CALIBRATION.counts(b.angle));
    for _ in 0..500 {
        assert_eq!(b.tick().state, NodeState::Enabled);
    }
    // A walking stance: swing, heel strike, the ankle turning down toward the taut angle.
    b.frozen = None;
    b.contact = false;
    b.run(250);
    b.contact = true;
    b.tick();
    assert_eq!(b.node.phase(), ReflexPhase::Free);
    for _ in 0..5 {
        b.angle -= 0.0005;
        b.tick();
    }
    let counts = CALIBRATION.counts(b.angle);
    b.frozen = Some(counts);
    let mut msgs = Vec::new();
    let mut safe_after = None;
    for k in 0..=60 {
        b.angle -= 0.0005;
        let o = b.tick();
        msgs.extend(o.transmit.iter().copied());
        if o.state == NodeState::Safe {
            safe_after = Some(k);
            break;
        }
    }
    let k = safe_after.expect("safe");
    assert!((48..=50).contains(&k), "{k} ms");
    assert_eq!(
        fault_details(&msgs, FaultCode::EncoderStuck),
        [(FaultTransition::Raised, counts as i16)]
    );
}

#[test]
fn a_switch_still_closed_after_the_release_is_stuck_closed_and_goes_safe() {
    let mut b = Bench::enabled();
    b.drive_to_push();
    let peer_hs = Message::HeelStrike(HeelStrike {
        node: PEER,
        step_count: 1,
        time_us: 0,
    });
    let o = b.tick_with(&[peer_hs]);
    assert_eq!(o.phase, ReflexPhase::Swing);
    // The foot never lifts (the switch stays closed) and the ankle does not turn as a
    // loaded one (it stays where the string left it).
    let mut msgs = Vec::new();
    let mut safe_after = None;
    for k in 1..=60 {
        let o = b.tick();
        msgs.extend(o.transmit.iter().copied());
        if o.state == NodeState::Safe {
            safe_after = Some(k);
            break;
        }
    }
    assert_eq!(safe_after, Some(50));
    assert_eq!(
        fault_details(&msgs, FaultCode::ContactStuck),
        [(
            FaultTransition::Raised,
            firmware::stride_check::CONTACT_STUCK_CLOSED
        )]
    );
    // It stays until the switch changes, so the node cannot be enabled on it.
    b.tick_with(&[cmd(CommandKind::Enable)]);
    assert_eq!(b.node.state(), NodeState::Safe);
    b.contact = false;
    b.tick();
    assert!(!b.node.faults().contains(FaultCode::ContactStuck));
}

#[test]
fn an_ankle_extending_under_a_silent_spool_is_a_stuck_spool() {
    // With a spool sensor, a push that extends the ankle while the spool reports no motion:
    // `SpoolStuck` with the ankle's extension in counts; without one, nothing is checked.
    for spool_sensor in [true, false] {
        let mut b = Bench::enabled();
        b.drivers.spool_sensor = spool_sensor;
        b.drivers.string_moving = false;
        b.drive_to_push();
        let mut msgs = Vec::new();
        for _ in 0..300 {
            msgs.extend(b.tick().transmit.iter().copied());
        }
        let found = fault_details(&msgs, FaultCode::SpoolStuck);
        if spool_sensor {
            assert!(
                // Over 16 counts (the threshold), by the encoder noise at most.
                matches!(found.first(), Some((FaultTransition::Raised, d)) if (17..=19).contains(d)),
                "{found:?}"
            );
            assert_eq!(b.node.state(), NodeState::Safe);
        } else {
            assert!(found.is_empty(), "{found:?}");
            assert_eq!(b.node.phase(), ReflexPhase::Hold);
        }
    }
}
