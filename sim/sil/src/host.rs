//! The host (node 1): the commands it sends (setup and `Enable` at the first tick, then a
//! schedule, then whatever socketcand clients send) and what it sees on the bus.

use canbus::Frame;
use protocol::{Command, CommandKind, DecodeError, Message, Target};
use sim::control::ControlError;

use crate::bus_side::BusSide;
use crate::config::{HostCommand, SilConfig};
use crate::error::control_error;
use crate::history::BoundedLog;
use crate::report::{fault_names, HostReport};
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

    /// Send the commands due at `t`: at the first tick the setup and `Enable` to every
    /// ankle; the scheduled ones due; the frames socketcand clients sent.
    ///
    /// # Errors
    /// A command that does not encode, a frame the bus refuses.
    pub fn send_due(&mut self, t: TickTime, bus: &mut BusSide) -> Result<(), ControlError> {
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
        }
        while let Some(c) = self.schedule.get(self.next).copied() {
            if c.at_s > t.t_s {
                break;
            }
            self.next += 1;
            self.send(t, bus, &Message::Command(c.command))?;
        }
        for f in bus.take_client_frames() {
            self.report.frames_from_clients += 1;
            bus.send_from_host(f, t.t_ns)?;
        }
        Ok(())
    }

    fn send(&mut self, t: TickTime, bus: &mut BusSide, m: &Message) -> Result<(), ControlError> {
        let raw = m.encode().map_err(|e| control_error(format!("{e:?}")))?;
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
            Message::ParamAck(a) => self.param_acks.push(format!(
                "{:.3} s {:?} {:?} {:?} {}",
                t_ns as f64 * 1e-9,
                a.node,
                a.param,
                a.status,
                a.value.to_si()
            )),
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

    /// Entries left out of the commands sent and of the parameter acknowledgements.
    pub fn elided(&self) -> (u64, u64) {
        (self.commands_sent.elided(), self.param_acks.elided())
    }
}
