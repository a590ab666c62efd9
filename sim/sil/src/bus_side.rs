//! The bus side of a firmware-in-the-loop run: the simulated CAN bus with the host attached,
//! the candump log and the socketcand server that see every event, and the bus's own records
//! (frames delivered, bus-off events).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use canbus::candump::CandumpWriter;
use canbus::socketcand::{ServerConfig, SocketcandServer};
use canbus::{
    Bus, BusConfig, BusError, BusEvent, ErrorState, FaultSpec, Frame, NodeHandle, SendOutcome,
};
use protocol::NodeId;

use crate::error::{SilError, TickError};
use crate::frames::FrameLog;
use crate::history::BoundedLog;
use crate::report::SocketcandReport;
use crate::side::Side;

/// Longest wait for the socketcand server to write out its clients' queues at the end of a
/// walk.
pub(crate) const SERVER_FLUSH_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(5);

/// The bus, its host node, its outputs and its records.
pub(crate) struct BusSide {
    bus: Bus,
    host: NodeHandle,
    candump: Option<CandumpWriter<BufWriter<File>>>,
    server: Option<SocketcandServer>,
    frames_delivered: u64,
    /// Bus-off events: (time [s], node name).
    bus_off: BoundedLog<(f64, String)>,
    /// The events kept in memory, when asked ([`BusSide::keep_frames`]).
    frame_log: Option<FrameLog>,
}

impl BusSide {
    /// A bus with the host (node 1) attached; `history_capacity` bounds the bus-off record.
    ///
    /// # Errors
    /// [`SilError::Bus`] when the bus refuses its configuration.
    pub fn new(config: &BusConfig, history_capacity: usize) -> Result<Self, SilError> {
        let mut bus = Bus::new(config.clone())?;
        let host = bus.attach("host", Some(NodeId::Host.raw()));
        Ok(BusSide {
            bus,
            host,
            candump: None,
            server: None,
            frames_delivered: 0,
            bus_off: BoundedLog::new(history_capacity),
            frame_log: None,
        })
    }

    /// Keep the first `max_frames` bus events from now on in memory, as a candump log would
    /// record them.
    pub fn keep_frames(&mut self, max_frames: usize) {
        self.frame_log = Some(FrameLog::new(max_frames));
    }

    /// The events kept ([`BusSide::keep_frames`]), taken out (`None` if none were asked for).
    pub fn take_frame_log(&mut self) -> Option<FrameLog> {
        self.frame_log.take()
    }

    /// Attach one ankle's node, named and numbered as the protocol's.
    pub fn attach_ankle(&mut self, side: Side) -> NodeHandle {
        self.bus.attach(side.bus_name(), Some(side.node().raw()))
    }

    /// Inject the faults (after every node is attached: they name nodes).
    ///
    /// # Errors
    /// [`SilError::Bus`] for a fault the bus refuses (an unknown node, say).
    pub fn add_faults(&mut self, faults: &[FaultSpec]) -> Result<(), SilError> {
        for f in faults {
            self.bus.add_fault(f.clone())?;
        }
        Ok(())
    }

    /// Write every bus event to a candump log at `candump`, and serve the bus over
    /// socketcand on `socketcand`, each if given; the server takes frames from its clients
    /// only with `allow_send`.
    ///
    /// # Errors
    /// [`SilError::Candump`] when the log cannot be created, [`SilError::Socketcand`] when
    /// the server cannot bind.
    pub fn open_outputs(
        &mut self,
        candump: Option<&Path>,
        socketcand: Option<&str>,
        allow_send: bool,
    ) -> Result<(), SilError> {
        if let Some(path) = candump {
            let file = BufWriter::new(File::create(path)?);
            self.candump = Some(CandumpWriter::new(file, "vcan0", 0));
        }
        if let Some(addr) = socketcand {
            self.server = Some(SocketcandServer::bind(
                addr,
                ServerConfig {
                    allow_send,
                    ..ServerConfig::default()
                },
            )?);
        }
        Ok(())
    }

    /// Run the bus up to `t_ns`: every event goes to the candump log, every delivered frame
    /// to the socketcand server, bus-off events to the record. The events, for routing.
    ///
    /// # Errors
    /// The bus's or the log's error.
    pub fn advance_to(&mut self, t_ns: u64) -> Result<Vec<BusEvent>, TickError> {
        let events = self.bus.advance_to(t_ns)?;
        for ev in &events {
            if let Some(w) = self.candump.as_mut() {
                w.write_event(ev)?;
            }
            if let Some(log) = self.frame_log.as_mut() {
                log.push(ev);
            }
            match ev {
                BusEvent::Delivered(d) => {
                    self.frames_delivered += 1;
                    if let Some(s) = &self.server {
                        s.publish(&d.frame, d.t_end_ns)?;
                    }
                }
                BusEvent::BusOff { node, t_ns } => {
                    let name = self.bus.node_name(*node).unwrap_or("?").to_string();
                    self.bus_off.push((*t_ns as f64 * 1e-9, name));
                }
                BusEvent::ErrorFrame { .. } => {}
            }
        }
        Ok(events)
    }

