//! Property: no input sequence makes the node panic, and its outputs stay within bounds:
//! a position setpoint is always finite and between the taut and the extended angle, the
//! actuator is released outside `Enabled`, and the transmit list never overflows.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use firmware::node::{AnkleNode, DriverHealth, NodeConfig, TickInputs};
use firmware::sensors::{AngleSample, EncoderError};
use firmware::{ActuatorCommand, Instant};
use proptest::prelude::*;
use protocol::*;
use std::sync::atomic::{AtomicU64, Ordering};

#[derive(Debug, Clone)]
struct Step {
    dt_us: u64,
    /// `None`: an encoder error; `Some((counts, None, d))`: the running angle moves by `d`;
    /// `Some((counts, Some(a), _))`: the angle jumps to `a` (NaN and infinities included).
    angle: Option<(u16, Option<f32>, f32)>,
    enable: bool,
    contact: bool,
    frames: Vec<(u16, Vec<u8>)>,
    drivers: (bool, bool),
}

fn angle() -> impl Strategy<Value = f32> {
    prop_oneof![
        -1.2f32..1.2,
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(-0.08f32),
        Just(0.2f32),
    ]
}

fn frame() -> impl Strategy<Value = (u16, Vec<u8>)> {
    // Mostly well-formed identifiers with random payloads, some garbage.
    (
        prop_oneof![
            prop::sample::select(vec![
                0x012u16, 0x01F, 0x023, 0x042, 0x04F, 0x063, 0x073, 0x062
            ]),
            0u16..0x800
        ],
        prop::collection::vec(any::<u8>(), 0..9),
    )
}

fn step() -> impl Strategy<Value = Step> {
    (
        prop_oneof![9 => Just(1000u64), 1 => 0u64..5_000_000],
        prop::option::weighted(
            0.98,
            (
                any::<u16>(),
                prop::option::weighted(0.02, angle()),
                -0.006f32..0.004,
            ),
        ),
        prop::bool::weighted(0.05),
        prop::bool::weighted(0.7),
        prop::collection::vec(frame(), 0..3),
        (prop::bool::weighted(0.01), prop::bool::weighted(0.01)),
    )
        .prop_map(|(dt_us, angle, enable, contact, frames, drivers)| Step {
            dt_us,
            angle,
            enable,
            contact,
            frames,
            drivers,
        })
}

static POSITION_TICKS: AtomicU64 = AtomicU64::new(0);

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn node_never_panics_and_outputs_stay_bounded(steps in prop::collection::vec(step(), 1..300)) {
        let mut node = AnkleNode::new(NodeConfig::nominal(NodeId::LeftAnkle)).unwrap();
        let mut now = 0u64;
        let mut running = 0.1f32;
        for s in steps {
            now = now.saturating_add(s.dt_us);
            let mut received: Vec<Message> = s
                .frames
                .iter()
                .filter_map(|(id, data)| Message::decode(*id, data).ok())
                .collect();
            received.push(Message::Heartbeat(Heartbeat {
                node: NodeId::RightAnkle,
                state: NodeState::Enabled,
                faults: FaultFlags::NONE,
                uptime_ms: 0,
            }));
            if s.enable {
                received.push(Message::Command(Command {
                    target: Target::Broadcast,
                    kind: CommandKind::Enable,
                }));
            }
            let angle = match s.angle {
                Some((counts, jump, delta)) => {
                    running = match jump {
                        Some(a) => a,
                        None if running.is_finite() => (running + delta).clamp(-0.5, 0.5),
                        None => 0.1,
                    };
                    Ok(AngleSample { counts: counts & 0x3FFF, angle_rad: running })
                }
                None => Err(EncoderError::Parity { word: 1 }),
            };
            let p = *node.params();
            let o = node.tick(
                Instant::from_micros(now),
                &TickInputs {
                    angle,
                    contact_closed: s.contact,
                    received: &received,
                    drivers: DriverHealth { actuator_error: s.drivers.0, actuator_error_detail: 0, can_error: s.drivers.1, can_bus_off: false, string_moving: false, spool_sensor: false, rx_lost: 0 },
                },
            );
            prop_assert_eq!(node.dropped_tx(), 0);
            for m in &o.transmit {
                prop_assert!(m.encode().is_ok());
            }
            match o.actuator {
                ActuatorCommand::Released => {}
                ActuatorCommand::Position { ankle_angle_rad } => {
                    POSITION_TICKS.fetch_add(1, Ordering::Relaxed);
                    prop_assert_eq!(o.state, NodeState::Enabled);
                    prop_assert!(ankle_angle_rad.is_finite());
                    let lo = p.taut_angle_rad().min(node.params().taut_angle_rad());
                    let hi = p.extended_angle_rad().max(node.params().extended_angle_rad());
                    prop_assert!(ankle_angle_rad >= lo - 1e-6 && ankle_angle_rad <= hi + 1e-6);
                }
            }
        }
    }
}

/// The property above must exercise the actuator, not only the disabled node.
#[test]
fn property_reaches_the_push_phase() {
    node_never_panics_and_outputs_stay_bounded();
    assert!(
        POSITION_TICKS.load(Ordering::Relaxed) > 100,
        "{}",
        POSITION_TICKS.load(Ordering::Relaxed)
    );
}
