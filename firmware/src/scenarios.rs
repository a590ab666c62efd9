//! Scripted sensor traces for the ankle node, run identically on the host and on the emulated
//! Cortex-M4 (QEMU `mps2-an386`).
//!
//! Each [`Scenario`] drives the left ankle at 1 kHz through a few strides of a synthetic gait
//! with a one-line plant: during stance the passive ankle angle falls from +0.15 rad at
//! 0.6 rad/s; the string keeps it at or above the actuator's setpoint of the previous tick; the
//! foot is on the floor for the first 700 ms of each 1000 ms stride. The peer's heartbeat
//! arrives every 50 ms and its heel strike 650 ms into each stance, unless the scenario
//! withholds them; host commands and encoder glitches are scripted by tick.
//!
//! [`run`] writes one line per tick (`tick actuator-bits phase state`) and a digest line of
//! every transmitted frame, so two runs can be compared bit for bit, and returns a
//! [`Summary`] that [`Scenario::verdict`] checks against the scenario's expectations.

use core::fmt::Write;

use heapless::Vec;
use protocol::{
    Command, CommandKind, FaultCode, FaultFlags, FaultTransition, Heartbeat, HeelStrike, Message,
    NodeId, NodeState, ParamId, ParamStatus, ParamValue, ReflexPhase, Target,
};

use crate::node::{AnkleNode, ConfigError, DriverHealth, NodeConfig, TickInputs};
use crate::reflex::ActuatorCommand;
use crate::sensors::{
    offset_counts, with_simulated_noise, AngleCalibration, AngleSample, EncoderError,
};
use crate::time::Instant;

/// Control period \[µs\].
pub const TICK_US: u64 = 1_000;
/// First stride's heel strike \[tick\].
pub const FIRST_STRIDE_TICK: u32 = 100;
/// Stride period \[ticks\].
pub const STRIDE_TICKS: u32 = 1_000;
/// Stance duration \[ticks\].
pub const STANCE_TICKS: u32 = 700;
/// The peer's heel strike, from the start of the own stance \[ticks\].
pub const PEER_HEEL_STRIKE_TICK: u32 = 650;
/// Encoder calibration of the scripted sensor: every simulated ankle's,
/// [`crate::sensors::SIMULATED_CALIBRATION`].
pub const CALIBRATION: AngleCalibration = crate::sensors::SIMULATED_CALIBRATION;

/// A scripted encoder misbehaviour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Glitch {
    /// SPI failures over `[from, to)` ticks.
    Comms {
        /// First tick.
        from: u32,
        /// End tick (exclusive).
        to: u32,
    },
    /// The reading freezes over `[from, to)` ticks.
    Stuck {
        /// First tick.
        from: u32,
        /// End tick (exclusive).
        to: u32,
    },
    /// One reading off by `counts` at tick `at`.
    Jump {
        /// The tick.
        at: u32,
        /// Offset \[counts\].
        counts: i16,
    },
}

/// What a scenario must produce.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Expect {
    /// Transitions into Push (from Free, or straight from an Enable with the string taut).
    pub pushes: u32,
    /// Releases by the peer's heel-strike message.
    pub releases_by_peer: u32,
    /// Releases by the own lift-off (fallback).
    pub releases_by_lift_off: u32,
    /// Fault codes raised at least once (bits as in [`FaultFlags`]).
    pub faults_raised: u16,
    /// Node state at the end.
    pub final_state: NodeState,
    /// Parameter acknowledgements, in order.
    pub acks: &'static [ParamStatus],
}

/// One scripted run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scenario {
    /// Name printed in the trace.
    pub name: &'static str,
    /// Length \[ticks\].
    pub ticks: u32,
    /// Host commands to the left ankle, by tick.
    pub commands: &'static [(u32, CommandKind)],
    /// Strides (0-based) whose peer heel-strike message is withheld.
    pub withhold_peer_heel_strike: &'static [u32],
    /// Ticks `[from, to)` without peer heartbeats.
    pub peer_silent: Option<(u32, u32)>,
    /// Encoder glitches.
    pub glitches: &'static [Glitch],
    /// Expected outcome.
    pub expect: Expect,
}

const fn flags(codes: &[FaultCode]) -> u16 {
    match codes {
        [first, rest @ ..] => first.flag() | flags(rest),
        [] => 0,
    }
}

const fn set(param: ParamId, micro: i32) -> CommandKind {
    CommandKind::SetParam {
        param,
        value: ParamValue(micro),
    }
}

const ENABLE_AT_10: &[(u32, CommandKind)] = &[(10, CommandKind::Enable)];

