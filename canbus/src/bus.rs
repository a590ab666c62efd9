//! The simulated bus: nodes with transmit queues, arbitration by identifier, frame timing,
//! error confinement and injected faults, driven by simulated time.
//!
//! # Model
//!
//! * Time is simulated, in nanoseconds from 0. [`Bus::send`] queues a frame at a time;
//!   [`Bus::advance_to`] runs the bus up to a time and returns what happened.
//! * The bus becomes idle at the end of a frame's interframe space. At every idle instant at
//!   which frames are pending, each node offers its lowest-identifier ready frame (a controller
//!   with priority-ordered mailboxes; equal identifiers in queue order) and the lowest
//!   identifier of all offers wins. When two nodes offer the same identifier (not allowed on a
//!   real bus) the node attached first wins.
//! * Arbitration instants strictly before the `t_ns` of `advance_to(t_ns)` are decided; a frame
//!   queued at `t_ns` or later takes part in the next call. Frames whose end lies after `t_ns`
//!   are delivered by the call that passes their end.
//! * A frame's length is its bit count on the wire (actual stuff bits by default, or the
//!   worst case, see [`Stuffing`]) including the 3-bit interframe space; duration =
//!   bits / bit rate.
//! * A corrupted transmission occupies the bus for the frame's bits up to the ACK delimiter
//!   (the receivers detect the CRC error there), a 6-bit error flag, an 8-bit error delimiter
//!   and the interframe space: `frame bits + 7` bits. Every receiver sees an error frame
//!   ([`BusEvent::ErrorFrame`]), the transmitter's transmit error counter (TEC) rises by 8,
//!   and the frame stays at the head of its queue for automatic retransmission. A successful
//!   transmission lowers the TEC by 1. TEC ≥ 128: error passive (the node waits 8 extra bit
//!   times, suspend transmission, after each of its transmissions). TEC > 255: bus-off, the
//!   node never transmits again (no automatic recovery; [`Bus::restart`] models the
//!   software-requested recovery) and its queue is discarded.

use std::collections::BTreeMap;

use serde::Serialize;
use thiserror::Error;

use crate::bits::{actual_frame_bits, worst_case_frame_bits};
use crate::fault::{FaultKind, FaultSpec, FrameFilter, Hit, NodeRef};
use crate::frame::Frame;
use crate::rng::SplitMix64;

/// Index of a node attached to a [`Bus`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct NodeHandle(pub usize);

/// How frame lengths are computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Stuffing {
    /// The stuff bits of the frame's actual bit stream (CRC-15 included).
    Actual,
    /// The worst case for the frame's DLC (Davis et al. 2007).
    WorstCase,
}

/// Bus parameters.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BusConfig {
    /// Bit rate [bit/s]. Default 500 000 (the protocol's).
    pub bitrate_bps: u32,
    /// Stuff-bit model. Default [`Stuffing::Actual`].
    pub stuffing: Stuffing,
    /// Seed of the RNG that probabilistic faults draw from. Default 1.
    pub seed: u64,
    /// Frames each node's transmit queue holds. Default 64.
    pub tx_queue_capacity: usize,
}

impl Default for BusConfig {
    fn default() -> Self {
        BusConfig {
            bitrate_bps: protocol::BITRATE_BPS,
            stuffing: Stuffing::Actual,
            seed: 1,
            tx_queue_capacity: 64,
        }
    }
}

/// Fault-confinement state of a node (ISO 11898-1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum ErrorState {
    /// TEC < 128.
    ErrorActive,
    /// 128 ≤ TEC ≤ 255.
    ErrorPassive,
    /// TEC > 255: the node does not transmit.
    BusOff,
}