    /// The host's node.
    pub fn host(&self) -> NodeHandle {
        self.host
    }

    /// Queue a frame from the host at `t_ns` (a full host queue loses it, as a real
    /// controller would).
    ///
    /// # Errors
    /// Any other refusal of the bus.
    pub fn send_from_host(&mut self, frame: Frame, t_ns: u64) -> Result<(), TickError> {
        self.bus
            .send_lossy(self.host, frame, t_ns)
            .map_err(TickError::Bus)
    }

    /// Queue a frame from `node` at `t_ns`.
    ///
    /// # Errors
    /// The bus's refusal.
    pub fn send(
        &mut self,
        node: NodeHandle,
        frame: Frame,
        t_ns: u64,
    ) -> Result<SendOutcome, BusError> {
        self.bus.send(node, frame, t_ns)
    }

    /// Frames socketcand clients sent since the last call.
    pub fn take_client_frames(&self) -> Vec<Frame> {
        self.server
            .as_ref()
            .map(SocketcandServer::take_inbound)
            .unwrap_or_default()
    }

    /// `node` is bus-off: its controller takes no part in the bus.
    pub fn is_bus_off(&self, node: NodeHandle) -> bool {
        matches!(
            self.bus.node_error_state(node),
            Some((ErrorState::BusOff, _))
        )
    }

    /// `node`'s fault-confinement state and transmit error counter, as its controller's
    /// status register would show them (error-active and 0 for an unknown node).
    pub fn error_state(&self, node: NodeHandle) -> (canbus::ErrorState, u16) {
        self.bus
            .node_error_state(node)
            .unwrap_or((canbus::ErrorState::ErrorActive, 0))
    }

    /// Room left in `node`'s transmit queue [frames].
    pub fn tx_room(&self, node: NodeHandle) -> usize {
        self.bus
            .config()
            .tx_queue_capacity
            .saturating_sub(self.bus.queued_frames(node).unwrap_or(0))
    }

    /// The bus (read-only: statistics, node error states).
    pub fn bus(&self) -> &Bus {
        &self.bus
    }

    /// The live socketcand server's address, if one runs.
    pub fn socketcand_addr(&self) -> Option<std::net::SocketAddr> {
        self.server.as_ref().map(SocketcandServer::local_addr)
    }

    /// Wait until a socketcand client is in rawmode, at most `timeout`: whether one is
    /// (`None` when no server runs).
    pub fn wait_for_socketcand_client(&self, timeout: std::time::Duration) -> Option<bool> {
        self.server.as_ref().map(|s| s.wait_for_client(timeout))
    }

    /// Frames delivered so far.
    pub fn frames_delivered(&self) -> u64 {
        self.frames_delivered
    }

    /// The bus-off record.
    pub fn bus_off(&self) -> &BoundedLog<(f64, String)> {
        &self.bus_off
    }

    /// The socketcand server's counters, if one runs.
    pub fn socketcand_report(&self) -> Option<SocketcandReport> {
        self.server.as_ref().map(|s| {
            let st = s.stats();
            SocketcandReport {
                clients_accepted: st.clients_accepted,
                frames_sent: st.frames_sent,
                frames_dropped: st.frames_dropped,
                frames_received: st.frames_received,
                sends_refused: st.sends_refused,
                clients_dropped_idle: st.clients_idle,
                clients_dropped_stalled: st.clients_stalled,
                clients_refused: st.clients_refused,
            }
        })
    }

    /// Flush the candump log, let the server write out what its clients are still owed (at
    /// most [`SERVER_FLUSH_TIMEOUT`]; a client that stops reading is given up within 100 ms)
    /// and stop it.
    ///
    /// # Errors
    /// [`SilError::Candump`] when the log cannot be flushed.
    pub fn close(&mut self) -> Result<(), SilError> {
        if let Some(w) = self.candump.take() {
            w.finish()?.flush()?;
        }
        if let Some(mut s) = self.server.take() {
            // A walk can end within a few milliseconds of its first frames, before the
            // client threads' next poll: without this their last frames were lost.
            s.flush(SERVER_FLUSH_TIMEOUT);
            s.shutdown();
        }
        Ok(())
    }
}