/// Every scenario, in the order the QEMU binary runs them.
pub const SCENARIOS: &[Scenario] = &[
    Scenario {
        name: "nominal",
        ticks: 3_200,
        commands: ENABLE_AT_10,
        withhold_peer_heel_strike: &[],
        peer_silent: None,
        glitches: &[],
        expect: Expect {
            pushes: 3,
            releases_by_peer: 3,
            releases_by_lift_off: 0,
            faults_raised: 0,
            final_state: NodeState::Enabled,
            acks: &[],
        },
    },
    Scenario {
        name: "late_peer_heel_strike",
        ticks: 3_200,
        commands: ENABLE_AT_10,
        withhold_peer_heel_strike: &[1],
        peer_silent: None,
        glitches: &[],
        expect: Expect {
            pushes: 3,
            releases_by_peer: 2,
            releases_by_lift_off: 1,
            faults_raised: flags(&[FaultCode::PeerHeelStrikeLate]),
            final_state: NodeState::Enabled,
            acks: &[],
        },
    },
    Scenario {
        name: "emergency_stop",
        ticks: 3_200,
        commands: &[
            (10, CommandKind::Enable),
            // Stride 0: push starts at 100 + 384 = 484; stop in the middle of it.
            (540, CommandKind::EmergencyStop),
            (1_000, CommandKind::Enable), // ignored: latched
            (1_500, CommandKind::Disable),
            // Stride 1 is in stance, the ankle past the taut angle: pushes at once.
            (1_600, CommandKind::Enable),
        ],
        withhold_peer_heel_strike: &[],
        peer_silent: None,
        glitches: &[],
        expect: Expect {
            pushes: 3,
            releases_by_peer: 2,
            releases_by_lift_off: 0,
            faults_raised: 0,
            final_state: NodeState::Enabled,
            acks: &[],
        },
    },
    Scenario {
        name: "peer_heartbeat_lost",
        ticks: 3_200,
        commands: &[(10, CommandKind::Enable), (2_000, CommandKind::Enable)],
        withhold_peer_heel_strike: &[],
        peer_silent: Some((1_200, 1_800)),
        glitches: &[],
        expect: Expect {
            pushes: 2,
            releases_by_peer: 2,
            releases_by_lift_off: 0,
            faults_raised: flags(&[FaultCode::PeerHeartbeatLost]),
            final_state: NodeState::Enabled,
            acks: &[],
        },
    },
    Scenario {
        name: "encoder_faults",
        ticks: 4_200,
        commands: &[
            (10, CommandKind::Enable),
            (1_050, CommandKind::Enable),
            (2_050, CommandKind::Enable),
            (3_050, CommandKind::Enable),
        ],
        withhold_peer_heel_strike: &[],
        peer_silent: None,
        glitches: &[
            Glitch::Comms { from: 300, to: 305 },
            Glitch::Jump {
                at: 1_300,
                counts: 200,
            },
            // Stride 2's push starts at 2_100 + 384; freeze during it.
            Glitch::Stuck {
                from: 2_500,
                to: 2_700,
            },
        ],
        // Stride 0: comms fault before the push; stride 1: rate fault before the push;
        // stride 2: pushes, then stuck; stride 3: pushes and is released normally.
        expect: Expect {
            pushes: 2,
            releases_by_peer: 1,
            releases_by_lift_off: 0,
            faults_raised: flags(&[
                FaultCode::EncoderComms,
                FaultCode::EncoderRate,
                FaultCode::EncoderStuck,
            ]),
            final_state: NodeState::Enabled,
            acks: &[],
        },
    },
    Scenario {
        name: "parameters",
        ticks: 2_200,
        commands: &[
            // Extended angle 0.01 rad (accepted), taut −0.03 rad (inconsistent: less than
            // 0.05 rad below the extended angle), duration 0.6 s (out of range), extended
            // 0.15 rad and taut −0.05 rad (accepted); then enable; a change while enabled is
            // refused.
            (5, set(ParamId::ExtendedAngle, 10_000)),
            (6, set(ParamId::TautAngle, -30_000)),
            (7, set(ParamId::PushDuration, 600_000)),
            (8, set(ParamId::ExtendedAngle, 150_000)),
            (9, set(ParamId::TautAngle, -50_000)),
            (10, CommandKind::Enable),
            (
                500,
                CommandKind::SetParam {
                    param: ParamId::TautAngle,
                    value: ParamValue(-80_000),
                },
            ),
        ],
        withhold_peer_heel_strike: &[],
        peer_silent: None,
        glitches: &[],
        expect: Expect {
            pushes: 2,
            releases_by_peer: 2,
            releases_by_lift_off: 0,
            faults_raised: 0,
            final_state: NodeState::Enabled,
            acks: &[
                ParamStatus::Accepted,
                ParamStatus::Inconsistent,
                ParamStatus::OutOfRange,
                ParamStatus::Accepted,
                ParamStatus::Accepted,
                ParamStatus::NotWhileEnabled,
            ],
        },
    },
];