/// Errors of the bus API.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum BusError {
    /// The bit rate is zero.
    #[error("bit rate must be positive")]
    ZeroBitrate,
    /// A time before the bus's current time.
    #[error("time {t_ns} ns is before the bus's current time {now_ns} ns")]
    TimeWentBack {
        /// The offending time \[ns\].
        t_ns: u64,
        /// The bus's time \[ns\].
        now_ns: u64,
    },
    /// No node with that handle.
    #[error("no node {0:?} on this bus")]
    NoSuchNode(NodeHandle),
    /// A fault names a node that is not attached.
    #[error("fault `{fault}` names node `{node}`, which is not on the bus (nodes: {known})")]
    UnknownNode {
        /// The fault, as text.
        fault: String,
        /// The node reference.
        node: String,
        /// The attached nodes.
        known: String,
    },
    /// A node's transmit queue is full.
    #[error("transmit queue of node `{node}` is full ({capacity} frames)")]
    QueueFull {
        /// The node's name.
        node: String,
        /// Its capacity \[frames\].
        capacity: usize,
    },
}

/// What became of a frame handed to [`Bus::send`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SendOutcome {
    /// Queued; it will arbitrate once ready.
    Queued,
    /// Discarded by a `drop` fault.
    Dropped,
    /// Discarded: the node is bus-off.
    BusOff,
}

/// A frame every receiver got.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Delivered {
    /// The frame.
    pub frame: Frame,
    /// Start of frame \[ns\].
    pub t_start_ns: u64,
    /// End of the interframe space \[ns\] (the receivers have the frame a few bits earlier).
    pub t_end_ns: u64,
    /// The transmitter.
    pub from: NodeHandle,
}

/// Something that happened on the bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum BusEvent {
    /// A frame was transmitted successfully.
    Delivered(Delivered),
    /// A transmission was destroyed by an error; receivers saw an error frame.
    ErrorFrame {
        /// The frame whose transmission failed (it will be retransmitted unless bus-off).
        frame: Frame,
        /// Start of the failed transmission \[ns\].
        t_start_ns: u64,
        /// End of the error frame's interframe space \[ns\].
        t_end_ns: u64,
        /// The transmitter.
        from: NodeHandle,
        /// Its transmit error counter afterwards.
        tec: u16,
    },
    /// A node went bus-off.
    BusOff {
        /// The node.
        node: NodeHandle,
        /// When \[ns\].
        t_ns: u64,
    },
}

impl BusEvent {
    /// The delivered frame, if this is a delivery.
    pub fn delivered(&self) -> Option<&Delivered> {
        match self {
            BusEvent::Delivered(d) => Some(d),
            _ => None,
        }
    }

    /// The time the event completed \[ns\].
    pub fn t_end_ns(&self) -> u64 {
        match self {
            BusEvent::Delivered(d) => d.t_end_ns,
            BusEvent::ErrorFrame { t_end_ns, .. } => *t_end_ns,
            BusEvent::BusOff { t_ns, .. } => *t_ns,
        }
    }
}

/// Per-identifier counters.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct IdStats {
    /// Frames delivered.
    pub frames: u64,
    /// Bits on the wire of the delivered frames \[bits\].
    pub bits: u64,
    /// Failed transmissions (error frames).
    pub errors: u64,
    /// Frames discarded by `drop` faults.
    pub dropped: u64,
    /// Delivery rate over the elapsed time \[Hz\].
    pub rate_hz: f64,
}

/// Per-node counters.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NodeStats {
    /// Name.
    pub name: String,
    /// Number (protocol node field), if any.
    pub number: Option<u8>,
    /// Frames delivered.
    pub tx_frames: u64,
    /// Failed transmissions.
    pub tx_errors: u64,
    /// Frames discarded by `drop` faults or because the node was bus-off.
    pub dropped: u64,
    /// Frames refused because its transmit queue was full ([`BusError::QueueFull`]).
    pub queue_overflows: u64,
    /// Transmit error counter.
    pub tec: u16,
    /// Fault-confinement state.
    pub state: ErrorState,
    /// Frames waiting in its transmit queue.
    pub queued: usize,
}

