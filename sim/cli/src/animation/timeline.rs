//! The events the page lists as they happen: the walk's own (knee locks, heel strikes, the
//! fall) and, with the firmware in the loop, the ankle nodes' (state and reflex-phase
//! changes, faults, landings, bus-off, host commands such as the emergency stop, injected
//! encoder faults). Steps are numbered from 1 in the text.

use crate::labels::{event_label, failure_label, is_fall, step_label, walk_end_label};
use serde::Serialize;
use sim::stride::walk::Walk;

/// One event at a walk time.
#[derive(Clone, Debug, Serialize)]
pub struct Event {
    /// Walk time \[s\].
    pub t_s: f64,
    /// `knee_lock`, `heel_strike`, `fall` (the walker fell over), `stop` (the walk ended
    /// on another failure, e.g. an impact that could not be solved), `state`, `phase`,
    /// `fault`, `landing`, `bus_off`, `command`, `sensor_fault`.
    pub kind: &'static str,
    /// The ankle node (`Left`, `Right`), for the firmware's events.
    pub side: Option<String>,
    /// The new state or phase (for `state` and `phase`), how the walk ended in words (for
    /// `fall` and `stop`: `labels::walk_end_label`), else empty.
    pub value: String,
    /// What happened, for people.
    pub text: String,
}

/// The walk's own events in time order.
pub fn walk_events(walk: &Walk) -> Vec<Event> {
    let mut out = Vec::new();
    for s in &walk.steps {
        let step = step_label(s.step);
        for e in &s.events {
            let kind = match e.name.as_str() {
                n if n.starts_with("knee_lock:") => "knee_lock",
                "heel_strike" => "heel_strike",
                _ => "event",
            };
            let text = format!("{step}: {}", event_label(&e.name));
            out.push(Event {
                t_s: s.start_t_walk_s + e.t_stride_s,
                kind,
                side: None,
                value: String::new(),
                text,
            });
        }
    }
    if let Some(f) = &walk.failure {
        out.push(Event {
            t_s: f.t_walk_s,
            kind: if is_fall(f.kind) { "fall" } else { "stop" },
            side: None,
            value: walk_end_label(f.kind),
            text: format!(
                "{}: {}: {}",
                step_label(f.step),
                failure_label(f.kind),
                f.detail
            ),
        });
    }
    sorted(out)
}

/// The firmware's events (from its run report) in time order.
pub fn firmware_events(r: &sil::SilReport) -> Vec<Event> {
    let side = |s: sil::Side| Some(format!("{s:?}"));
    let mut out = Vec::new();
    for c in &r.state_history {
        out.push(Event {
            t_s: c.t_s,
            kind: "state",
            side: side(c.side),
            value: c.state.clone(),
            text: format!("{:?} node: state {}", c.side, c.state),
        });
    }
    for c in &r.phase_history {
        let leg = if c.stance { "stance" } else { "swing" };
        out.push(Event {
            t_s: c.t_s,
            kind: "phase",
            side: side(c.side),
            value: c.phase.clone(),
            text: format!("{:?} ankle ({leg}): {}", c.side, c.phase),
        });
    }
    for f in &r.faults {
        let what = if f.raised { "raised" } else { "cleared" };
        out.push(Event {
            t_s: f.t_s,
            kind: "fault",
            side: side(f.side),
            value: f.code.clone(),
            text: format!(
                "{:?} node: fault {} {what} (detail {})",
                f.side, f.code, f.detail
            ),
        });
    }
    for l in &r.landings {
        out.push(Event {
            t_s: l.t_s,
            kind: "landing",
            side: side(l.side),
            value: String::new(),
            text: format!("{:?} foot landed, ankle {:.3} rad", l.side, l.angle_rad),
        });
    }
    for (t_s, node) in &r.bus_off {
        out.push(Event {
            t_s: *t_s,
            kind: "bus_off",
            side: None,
            value: node.clone(),
            text: format!("{node}: bus off"),
        });
    }
    for (t_s, command) in &r.host.commands_sent {
        out.push(Event {
            t_s: *t_s,
            kind: "command",
            side: None,
            value: command.clone(),
            text: format!("host sent {}", command_words(command)),
        });
    }
    for a in &r.sensor_faults_applied {
        out.push(Event {
            t_s: a.t_s,
            kind: "sensor_fault",
            side: side(a.side),
            value: a.kind.to_string(),
            text: format!("{:?} encoder fault: {}", a.side, a.kind),
        });
    }
    sorted(out)
}

/// A host command as the run's report writes it (`Command(Command { target: Broadcast, kind:
/// EmergencyStop })`) shortened to `EmergencyStop to Broadcast`; any other form as it is.
fn command_words(debug: &str) -> String {
    let target = debug
        .split_once("target: ")
        .and_then(|(_, rest)| rest.split(',').next());
    let kind = debug
        .split_once("kind: ")
        .and_then(|(_, rest)| rest.strip_suffix(" })"));
    match (target, kind) {
        (Some(target), Some(kind)) => format!("{kind} to {target}"),
        _ => debug.to_string(),
    }
}

fn sorted(mut events: Vec<Event>) -> Vec<Event> {
    events.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
    events
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_read_as_words() {
        assert_eq!(
            command_words("Command(Command { target: Broadcast, kind: EmergencyStop })"),
            "EmergencyStop to Broadcast"
        );
        assert_eq!(
            command_words(
                "Command(Command { target: Broadcast, kind: GetParam { param: TautAngle } })"
            ),
            "GetParam { param: TautAngle } to Broadcast"
        );
        assert_eq!(command_words("something else"), "something else");
    }
}