/// What a run produced.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Summary {
    /// Free → Push transitions.
    pub pushes: u32,
    /// Releases by the peer's heel strike.
    pub releases_by_peer: u32,
    /// Releases by the own lift-off.
    pub releases_by_lift_off: u32,
    /// Fault codes raised at least once.
    pub faults_raised: FaultFlags,
    /// Final node state.
    pub final_state: NodeState,
    /// Acknowledgements received, in order (first 8).
    pub acks: Vec<ParamStatus, 8>,
    /// Frames transmitted.
    pub frames: u32,
    /// FNV-1a digest of every actuator command's bits.
    pub actuator_digest: u64,
    /// FNV-1a digest of every transmitted frame (id, length, payload).
    pub frame_digest: u64,
    /// Largest setpoint commanded \[rad\] (bits, for exact comparison).
    pub max_setpoint_bits: u32,
}

/// Why a scenario failed its expectations: the first mismatching field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mismatch {
    /// Push count differs.
    Pushes {
        /// Expected.
        expected: u32,
        /// Got.
        got: u32,
    },
    /// Peer-release count differs.
    ReleasesByPeer {
        /// Expected.
        expected: u32,
        /// Got.
        got: u32,
    },
    /// Lift-off-release count differs.
    ReleasesByLiftOff {
        /// Expected.
        expected: u32,
        /// Got.
        got: u32,
    },
    /// Raised faults differ.
    Faults {
        /// Expected bits.
        expected: u16,
        /// Got bits.
        got: u16,
    },
    /// Final state differs.
    FinalState {
        /// Expected.
        expected: NodeState,
        /// Got.
        got: NodeState,
    },
    /// Acknowledgements differ (index of the first difference).
    Acks {
        /// Index.
        index: usize,
    },
    /// The node could not be built.
    Config(ConfigError),
}

impl Scenario {
    /// Compare a summary with the expectations.
    ///
    /// # Errors
    /// The first [`Mismatch`].
    pub fn verdict(&self, s: &Summary) -> Result<(), Mismatch> {
        let e = &self.expect;
        if s.pushes != e.pushes {
            return Err(Mismatch::Pushes {
                expected: e.pushes,
                got: s.pushes,
            });
        }
        if s.releases_by_peer != e.releases_by_peer {
            return Err(Mismatch::ReleasesByPeer {
                expected: e.releases_by_peer,
                got: s.releases_by_peer,
            });
        }
        if s.releases_by_lift_off != e.releases_by_lift_off {
            return Err(Mismatch::ReleasesByLiftOff {
                expected: e.releases_by_lift_off,
                got: s.releases_by_lift_off,
            });
        }
        if s.faults_raised.bits() != e.faults_raised {
            return Err(Mismatch::Faults {
                expected: e.faults_raised,
                got: s.faults_raised.bits(),
            });
        }
        if s.final_state != e.final_state {
            return Err(Mismatch::FinalState {
                expected: e.final_state,
                got: s.final_state,
            });
        }
        if s.acks.len() != e.acks.len() {
            return Err(Mismatch::Acks {
                index: s.acks.len().min(e.acks.len()),
            });
        }
        for (i, (a, b)) in s.acks.iter().zip(e.acks.iter()).enumerate() {
            if a != b {
                return Err(Mismatch::Acks { index: i });
            }
        }
        Ok(())
    }
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

fn fnv(mut h: u64, bytes: &[u8]) -> u64 {
    for b in bytes {
        h ^= *b as u64;
        h = h.wrapping_mul(FNV_PRIME);
    }
    h
}

/// The scripted world around the node: the plant and the peer.
#[derive(Clone, Copy, Debug)]
pub struct World {
    scenario: &'static Scenario,
    last_command: ActuatorCommand,
    frozen_counts: Option<u16>,
    angle_rad: f32,
}

/// Largest change of the plant's ankle angle per tick \[rad\] (10 rad/s, below the
/// plausibility limit).
pub const PLANT_MAX_STEP_RAD: f32 = 0.01;

impl World {
    /// A world for `scenario`, actuator released.
    pub fn new(scenario: &'static Scenario) -> Self {
        World {
            scenario,
            last_command: ActuatorCommand::Released,
            frozen_counts: None,
            angle_rad: 0.15,
        }
    }