/// Bus-load statistics over `[0, elapsed_ns]`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BusStats {
    /// Bit rate [bit/s].
    pub bitrate_bps: u32,
    /// Simulated time covered \[ns\].
    pub elapsed_ns: u64,
    /// Time the bus carried frames, error frames or interframe spaces \[ns\].
    pub busy_ns: u64,
    /// `busy_ns / elapsed_ns` (0 when no time elapsed).
    pub load: f64,
    /// Frames delivered.
    pub frames: u64,
    /// Error frames.
    pub error_frames: u64,
    /// Frames discarded by faults.
    pub dropped: u64,
    /// Frames refused by full transmit queues.
    pub queue_overflows: u64,
    /// Per identifier (key: the identifier).
    pub per_id: BTreeMap<u16, IdStats>,
    /// Per node, in attach order.
    pub nodes: Vec<NodeStats>,
}

#[derive(Clone, Debug)]
struct Pending {
    frame: Frame,
    ready_ns: u64,
    seq: u64,
}

#[derive(Clone, Debug)]
struct Node {
    name: String,
    number: Option<u8>,
    queue: Vec<Pending>,
    tec: u16,
    state: ErrorState,
    suspend_until_ns: u64,
    tx_frames: u64,
    tx_errors: u64,
    dropped: u64,
    queue_overflows: u64,
}

#[derive(Clone, Debug)]
struct ActiveFault {
    spec: FaultSpec,
    node: Option<NodeHandle>,
    hits: u32,
}

#[derive(Clone, Copy, Debug)]
enum Source {
    Queue { seq: u64, ready_ns: u64 },
    Babble,
}

#[derive(Clone, Copy, Debug)]
struct InFlight {
    node: NodeHandle,
    frame: Frame,
    source: Source,
    t_start_ns: u64,
    t_end_ns: u64,
    corrupted: bool,
}

/// Payload of babble frames.
pub const BABBLE_DATA: [u8; 8] = [0xBA; 8];

/// A simulated classic CAN bus.
#[derive(Clone, Debug)]
pub struct Bus {
    config: BusConfig,
    nodes: Vec<Node>,
    faults: Vec<ActiveFault>,
    rng: SplitMix64,
    now_ns: u64,
    idle_at_ns: u64,
    in_flight: Option<InFlight>,
    seq: u64,
    busy_ns: u64,
    per_id: BTreeMap<u16, IdStats>,
    frames: u64,
    error_frames: u64,
    dropped: u64,
    queue_overflows: u64,
}

