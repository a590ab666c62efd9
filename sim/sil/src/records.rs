//! The nodes' records over a run: the histories of state changes, reflex-phase changes and
//! faults of both nodes, and each node's counters (engagements, releases and by what, fault
//! raises, heel strikes sent, frames queued / dropped / lost), from what each step did.

use firmware::TickOutputs;
use protocol::{FaultTransition, Message, NodeState, ReflexPhase};

use crate::ankle::{AnkleStep, TransmitTally};
use crate::history::BoundedLog;
use crate::report::{FaultRecord, NodeReport, PhaseChange, StateChange};
use crate::side::Side;

/// One node's last state and phase, and its counters.
struct NodeTally {
    last_state: NodeState,
    last_phase: ReflexPhase,
    report: NodeReport,
}

impl NodeTally {
    fn new() -> Self {
        NodeTally {
            last_state: NodeState::Disabled,
            last_phase: ReflexPhase::Inactive,
            report: NodeReport::default(),
        }
    }
}

/// Both nodes' histories and counters.
pub(crate) struct Records {
    state_history: BoundedLog<StateChange>,
    phase_history: BoundedLog<PhaseChange>,
    faults: BoundedLog<FaultRecord>,
    nodes: [NodeTally; 2],
}

impl Records {
    /// Empty records; each history keeps at most `history_capacity` entries.
    pub fn new(history_capacity: usize) -> Self {
        Records {
            state_history: BoundedLog::new(history_capacity),
            phase_history: BoundedLog::new(history_capacity),
            faults: BoundedLog::new(history_capacity),
            nodes: [NodeTally::new(), NodeTally::new()],
        }
    }

    /// Record `side`'s step at `t_s` (`stance`: it was the stance ankle): its receive
    /// backlog, a state change, a phase change (an engagement, a release and by what), the
    /// faults raised or cleared and the heel strikes it sent.
    pub fn observe(&mut self, t_s: f64, side: Side, stance: bool, step: &AnkleStep) {
        let n = &mut self.nodes[side.index()];
        let out: &TickOutputs = &step.outputs;
        n.report.max_rx_backlog = n.report.max_rx_backlog.max(step.rx_backlog);
        if out.state != n.last_state {
            self.state_history.push(StateChange {
                t_s,
                side,
                state: format!("{:?}", out.state),
            });
            n.last_state = out.state;
        }
        if out.phase != n.last_phase {
            let was_loaded = matches!(
                n.last_phase,
                ReflexPhase::Free | ReflexPhase::Push | ReflexPhase::Hold
            );
            if was_loaded && out.phase == ReflexPhase::Swing {
                if step.peer_heel_strike {
                    n.report.releases_by_peer_heel_strike += 1;
                } else {
                    n.report.releases_by_lift_off += 1;
                }
            }
            if n.last_phase == ReflexPhase::Free && out.phase == ReflexPhase::Push {
                n.report.engagements += 1;
            }
            self.phase_history.push(PhaseChange {
                t_s,
                side,
                phase: format!("{:?}", out.phase),
                stance,
            });
            n.last_phase = out.phase;
        }
        for m in out.transmit.iter() {
            match m {
                Message::Fault(f) => {
                    let raised = f.transition == FaultTransition::Raised;
                    if raised {
                        *n.report
                            .fault_raises
                            .entry(format!("{:?}", f.code))
                            .or_default() += 1;
                    }
                    self.faults.push(FaultRecord {
                        t_s,
                        side,
                        code: format!("{:?}", f.code),
                        raised,
                        detail: f.detail,
                    });
                }
                Message::HeelStrike(_) => n.report.heel_strikes_sent += 1,
                _ => {}
            }
        }
    }

    /// Count what became of `side`'s frames on the bus.
    pub fn count_transmit(&mut self, side: Side, tally: TransmitTally) {
        let r = &mut self.nodes[side.index()].report;
        r.frames_queued += tally.queued;
        r.frames_dropped += tally.dropped;
        r.frames_lost_at_bus += tally.lost_at_bus;
    }

    /// `side`'s counters (the fields the records keep; the rest at their defaults).
    pub fn node_report(&self, side: Side) -> NodeReport {
        self.nodes[side.index()].report.clone()
    }

    /// The node-state changes.
    pub fn state_history(&self) -> &BoundedLog<StateChange> {
        &self.state_history
    }

    /// The reflex-phase changes.
    pub fn phase_history(&self) -> &BoundedLog<PhaseChange> {
        &self.phase_history
    }

    /// The faults raised or cleared.
    pub fn faults(&self) -> &BoundedLog<FaultRecord> {
        &self.faults
    }
}