    fn stride_of(tick: u32) -> Option<(u32, u32)> {
        tick.checked_sub(FIRST_STRIDE_TICK)
            .map(|t| (t / STRIDE_TICKS, t % STRIDE_TICKS))
    }

    /// Foot on the floor at `tick`.
    pub fn contact(tick: u32) -> bool {
        matches!(Self::stride_of(tick), Some((_, phase)) if phase < STANCE_TICKS)
    }

    /// Advance the plant to `tick`: the ankle moves towards the passive angle, or the
    /// actuator's setpoint when that is higher (taut string), by at most
    /// [`PLANT_MAX_STEP_RAD`].
    pub fn advance(&mut self, tick: u32) -> f32 {
        let passive = match Self::stride_of(tick) {
            Some((_, phase)) if phase < STANCE_TICKS => 0.15 - 0.6 * (phase as f32 * 1.0e-3),
            _ => 0.15,
        };
        let target = match self.last_command {
            ActuatorCommand::Position { ankle_angle_rad } if ankle_angle_rad > passive => {
                ankle_angle_rad
            }
            _ => passive,
        };
        let step = (target - self.angle_rad).clamp(-PLANT_MAX_STEP_RAD, PLANT_MAX_STEP_RAD);
        self.angle_rad += step;
        self.angle_rad
    }

    /// The encoder read of the current plant angle, glitches applied.
    pub fn encoder(&mut self, tick: u32) -> Result<AngleSample, EncoderError> {
        let mut counts = with_simulated_noise(CALIBRATION.counts(self.angle_rad), tick);
        let mut frozen = false;
        for g in self.scenario.glitches {
            match *g {
                Glitch::Comms { from, to } if (from..to).contains(&tick) => {
                    return Err(EncoderError::Bus(embedded_hal::spi::ErrorKind::Other));
                }
                Glitch::Stuck { from, to } if (from..to).contains(&tick) => {
                    counts = *self.frozen_counts.get_or_insert(counts);
                    frozen = true;
                }
                Glitch::Jump { at, counts: d } if at == tick => {
                    counts = offset_counts(counts, i32::from(d));
                }
                _ => {}
            }
        }
        if !frozen {
            self.frozen_counts = None;
        }
        Ok(AngleSample {
            counts,
            angle_rad: CALIBRATION.angle_rad(counts),
        })
    }

    /// Messages that reach the node at `tick`.
    pub fn received(&self, tick: u32) -> Vec<Message, 4> {
        let mut rx = Vec::new();
        let silent = matches!(self.scenario.peer_silent, Some((a, b)) if (a..b).contains(&tick));
        if tick % 50 == 7 && !silent {
            let _ = rx.push(Message::Heartbeat(Heartbeat {
                node: NodeId::RightAnkle,
                state: NodeState::Enabled,
                faults: FaultFlags::NONE,
                uptime_ms: tick,
            }));
        }
        if let Some((stride, phase)) = Self::stride_of(tick) {
            if phase == PEER_HEEL_STRIKE_TICK
                && !self.scenario.withhold_peer_heel_strike.contains(&stride)
            {
                let _ = rx.push(Message::HeelStrike(HeelStrike {
                    node: NodeId::RightAnkle,
                    // The signal counts strides modulo 2¹⁶ (it wraps): on purpose.
                    step_count: (stride & 0xFFFF) as u16,
                    time_us: tick.wrapping_mul(1000),
                }));
            }
        }
        for (t, kind) in self.scenario.commands {
            if *t == tick {
                let _ = rx.push(Message::Command(Command {
                    target: Target::Node(NodeId::LeftAnkle),
                    kind: *kind,
                }));
            }
        }
        rx
    }
}

/// Observes each tick of a run: called with the tick, the node (before the tick) and the
/// closure that runs the tick. The QEMU binary uses it to count cycles.
pub trait TickHook {
    /// Run `f` (exactly once) and return its result.
    fn around<R>(&mut self, tick: u32, f: impl FnOnce() -> R) -> R;
}

/// A hook that only runs the tick.
pub struct NoHook;

impl TickHook for NoHook {
    fn around<R>(&mut self, _: u32, f: impl FnOnce() -> R) -> R {
        f()
    }
}

/// Line-buffered writer: collects output and flushes in chunks (few semihosting calls).
pub struct Buffered<W: Write> {
    inner: W,
    buf: heapless::String<512>,
}

impl<W: Write> Buffered<W> {
    /// Wrap a writer.
    pub fn new(inner: W) -> Self {
        Buffered {
            inner,
            buf: heapless::String::new(),
        }
    }
    /// Write out what is buffered.
    pub fn flush(&mut self) -> core::fmt::Result {
        let r = self.inner.write_str(&self.buf);
        self.buf.clear();
        r
    }
}

impl<W: Write> Write for Buffered<W> {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        if self.buf.len().saturating_add(s.len()) > self.buf.capacity() {
            self.flush()?;
        }
        if self.buf.push_str(s).is_err() {
            return self.inner.write_str(s);
        }
        Ok(())
    }
}

