//! The host (node 1): the commands it sends (setup and `Enable` at the first tick, then a
//! schedule, then whatever socketcand clients send) and what it sees on the bus.

use canbus::Frame;
use std::collections::BTreeMap;

use protocol::{Command, CommandKind, DecodeError, Message, ParamId, ParamValue, Target};

use crate::bus_side::BusSide;
use crate::config::{HostCommand, SilConfig, READ_BACK_PARAMS};
use crate::error::TickError;
use crate::firmware_param::param_si;
use crate::history::BoundedLog;
use crate::report::{fault_names, HostReport, NodeParameters};
use crate::side::Side;
use crate::tick::TickTime;

/// The host node's commands and observations.
pub(crate) struct Host {
    /// Sent to the still disabled ankles at the first tick, before the `Enable`.
    setup: Vec<Command>,
    enabled_sent: bool,
    /// Scheduled commands, by time; those before `next` are sent.
    schedule: Vec<HostCommand>,
    next: usize,
    report: HostReport,
    /// Commands put on the bus: (time [s], command).
    commands_sent: BoundedLog<(f64, String)>,
    /// Parameter acknowledgements seen.
    param_acks: BoundedLog<String>,
    /// The value in force of each parameter per node (left, right), from its last
    /// `ParamAck`.
    in_force: [BTreeMap<ParamId, ParamValue>; 2],
}

impl Host {
    /// The host of `config`: its setup commands and its schedule.
    pub fn new(config: &SilConfig) -> Self {
        let mut schedule = config.host_commands.clone();
        schedule.sort_by(|a, b| a.at_s.total_cmp(&b.at_s));
        Host {
            setup: config.setup_commands.clone(),
            enabled_sent: false,
            schedule,
            next: 0,
            report: HostReport::default(),
            commands_sent: BoundedLog::new(config.history_capacity),
            param_acks: BoundedLog::new(config.history_capacity),
            in_force: [BTreeMap::new(), BTreeMap::new()],
        }
    }

    /// Schedule `command` at `t_s` (sent at the first tick at or after it; commands at equal
    /// times keep their order).
    pub fn schedule_at(&mut self, t_s: f64, command: Command) {
        let at = self
            .schedule
            .iter()
            .enumerate()
            .skip(self.next)
            .find(|(_, c)| c.at_s > t_s)
            .map_or(self.schedule.len(), |(i, _)| i);
        self.schedule.insert(at, HostCommand { at_s: t_s, command });
    }

    /// Send the commands due at `t`: at the first tick the setup, `Enable` to every ankle and
    /// a `GetParam` of each of [`READ_BACK_PARAMS`]; the scheduled ones due (each `SetParam`
    /// followed by a `GetParam` of that parameter to the same target); the frames socketcand
    /// clients sent.
    ///
    /// # Errors
    /// A command that does not encode, a frame the bus refuses.
    pub fn send_due(&mut self, t: TickTime, bus: &mut BusSide) -> Result<(), TickError> {
        if !self.enabled_sent {
            self.enabled_sent = true;
            for c in self.setup.clone() {
                self.send(t, bus, &Message::Command(c))?;
            }
            let enable = Message::Command(Command {
                target: Target::Broadcast,
                kind: CommandKind::Enable,
            });
            self.send(t, bus, &enable)?;
            // After the Enable, so that it is read at the next tick as ever.
            for param in READ_BACK_PARAMS {
                self.send(t, bus, &get_param(Target::Broadcast, param))?;
            }
        }
        while let Some(c) = self.schedule.get(self.next).copied() {
            if c.at_s > t.t_s {
                break;
            }
            self.next += 1;
            self.send(t, bus, &Message::Command(c.command))?;
            if let CommandKind::SetParam { param, .. } = c.command.kind {
                self.send(t, bus, &get_param(c.command.target, param))?;
            }
        }
        for f in bus.take_client_frames() {
            self.report.frames_from_clients += 1;
            bus.send_from_host(f, t.t_ns)?;
        }
        Ok(())
    }

    fn send(&mut self, t: TickTime, bus: &mut BusSide, m: &Message) -> Result<(), TickError> {
        let raw = m.encode().map_err(TickError::Encode)?;
        bus.send_from_host(Frame::from(raw), t.t_ns)?;
        self.commands_sent.push((t.t_s, format!("{m:?}")));
        Ok(())
    }

    /// A frame an ankle sent, delivered at `t_ns`, decoded.
    pub fn observe(&mut self, t_ns: u64, m: &Result<Message, DecodeError>) {
        let h = &mut self.report;
        h.frames_seen += 1;
        let Ok(m) = m else {
            h.undecodable_frames += 1;
            return;
        };
        *h.per_class.entry(format!("{:?}", m.class())).or_default() += 1;
        match m {
            Message::Heartbeat(hb) => {
                h.last_heartbeat.insert(
                    format!("{:?}", hb.node),
                    (
                        t_ns as f64 * 1e-9,
                        format!("{:?}", hb.state),
                        fault_names(hb.faults),
                    ),
                );
            }
            Message::Fault(_) => h.fault_events_seen += 1,
            Message::ParamAck(a) => {
                // Every answer carries the value in force, whatever its status.
                if let Some(side) = Side::BOTH.iter().find(|s| s.node() == a.node) {
                    self.in_force[side.index()].insert(a.param, a.value);
                }
                self.param_acks.push(format!(
                    "{:.3} s {:?} {:?} {:?} {}",
                    t_ns as f64 * 1e-9,
                    a.node,
                    a.param,
                    a.status,
                    a.value.to_si()
                ))
            }
            _ => {}
        }
    }

    /// The host's view so far.
    pub fn report(&self) -> HostReport {
        HostReport {
            commands_sent: self.commands_sent.to_vec(),
            param_acks: self.param_acks.to_vec(),
            ..self.report.clone()
        }
    }

    /// The extension profile's parameters `side` last reported.
    pub fn parameters(&self, side: Side) -> NodeParameters {
        let reported = |id: ParamId| self.in_force[side.index()].get(&id).map(|v| param_si(*v));
        NodeParameters::from_reported(
            reported(ParamId::TautAngle),
            reported(ParamId::ExtendedAngle),
            reported(ParamId::PushDuration),
            reported(ParamId::MaxPushRate),
        )
    }

    /// Entries left out of the commands sent and of the parameter acknowledgements.
    pub fn elided(&self) -> (u64, u64) {
        (self.commands_sent.elided(), self.param_acks.elided())
    }
}

/// A `GetParam` of `param` to `target`.
fn get_param(target: Target, param: ParamId) -> Message {
    Message::Command(Command {
        target,
        kind: CommandKind::GetParam { param },
    })
}