impl Bus {
    /// An empty bus at time 0.
    ///
    /// # Errors
    /// [`BusError::ZeroBitrate`].
    pub fn new(config: BusConfig) -> Result<Self, BusError> {
        if config.bitrate_bps == 0 {
            return Err(BusError::ZeroBitrate);
        }
        Ok(Bus {
            rng: SplitMix64::new(config.seed),
            config,
            nodes: Vec::new(),
            faults: Vec::new(),
            now_ns: 0,
            idle_at_ns: 0,
            in_flight: None,
            seq: 0,
            busy_ns: 0,
            per_id: BTreeMap::new(),
            frames: 0,
            error_frames: 0,
            dropped: 0,
            queue_overflows: 0,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &BusConfig {
        &self.config
    }

    /// The bus's current simulated time \[ns\].
    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    /// Attach a node with a name and optionally a number (for faults that name it).
    pub fn attach(&mut self, name: &str, number: Option<u8>) -> NodeHandle {
        self.nodes.push(Node {
            name: name.to_string(),
            number,
            queue: Vec::new(),
            tec: 0,
            state: ErrorState::ErrorActive,
            suspend_until_ns: 0,
            tx_frames: 0,
            tx_errors: 0,
            dropped: 0,
            queue_overflows: 0,
        });
        NodeHandle(self.nodes.len() - 1)
    }

    /// The node a fault refers to: by name (case-insensitive) or number.
    pub fn find_node(&self, r: &NodeRef) -> Option<NodeHandle> {
        self.nodes
            .iter()
            .position(|n| match r {
                NodeRef::Name(s) => n.name.eq_ignore_ascii_case(s),
                NodeRef::Number(k) => n.number == Some(*k),
            })
            .map(NodeHandle)
    }

    /// A node's name.
    pub fn node_name(&self, node: NodeHandle) -> Option<&str> {
        self.nodes.get(node.0).map(|n| n.name.as_str())
    }

    /// Frames waiting in a node's transmit queue (its capacity is
    /// [`BusConfig::tx_queue_capacity`]).
    pub fn queued_frames(&self, node: NodeHandle) -> Option<usize> {
        self.nodes.get(node.0).map(|n| n.queue.len())
    }

    /// A node's fault-confinement state and transmit error counter.
    pub fn node_error_state(&self, node: NodeHandle) -> Option<(ErrorState, u16)> {
        self.nodes.get(node.0).map(|n| (n.state, n.tec))
    }

    /// Add a fault. Faults act in the order they were added (a frame dropped by one is not
    /// seen by the next).
    ///
    /// # Errors
    /// [`BusError::UnknownNode`] when the fault names a node that is not attached.
    pub fn add_fault(&mut self, spec: FaultSpec) -> Result<(), BusError> {
        let node_ref = match &spec.kind {
            FaultKind::Drop { filter, .. }
            | FaultKind::Corrupt { filter, .. }
            | FaultKind::Delay { filter, .. } => filter.node.as_ref(),
            FaultKind::Babble { node, .. } | FaultKind::BusOff { node } => Some(node),
        };
        let node = match node_ref {
            Some(r) => Some(self.find_node(r).ok_or_else(|| {
                BusError::UnknownNode {
                    fault: spec.to_string(),
                    node: r.to_string(),
                    known: self
                        .nodes
                        .iter()
                        .map(|n| match n.number {
                            Some(k) => format!("{} ({k})", n.name),
                            None => n.name.clone(),
                        })
                        .collect::<Vec<_>>()
                        .join(", "),
                }
            })?),
            None => None,
        };
        self.faults.push(ActiveFault {
            spec,
            node,
            hits: 0,
        });
        Ok(())
    }

    /// Restart a bus-off node (software-requested recovery): TEC 0, error active.
    ///
    /// # Errors
    /// [`BusError::NoSuchNode`].
    pub fn restart(&mut self, node: NodeHandle) -> Result<(), BusError> {
        let n = self
            .nodes
            .get_mut(node.0)
            .ok_or(BusError::NoSuchNode(node))?;
        n.tec = 0;
        n.state = ErrorState::ErrorActive;
        Ok(())
    }

    /// Duration of `bits` bits \[ns\], rounded to the nearest nanosecond.
    pub fn bits_to_ns(&self, bits: u32) -> u64 {
        let bps = u128::from(self.config.bitrate_bps);
        ((u128::from(bits) * 1_000_000_000 + bps / 2) / bps) as u64
    }

    /// Length of `frame` on the wire under this bus's stuffing model \[bits\].
    pub fn frame_bits(&self, frame: &Frame) -> u32 {
        match self.config.stuffing {
            Stuffing::Actual => actual_frame_bits(frame),
            Stuffing::WorstCase => worst_case_frame_bits(frame.dlc()),
        }
    }

    fn matches(
        &self,
        filter: &FrameFilter,
        filter_node: Option<NodeHandle>,
        node: NodeHandle,
        frame: &Frame,
    ) -> bool {
        filter.id.is_none_or(|id| id == frame.id())
            && (filter.node.is_none() || filter_node == Some(node))
    }

    /// Does fault `i` (of kind drop/corrupt with `hit`) hit this frame? Consumes its count and
    /// draws from the RNG only for matching frames.
    fn try_hit(&mut self, i: usize, hit: &Hit) -> bool {
        let Some(f) = self.faults.get(i) else {
            return false;
        };
        if hit.count.is_some_and(|c| f.hits >= c) {
            return false;
        }
        let yes = match hit.prob {
            Some(p) => self.rng.next_f64() < p,
            None => true,
        };
        if yes {
            if let Some(f) = self.faults.get_mut(i) {
                f.hits += 1;
            }
        }
        yes
    }

    /// As [`Self::send`], but a full transmit queue loses the frame, as a controller whose
    /// software sends faster than the bus carries would (counted in the statistics' queue
    /// overflows), instead of failing.
    ///
    /// # Errors
    /// Any other refusal of [`Self::send`].
    pub fn send_lossy(
        &mut self,
        node: NodeHandle,
        frame: Frame,
        t_ns: u64,
    ) -> Result<(), BusError> {
        match self.send(node, frame, t_ns) {
            Ok(_) | Err(BusError::QueueFull { .. }) => Ok(()),
            Err(e) => Err(e),
        }
    }

    /// Queue `frame` for transmission by `node`, ready at `t_ns` (plus any `delay` fault).
    ///
    /// # Errors
    /// [`BusError::NoSuchNode`], [`BusError::TimeWentBack`] when `t_ns` is before
    /// [`Bus::now_ns`], [`BusError::QueueFull`].
    pub fn send(
        &mut self,
        node: NodeHandle,
        frame: Frame,
        t_ns: u64,
    ) -> Result<SendOutcome, BusError> {
        if t_ns < self.now_ns {
            return Err(BusError::TimeWentBack {
                t_ns,
                now_ns: self.now_ns,
            });
        }
        let n = self.nodes.get(node.0).ok_or(BusError::NoSuchNode(node))?;
        if n.state == ErrorState::BusOff {
            self.count_drop(node, &frame);
            return Ok(SendOutcome::BusOff);
        }
        if n.queue.len() >= self.config.tx_queue_capacity {
            let err = BusError::QueueFull {
                node: n.name.clone(),
                capacity: self.config.tx_queue_capacity,
            };
            self.queue_overflows += 1;
            if let Some(n) = self.nodes.get_mut(node.0) {
                n.queue_overflows += 1;
            }
            return Err(err);
        }
        let mut ready_ns = t_ns;
        for i in 0..self.faults.len() {
            let Some(f) = self.faults.get(i) else { break };
            if !f.spec.active_at(t_ns) {
                continue;
            }
            let fault_node = f.node;
            match f.spec.kind.clone() {
                FaultKind::Drop { filter, hit }
                    if self.matches(&filter, fault_node, node, &frame) && self.try_hit(i, &hit) =>
                {
                    self.count_drop(node, &frame);
                    return Ok(SendOutcome::Dropped);
                }
                FaultKind::Delay { filter, delay_ns }
                    if self.matches(&filter, fault_node, node, &frame) =>
                {
                    ready_ns = ready_ns.saturating_add(delay_ns);
                }
                _ => {}
            }
        }
        self.seq += 1;
        let seq = self.seq;
        if let Some(n) = self.nodes.get_mut(node.0) {
            n.queue.push(Pending {
                frame,
                ready_ns,
                seq,
            });
        }
        Ok(SendOutcome::Queued)
    }

    fn count_drop(&mut self, node: NodeHandle, frame: &Frame) {
        self.dropped += 1;
        self.per_id.entry(frame.id()).or_default().dropped += 1;
        if let Some(n) = self.nodes.get_mut(node.0) {
            n.dropped += 1;
        }
    }

    /// Babble window of a node: the babble identifier and the time it starts, if active at or
    /// after `t_ns`.
    fn babble_of(&self, node: NodeHandle, t_ns: u64) -> Option<(u16, u64)> {
        self.faults.iter().find_map(|f| match f.spec.kind {
            FaultKind::Babble { id, .. }
                if f.node == Some(node) && f.spec.until_ns.is_none_or(|u| t_ns < u) =>
            {
                Some((id, f.spec.from_ns.max(t_ns)))
            }
            _ => None,
        })
    }

    /// A node's offer at instant `t_ns`: its best frame ready by then.
    fn offer(&self, h: NodeHandle, t_ns: u64) -> Option<(Frame, Source)> {
        let n = self.nodes.get(h.0)?;
        if n.state == ErrorState::BusOff || n.suspend_until_ns > t_ns {
            return None;
        }
        let mut best: Option<(Frame, Source)> = n
            .queue
            .iter()
            .filter(|p| p.ready_ns <= t_ns)
            .min_by_key(|p| (p.frame.id(), p.seq))
            .map(|p| {
                (
                    p.frame,
                    Source::Queue {
                        seq: p.seq,
                        ready_ns: p.ready_ns,
                    },
                )
            });
        if let Some((id, start)) = self.babble_of(h, t_ns) {
            if start <= t_ns && best.is_none_or(|(f, _)| id < f.id()) {
                let frame = Frame::new(u32::from(id), &BABBLE_DATA).ok()?;
                best = Some((frame, Source::Babble));
            }
        }
        best
    }

    /// Earliest instant ≥ the idle time at which some node has something to send.
    fn next_arbitration(&self) -> Option<u64> {
        let idle = self.idle_at_ns;
        (0..self.nodes.len())
            .filter_map(|i| {
                let n = self.nodes.get(i)?;
                if n.state == ErrorState::BusOff {
                    return None;
                }
                let q = n.queue.iter().map(|p| p.ready_ns).min();
                let b = self.babble_of(NodeHandle(i), idle).map(|(_, s)| s);
                let t = match (q, b) {
                    (Some(a), Some(b)) => a.min(b),
                    (a, b) => a.or(b)?,
                };
                Some(t.max(idle).max(n.suspend_until_ns))
            })
            .min()
    }

    fn corrupts(&mut self, node: NodeHandle, frame: &Frame, t_ns: u64) -> bool {
        let mut hit_any = false;
        for i in 0..self.faults.len() {
            let Some(f) = self.faults.get(i) else { break };
            if !f.spec.active_at(t_ns) {
                continue;
            }
            match f.spec.kind.clone() {
                FaultKind::BusOff { .. } if f.node == Some(node) => hit_any = true,
                FaultKind::Corrupt { filter, hit }
                    if !hit_any && self.matches(&filter, f.node, node, frame) =>
                {
                    hit_any = self.try_hit(i, &hit);
                }
                _ => {}
            }
        }
        hit_any
    }

    fn start_transmission(&mut self, t_ns: u64) -> bool {
        let mut winner: Option<(NodeHandle, Frame, Source)> = None;
        for i in 0..self.nodes.len() {
            let h = NodeHandle(i);
            if let Some((f, s)) = self.offer(h, t_ns) {
                if winner.is_none_or(|(_, wf, _)| f.id() < wf.id()) {
                    winner = Some((h, f, s));
                }
            }
        }
        let Some((node, frame, source)) = winner else {
            return false;
        };
        if let (Source::Queue { seq, .. }, Some(n)) = (source, self.nodes.get_mut(node.0)) {
            n.queue.retain(|p| p.seq != seq);
        }
        let corrupted = self.corrupts(node, &frame, t_ns);
        let bits = self.frame_bits(&frame) + if corrupted { 7 } else { 0 };
        let t_end_ns = t_ns + self.bits_to_ns(bits);
        self.in_flight = Some(InFlight {
            node,
            frame,
            source,
            t_start_ns: t_ns,
            t_end_ns,
            corrupted,
        });
        true
    }

    fn finish(&mut self, tx: InFlight, out: &mut Vec<BusEvent>) {
        self.busy_ns += tx.t_end_ns - tx.t_start_ns;
        self.idle_at_ns = tx.t_end_ns;
        let suspend = self.bits_to_ns(8);
        let bits = u64::from(self.frame_bits(&tx.frame));
        let Some(n) = self.nodes.get_mut(tx.node.0) else {
            return;
        };
        if n.state == ErrorState::ErrorPassive {
            n.suspend_until_ns = tx.t_end_ns + suspend;
        }
        let ids = self.per_id.entry(tx.frame.id()).or_default();
        if tx.corrupted {
            n.tec = n.tec.saturating_add(8);
            n.tx_errors += 1;
            ids.errors += 1;
            self.error_frames += 1;
            out.push(BusEvent::ErrorFrame {
                frame: tx.frame,
                t_start_ns: tx.t_start_ns,
                t_end_ns: tx.t_end_ns,
                from: tx.node,
                tec: n.tec,
            });
            if n.tec > 255 {
                n.state = ErrorState::BusOff;
                self.dropped += n.queue.len() as u64;
                n.dropped += n.queue.len() as u64;
                n.queue.clear();
                out.push(BusEvent::BusOff {
                    node: tx.node,
                    t_ns: tx.t_end_ns,
                });
            } else {
                if n.tec >= 128 {
                    n.state = ErrorState::ErrorPassive;
                    n.suspend_until_ns = tx.t_end_ns + suspend;
                }
                if let Source::Queue { seq, ready_ns } = tx.source {
                    n.queue.push(Pending {
                        frame: tx.frame,
                        ready_ns,
                        seq,
                    });
                }
            }
        } else {
            n.tec = n.tec.saturating_sub(1);
            if n.tec < 128 && n.state == ErrorState::ErrorPassive {
                n.state = ErrorState::ErrorActive;
            }
            n.tx_frames += 1;
            ids.frames += 1;
            ids.bits += bits;
            self.frames += 1;
            out.push(BusEvent::Delivered(Delivered {
                frame: tx.frame,
                t_start_ns: tx.t_start_ns,
                t_end_ns: tx.t_end_ns,
                from: tx.node,
            }));
        }
    }

    /// Run the bus up to simulated time `t_ns`: decide every arbitration instant before `t_ns`
    /// and return the transmissions that ended by `t_ns`, in time order.
    ///
    /// # Errors
    /// [`BusError::TimeWentBack`] when `t_ns` is before [`Bus::now_ns`].
    pub fn advance_to(&mut self, t_ns: u64) -> Result<Vec<BusEvent>, BusError> {
        if t_ns < self.now_ns {
            return Err(BusError::TimeWentBack {
                t_ns,
                now_ns: self.now_ns,
            });
        }
        let mut out = Vec::new();
        loop {
            if let Some(tx) = self.in_flight {
                if tx.t_end_ns > t_ns {
                    break;
                }
                self.in_flight = None;
                self.finish(tx, &mut out);
                continue;
            }
            match self.next_arbitration() {
                Some(s) if s < t_ns => {
                    if !self.start_transmission(s) {
                        // Nothing offered at s (cannot happen: s is when something is ready);
                        // move on rather than loop.
                        self.idle_at_ns = s + 1;
                    }
                }
                _ => break,
            }
        }
        self.now_ns = t_ns;
        Ok(out)
    }

    /// Statistics over `[0, now]`. Time of a frame still in flight is not yet counted.
    pub fn stats(&self) -> BusStats {
        let elapsed_s = self.now_ns as f64 / 1e9;
        let rate = |n: u64| {
            if elapsed_s > 0.0 {
                n as f64 / elapsed_s
            } else {
                0.0
            }
        };
        let per_id = self
            .per_id
            .iter()
            .map(|(id, s)| {
                (
                    *id,
                    IdStats {
                        rate_hz: rate(s.frames),
                        ..s.clone()
                    },
                )
            })
            .collect();
        BusStats {
            bitrate_bps: self.config.bitrate_bps,
            elapsed_ns: self.now_ns,
            busy_ns: self.busy_ns,
            load: if self.now_ns > 0 {
                self.busy_ns as f64 / self.now_ns as f64
            } else {
                0.0
            },
            frames: self.frames,
            error_frames: self.error_frames,
            dropped: self.dropped,
            queue_overflows: self.queue_overflows,
            per_id,
            nodes: self
                .nodes
                .iter()
                .map(|n| NodeStats {
                    name: n.name.clone(),
                    number: n.number,
                    tx_frames: n.tx_frames,
                    tx_errors: n.tx_errors,
                    dropped: n.dropped,
                    queue_overflows: n.queue_overflows,
                    tec: n.tec,
                    state: n.state,
                    queued: n.queue.len(),
                })
                .collect(),
        }
    }
}