/// Run a scenario, writing one line per tick to `out`.
///
/// # Errors
/// [`Mismatch::Config`] if the node cannot be built; write errors are ignored (the summary
/// still counts).
pub fn run<W: Write, H: TickHook>(
    scenario: &'static Scenario,
    out: &mut W,
    hook: &mut H,
) -> Result<Summary, Mismatch> {
    let mut node =
        AnkleNode::new(NodeConfig::nominal(NodeId::LeftAnkle)).map_err(Mismatch::Config)?;
    let mut world = World::new(scenario);
    let mut s = Summary {
        pushes: 0,
        releases_by_peer: 0,
        releases_by_lift_off: 0,
        faults_raised: FaultFlags::NONE,
        final_state: NodeState::Disabled,
        acks: Vec::new(),
        frames: 0,
        actuator_digest: FNV_OFFSET,
        frame_digest: FNV_OFFSET,
        max_setpoint_bits: 0,
    };
    let mut max_setpoint = f32::NEG_INFINITY;
    let _ = writeln!(out, "scenario {}", scenario.name);
    for tick in 0..scenario.ticks {
        world.advance(tick);
        let angle = world.encoder(tick);
        let rx = world.received(tick);
        let inputs = TickInputs {
            angle,
            contact_closed: World::contact(tick),
            received: &rx,
            drivers: DriverHealth::default(),
        };
        let phase_before = node.phase();
        let now = Instant::from_micros(u64::from(tick).saturating_mul(TICK_US));
        let o = hook.around(tick, || node.tick(now, &inputs));
        world.last_command = o.actuator;

        if phase_before != ReflexPhase::Push && o.phase == ReflexPhase::Push {
            s.pushes = s.pushes.saturating_add(1);
        }
        let released = matches!(
            phase_before,
            ReflexPhase::Free | ReflexPhase::Push | ReflexPhase::Hold
        ) && o.phase == ReflexPhase::Swing;
        let late_raised = o.transmit.iter().any(|m| {
            matches!(m, Message::Fault(f) if f.code == FaultCode::PeerHeelStrikeLate
                && f.transition == FaultTransition::Raised)
        });
        if released && (late_raised || node.faults().contains(FaultCode::PeerHeelStrikeLate)) {
            s.releases_by_lift_off = s.releases_by_lift_off.saturating_add(1);
        } else if released {
            s.releases_by_peer = s.releases_by_peer.saturating_add(1);
        }
        let bits = o.actuator.bits();
        s.actuator_digest = fnv(s.actuator_digest, &bits.to_le_bytes());
        if let ActuatorCommand::Position { ankle_angle_rad } = o.actuator {
            if ankle_angle_rad > max_setpoint {
                max_setpoint = ankle_angle_rad;
            }
        }
        for m in &o.transmit {
            if let Ok(f) = m.encode() {
                s.frames = s.frames.saturating_add(1);
                s.frame_digest = fnv(s.frame_digest, &f.id.raw().to_le_bytes());
                s.frame_digest = fnv(s.frame_digest, f.payload());
            }
            match m {
                Message::Fault(f) if f.transition == FaultTransition::Raised => {
                    s.faults_raised.insert(f.code)
                }
                Message::ParamAck(a) => {
                    let _ = s.acks.push(a.status);
                }
                _ => {}
            }
        }
        let _ = writeln!(out, "{tick} {bits:08x} {} {}", o.phase.raw(), o.state.raw());
    }
    s.final_state = node.state();
    s.max_setpoint_bits = max_setpoint.to_bits();
    let _ = writeln!(
        out,
        "end {} frames {} actuator {:016x} frames {:016x} max_setpoint {:08x}",
        scenario.name, s.frames, s.actuator_digest, s.frame_digest, s.max_setpoint_bits
    );
    Ok(s)
}
