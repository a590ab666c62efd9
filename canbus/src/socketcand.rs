//! A socketcand-protocol server (<https://github.com/linux-can/socketcand>, "rawmode"),
//! enough for python-can's `socketcand` interface.
//!
//! ```text
//! server: < hi >
//! client: < open vcan0 >          server: < ok >     (another channel: < error ... >)
//! client: < rawmode >             server: < ok >
//! server: < frame 072 1700000000.012345 0102030405060708 >   (one per delivered frame)
//! client: < send 42 6 1 0 0 0 0 0 >                          (id, length, bytes; all hex)
//! client: < echo >                server: < echo >
//! ```
//!
//! **Read-only unless told otherwise.** A monitor needs no write access, and a frame sent into
//! the simulated bus is a command to the walker (a spoofed heel strike or an
//! `EmergencyStop_ALL` makes it fall): `send` is answered `< error read-only bus ... >` and
//! counted in [`ServerStats::sends_refused`] unless [`ServerConfig::allow_send`] is set (the
//! `--socketcand-allow-send` flag of `walker sil` and `canbus-demo`: the server is then a
//! control channel for any local process).
//!
//! Frames are queued per client in a bounded queue (frames that do not fit are counted in
//! [`ServerStats::frames_dropped`], never blocking the simulation); frames sent by clients are
//! queued in a bounded inbound queue that the simulation drains with
//! [`SocketcandServer::take_inbound`] and puts on the bus as a host node. python-can reads the
//! `< ok >` of `rawmode` with a single `recv` and compares it exactly, so the server waits
//! [`ServerConfig::rawmode_grace`] before the first frame. Only standard identifiers; error
//! frames are not sent (socketcand's rawmode has no form python-can parses).
//!
//! Bounds, whatever the clients do:
//! * at most [`ServerConfig::max_clients`] clients at once. A client that has not opened a bus
//!   and entered rawmode within [`ServerConfig::open_timeout`] is dropped
//!   ([`ServerStats::clients_idle`]); when the server is full, a new connection takes the place
//!   of the oldest client not yet in rawmode (also counted there), so idle connections never
//!   lock a monitor out; failing that, of the oldest client in rawmode whose queue is full
//!   (it does not read: [`ServerStats::clients_stalled`]). Evicted clients are closed, told
//!   `< error dropped to make room for a new client >` when their socket has room for it. Only when every client is in rawmode
//!   and reading is a new one answered
//!   `< error too many clients ... >`, closed and counted in [`ServerStats::clients_refused`];
//! * per client, memory for at most [`ServerConfig::client_queue_frames`] queued frames (taken
//!   as needed, not up front), 64 KiB of output and 64 KiB of unparsed input; a client whose
//!   output makes no progress for [`ServerConfig::write_timeout`] is disconnected
//!   ([`ServerStats::clients_stalled`]), and so is one whose frame queue stays full (every
//!   frame published for it lost) for as long. The kernel's send buffer of each client socket
//!   is set to [`ServerConfig::socket_send_buffer_bytes`], so a client that stops reading
//!   stalls the output after at most that much (plus its own receive buffer) instead of the
//!   4 MiB the kernel's autotuning allows; [`ServerConfig::memory_bound_bytes`] sums it up;
//! * sockets are non-blocking: no thread ever waits on a client, finished clients are joined
//!   and forgotten at once, and [`SocketcandServer::shutdown`] (also run on drop) returns within
//!   a few polls of 10 ms.

use std::collections::VecDeque;
use std::fmt::Write as _;
use std::io::{self, ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream, ToSocketAddrs};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use thiserror::Error;

use crate::frame::Frame;
use crate::timestamp::{stamp_ns, TimestampOverflow};

/// Server parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct ServerConfig {
    /// The one channel served (`< open CHANNEL >`). Default `vcan0`.
    pub channel: String,
    /// Clients served at once; more are refused. Default 8.
    pub max_clients: usize,
    /// Frames queued per client before new ones are dropped (memory is taken as the queue
    /// fills, 24 bytes a frame). Default 65536.
    pub client_queue_frames: usize,
    /// Frames from clients queued before new ones are dropped. Default 1024.
    pub inbound_queue_frames: usize,
    /// Wait after the `rawmode` answer before the first frame. Default 200 ms.
    pub rawmode_grace: Duration,
    /// Added to simulated time in frame timestamps [ns since the Unix epoch]. Default 0.
    pub origin_ns: u64,
    /// A client whose pending output makes no progress for this long (it does not read), or
    /// whose frame queue stays full this long, is disconnected. Default 5 s.
    pub write_timeout: Duration,
    /// A client that has not entered rawmode (`< open CHANNEL >`, `< rawmode >`) this long
    /// after connecting is disconnected. Default 3 s.
    pub open_timeout: Duration,
    /// Frames from clients (`< send ... >`) are put on the bus; otherwise they are refused
    /// and the server is read-only. Default false.
    pub allow_send: bool,
    /// The kernel send buffer of each client socket (`SO_SNDBUF`) \[bytes\]: how much a client
    /// that stopped reading can be sent before its output stalls. Default 32 KiB.
    pub socket_send_buffer_bytes: usize,
}

impl Default for ServerConfig {
    fn default() -> Self {
        ServerConfig {
            channel: "vcan0".into(),
            max_clients: 8,
            client_queue_frames: 65_536,
            inbound_queue_frames: 1024,
            rawmode_grace: Duration::from_millis(200),
            origin_ns: 0,
            write_timeout: Duration::from_secs(5),
            open_timeout: Duration::from_secs(3),
            allow_send: false,
            socket_send_buffer_bytes: 32 * 1024,
        }
    }
}

/// Output bytes a client may have pending; no command is read from it beyond this.
const OUT_LIMIT_BYTES: usize = 64 * 1024;
/// Unparsed input kept per client; a longer text without a complete command is discarded.
const INPUT_LIMIT_BYTES: usize = 64 * 1024;
/// Bytes read from a client at once.
const READ_CHUNK_BYTES: usize = 4096;
/// Stack of a client thread [bytes].
const CLIENT_STACK_BYTES: usize = 256 * 1024;
/// Characters of a bad command echoed in the error answer.
const ECHO_CHARS: usize = 64;
/// Longest wait of [`SocketcandServer::wait_for_client`] and [`SocketcandServer::flush`].
const MAX_WAIT: Duration = Duration::from_secs(7 * 86_400);
/// [`SocketcandServer::flush`] gives up when no frame was written for this long.
const FLUSH_STALL: Duration = Duration::from_millis(100);

impl ServerConfig {
    /// An upper bound of the memory the clients hold at once \[bytes\]: per client, its frame
    /// queue (at most twice its capacity in frames, as a growing `VecDeque`), its output and
    /// input buffers (each at most twice its limit) and its thread's stack, times
    /// [`ServerConfig::max_clients`].
    pub fn memory_bound_bytes(&self) -> usize {
        let queue = self
            .client_queue_frames
            .saturating_mul(2 * std::mem::size_of::<(Frame, u64)>());
        let buffers = 2 * (OUT_LIMIT_BYTES + ECHO_CHARS + 256) + 2 * INPUT_LIMIT_BYTES;
        queue
            .saturating_add(buffers + READ_CHUNK_BYTES + CLIENT_STACK_BYTES)
            .saturating_mul(self.max_clients)
    }
}

/// Server errors.
#[derive(Debug, Error)]
pub enum ServerError {
    /// Binding the listening socket failed.
    #[error("binding the socketcand server to {addr}: {source}")]
    Bind {
        /// The address.
        addr: String,
        /// Why.
        source: io::Error,
    },
    /// Another socket operation failed.
    #[error("socketcand server socket: {0}")]
    Io(#[from] io::Error),
    /// Refused: the server listens on loopback addresses only.
    #[error("refusing to listen on {0}: the simulated bus is served on loopback only")]
    NotLoopback(SocketAddr),
}

/// Counters of a running server.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ServerStats {
    /// Clients accepted so far.
    pub clients_accepted: u64,
    /// Frames written to clients.
    pub frames_sent: u64,
    /// Frames dropped because a client's queue was full.
    pub frames_dropped: u64,
    /// Frames received from clients.
    pub frames_received: u64,
    /// Client commands that could not be parsed.
    pub bad_commands: u64,
    /// Connections refused (too many clients, or no thread for one).
    pub clients_refused: u64,
    /// Clients disconnected because their output made no progress for
    /// [`ServerConfig::write_timeout`].
    pub clients_stalled: u64,
    /// Frames from clients dropped because the inbound queue was full.
    pub inbound_dropped: u64,
    /// Clients disconnected because they had not entered rawmode within
    /// [`ServerConfig::open_timeout`], or to make room for a new client.
    pub clients_idle: u64,
    /// `send` commands refused because the server is read-only.
    pub sends_refused: u64,
}

#[derive(Default)]
struct Counters {
    clients_accepted: AtomicU64,
    frames_sent: AtomicU64,
    frames_dropped: AtomicU64,
    frames_received: AtomicU64,
    bad_commands: AtomicU64,
    clients_refused: AtomicU64,
    clients_stalled: AtomicU64,
    inbound_dropped: AtomicU64,
    clients_idle: AtomicU64,
    sends_refused: AtomicU64,
}

fn bump(c: &AtomicU64) {
    c.fetch_add(1, Ordering::Relaxed);
}

/// What a client's thread shares with the server.
#[derive(Default)]
struct ClientState {
    /// In rawmode: frames are queued for it.
    rawmode: AtomicBool,
    /// Frames to send, with their timestamps [ns since the Unix epoch].
    queue: Mutex<VecDeque<(Frame, u64)>>,
    /// Output not yet written (frames taken from the queue, answers).
    out_pending: AtomicBool,
    /// Told to leave (its place was given to a new client).
    evicted: AtomicBool,
    /// When its queue was last found full by [`SocketcandServer::publish`] with no room made
    /// since (`None` while frames fit).
    full_since: Mutex<Option<Instant>>,
}

struct Client {
    state: Arc<ClientState>,
    thread: JoinHandle<()>,
}

impl Client {
    fn connected(&self) -> bool {
        !self.thread.is_finished()
    }
}

struct Shared {
    config: ServerConfig,
    stop: AtomicBool,
    clients: Mutex<Vec<Client>>,
    inbound: Mutex<VecDeque<Frame>>,
    counters: Counters,
}

/// A running socketcand server.
pub struct SocketcandServer {
    addr: SocketAddr,
    shared: Arc<Shared>,
    acceptor: Option<JoinHandle<()>>,
}

const POLL: Duration = Duration::from_millis(10);

impl SocketcandServer {
    /// Listen on `addr` (a loopback address; port 0 picks a free port).
    ///
    /// # Errors
    /// [`ServerError::Bind`], [`ServerError::NotLoopback`], [`ServerError::Io`].
    pub fn bind<A: ToSocketAddrs + std::fmt::Display>(
        addr: A,
        config: ServerConfig,
    ) -> Result<Self, ServerError> {
        let addrs: Vec<SocketAddr> = addr
            .to_socket_addrs()
            .map_err(|source| ServerError::Bind {
                addr: addr.to_string(),
                source,
            })?
            .collect();
        if let Some(a) = addrs.iter().find(|a| !a.ip().is_loopback()) {
            return Err(ServerError::NotLoopback(*a));
        }
        let listener = TcpListener::bind(&addrs[..]).map_err(|source| ServerError::Bind {
            addr: addr.to_string(),
            source,
        })?;
        let local = listener.local_addr()?;
        listener.set_nonblocking(true)?;
        let shared = Arc::new(Shared {
            config,
            stop: AtomicBool::new(false),
            clients: Mutex::new(Vec::new()),
            inbound: Mutex::new(VecDeque::new()),
            counters: Counters::default(),
        });
        let s2 = Arc::clone(&shared);
        let acceptor = std::thread::Builder::new()
            .name("socketcand-accept".into())
            .spawn(move || accept_loop(&listener, &s2))?;
        Ok(SocketcandServer {
            addr: local,
            shared,
            acceptor: Some(acceptor),
        })
    }

    /// The address it listens on.
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// Queue a delivered frame, stamped at simulated time `t_ns` (plus
    /// [`ServerConfig::origin_ns`]), for every client in rawmode. Never waits on a client: a
    /// full queue loses the frame, counted in [`ServerStats::frames_dropped`].
    ///
    /// # Errors
    /// [`TimestampOverflow`] when the origin plus `t_ns` does not fit (nothing is queued).
    pub fn publish(&self, frame: &Frame, t_ns: u64) -> Result<(), TimestampOverflow> {
        let t = stamp_ns(self.shared.config.origin_ns, t_ns)?;
        let clients = lock(&self.shared.clients);
        for c in clients.iter() {
            if !c.state.rawmode.load(Ordering::Acquire) || !c.connected() {
                continue;
            }
            let mut q = lock(&c.state.queue);
            let mut full_since = lock(&c.state.full_since);
            if q.len() < self.shared.config.client_queue_frames {
                q.push_back((*frame, t));
                *full_since = None;
            } else {
                bump(&self.shared.counters.frames_dropped);
                full_since.get_or_insert_with(Instant::now);
            }
        }
        Ok(())
    }

    /// Frames clients sent since the last call, in arrival order.
    pub fn take_inbound(&self) -> Vec<Frame> {
        lock(&self.shared.inbound).drain(..).collect()
    }

    /// Number of connected clients in rawmode.
    pub fn rawmode_clients(&self) -> usize {
        lock(&self.shared.clients)
            .iter()
            .filter(|c| c.state.rawmode.load(Ordering::Acquire) && c.connected())
            .count()
    }

    /// Number of connected clients (finished ones are forgotten within a poll of 10 ms).
    pub fn connected_clients(&self) -> usize {
        lock(&self.shared.clients)
            .iter()
            .filter(|c| c.connected())
            .count()
    }

    /// Wait until at least one client is in rawmode and past its grace time, at most
    /// `timeout` (at most a week). Returns whether one is.
    pub fn wait_for_client(&self, timeout: Duration) -> bool {
        let start = Instant::now();
        let timeout = timeout.min(MAX_WAIT);
        while start.elapsed() < timeout {
            if self.rawmode_clients() > 0 {
                std::thread::sleep(self.shared.config.rawmode_grace);
                return true;
            }
            std::thread::sleep(POLL);
        }
        false
    }

    /// Wait until every client's queue is written out, at most `timeout` (at most a week) and
    /// no longer than 100 ms without a frame written (a client that does not read is not
    /// waited for). Returns whether everything was written.
    pub fn flush(&self, timeout: Duration) -> bool {
        let start = Instant::now();
        let timeout = timeout.min(MAX_WAIT);
        let sent = || self.shared.counters.frames_sent.load(Ordering::Relaxed);
        let (mut last_sent, mut last_change) = (sent(), start);
        loop {
            if self.all_written() {
                return true;
            }
            let now = Instant::now();
            if now.duration_since(start) >= timeout {
                return false;
            }
            let s = sent();
            if s != last_sent {
                (last_sent, last_change) = (s, now);
            } else if now.duration_since(last_change) >= FLUSH_STALL {
                return false;
            }
            std::thread::sleep(POLL);
        }
    }

    fn all_written(&self) -> bool {
        lock(&self.shared.clients).iter().all(|c| {
            !c.connected()
                || !c.state.rawmode.load(Ordering::Acquire)
                || (lock(&c.state.queue).is_empty() && !c.state.out_pending.load(Ordering::Acquire))
        })
    }

    /// Counters so far.
    pub fn stats(&self) -> ServerStats {
        let c = &self.shared.counters;
        let get = |a: &AtomicU64| a.load(Ordering::Relaxed);
        ServerStats {
            clients_accepted: get(&c.clients_accepted),
            frames_sent: get(&c.frames_sent),
            frames_dropped: get(&c.frames_dropped),
            frames_received: get(&c.frames_received),
            bad_commands: get(&c.bad_commands),
            clients_refused: get(&c.clients_refused),
            clients_stalled: get(&c.clients_stalled),
            inbound_dropped: get(&c.inbound_dropped),
            clients_idle: get(&c.clients_idle),
            sends_refused: get(&c.sends_refused),
        }
    }

    /// Stop accepting, close every client and join the threads (none waits on a socket, so
    /// this takes a few polls of 10 ms whatever the clients do).
    pub fn shutdown(&mut self) {
        self.shared.stop.store(true, Ordering::Release);
        if let Some(a) = self.acceptor.take() {
            let _ = a.join();
        }
        let clients: Vec<Client> = lock(&self.shared.clients).drain(..).collect();
        for c in clients {
            let _ = c.thread.join();
        }
    }
}

impl Drop for SocketcandServer {
    fn drop(&mut self) {
        self.shutdown();
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Join and forget the clients whose threads have finished.
fn reap(shared: &Shared) {
    let finished: Vec<Client> = {
        let mut clients = lock(&shared.clients);
        if clients.iter().all(Client::connected) {
            return;
        }
        let (done, live): (Vec<Client>, Vec<Client>) =
            clients.drain(..).partition(|c| !c.connected());
        *clients = live;
        done
    };
    for c in finished {
        let _ = c.thread.join();
    }
}

fn refuse(mut stream: TcpStream, why: &str, shared: &Shared) {
    bump(&shared.counters.clients_refused);
    if stream.set_nonblocking(true).is_ok() {
        let _ = stream.write(format!("< error {why} >").as_bytes());
    }
}

fn admit(stream: TcpStream, shared: &Arc<Shared>) {
    let mut clients = lock(&shared.clients);
    let max = shared.config.max_clients;
    if clients.len() >= max {
        // The oldest client not yet in rawmode gives up its place, else the oldest in rawmode
        // that is not reading (its queue full: every frame for it lost), so neither idle nor
        // stalled clients lock a monitor out; one already leaving is not counted twice.
        let leaving = |c: &Client| c.state.evicted.load(Ordering::Acquire);
        let idle = clients
            .iter()
            .position(|c| !c.state.rawmode.load(Ordering::Acquire) && !leaving(c));
        let stalled = || {
            clients
                .iter()
                .position(|c| !leaving(c) && lock(&c.state.full_since).is_some())
        };
        let evict = match idle {
            Some(pos) => Some((pos, &shared.counters.clients_idle)),
            None => stalled().map(|pos| (pos, &shared.counters.clients_stalled)),
        };
        if let Some((pos, counter)) = evict {
            if let Some(old) = clients.get(pos) {
                old.state.evicted.store(true, Ordering::Release);
                bump(counter);
            }
            let old = clients.remove(pos);
            // Its thread sees the flag within a poll and closes; the acceptor's reap would
            // join it, but it is no longer listed: join it here, off the lock.
            drop(clients);
            let _ = old.thread.join();
            clients = lock(&shared.clients);
        }
    }
    if clients.len() >= max {
        drop(clients);
        refuse(
            stream,
            &format!("too many clients ({max} connected, the limit)"),
            shared,
        );
        return;
    }
    let state = Arc::new(ClientState::default());
    let (s2, st2) = (Arc::clone(shared), Arc::clone(&state));
    let spawned = std::thread::Builder::new()
        .name("socketcand-client".into())
        .stack_size(CLIENT_STACK_BYTES)
        .spawn(move || serve_client(stream, &s2, &st2));
    match spawned {
        Ok(thread) => {
            bump(&shared.counters.clients_accepted);
            clients.push(Client { state, thread });
        }
        // the stream went with the closure and is closed
        Err(_) => bump(&shared.counters.clients_refused),
    }
}

fn accept_loop(listener: &TcpListener, shared: &Arc<Shared>) {
    while !shared.stop.load(Ordering::Acquire) {
        reap(shared);
        match listener.accept() {
            Ok((stream, _)) => admit(stream, shared),
            Err(_) => std::thread::sleep(POLL),
        }
    }
}

/// Parse `send ID LEN B...` (the text between `<` and `>`, already split in words).
fn parse_send(words: &[&str]) -> Result<Frame, String> {
    let [id, len, bytes @ ..] = words else {
        return Err("send needs an identifier and a length".into());
    };
    if id.len() > 3 {
        return Err(format!(
            "identifier {id}: only 11-bit identifiers are served"
        ));
    }
    let id = u32::from_str_radix(id, 16).map_err(|_| format!("identifier {id} is not hex"))?;
    let len = usize::from_str_radix(len, 16).map_err(|_| format!("length {len} is not hex"))?;
    if len != bytes.len() {
        return Err(format!("length {len} but {} data bytes", bytes.len()));
    }
    let data = bytes
        .iter()
        .map(|b| u8::from_str_radix(b, 16).map_err(|_| format!("data byte {b} is not hex")))
        .collect::<Result<Vec<u8>, String>>()?;
    Frame::new(id, &data).map_err(|e| e.to_string())
}

enum Phase {
    NoBus,
    Opened,
    Raw { first_frame_at: Instant },
}

/// One client's protocol state and buffers.
struct Session<'a> {
    shared: &'a Shared,
    me: &'a ClientState,
    phase: Phase,
    /// Output; `out[out_pos..]` is still to be written.
    out: String,
    out_pos: usize,
    /// Frames in `out`, counted as sent once `out` is written.
    out_frames: u64,
    /// Input not parsed yet.
    input: Vec<u8>,
}

impl<'a> Session<'a> {
    /// A new client's session: no bus opened yet, nothing buffered.
    fn new(shared: &'a Shared, me: &'a ClientState) -> Self {
        Self {
            shared,
            me,
            phase: Phase::NoBus,
            out: String::new(),
            out_pos: 0,
            out_frames: 0,
            input: Vec::new(),
        }
    }

    fn pending(&self) -> usize {
        self.out.len() - self.out_pos
    }

    fn push_out(&mut self, text: &str) {
        // Drop what is written before appending, so that the buffer holds only what is
        // pending (at most about `OUT_LIMIT_BYTES` plus one answer) even for a client that
        // reads slowly but never lets its output drain completely. Compacted when the written
        // part is at least half of the buffer (amortised), at a character boundary.
        if self.out_pos > 0
            && self.out_pos >= self.out.len() / 2
            && self.out.is_char_boundary(self.out_pos)
        {
            self.out.drain(..self.out_pos);
            self.out_pos = 0;
        }
        self.out.push_str(text);
        self.me.out_pending.store(true, Ordering::Release);
    }

    /// `n` more bytes are written.
    fn wrote(&mut self, n: usize) {
        self.out_pos = (self.out_pos + n).min(self.out.len());
        if self.out_pos == self.out.len() {
            self.out.clear();
            self.out_pos = 0;
            self.shared
                .counters
                .frames_sent
                .fetch_add(self.out_frames, Ordering::Relaxed);
            self.out_frames = 0;
            self.me.out_pending.store(false, Ordering::Release);
        }
    }

    /// With nothing pending and in rawmode past the grace time, take queued frames (up to
    /// about [`OUT_LIMIT_BYTES`] of text) into the output.
    fn take_frames(&mut self, now: Instant) {
        let Phase::Raw { first_frame_at } = self.phase else {
            return;
        };
        if now < first_frame_at || self.pending() > 0 {
            return;
        }
        let mut q = lock(&self.me.queue);
        if q.is_empty() {
            return;
        }
        self.me.out_pending.store(true, Ordering::Release);
        while self.out.len() < OUT_LIMIT_BYTES {
            let Some((f, t)) = q.pop_front() else { break };
            let _ = write!(
                self.out,
                "< frame {:03X} {}.{:06} ",
                f.id(),
                t / 1_000_000_000,
                (t % 1_000_000_000) / 1000
            );
            for b in f.data() {
                let _ = write!(self.out, "{b:02X}");
            }
            self.out.push_str(" >");
            self.out_frames += 1;
        }
    }

    /// Answer the complete commands in the input, while the output has room. A long text
    /// without a complete command is discarded (one bad command).
    fn handle_commands(&mut self) {
        let mut pos = 0;
        let mut held_back = false;
        while pos < self.input.len() {
            if self.pending() >= OUT_LIMIT_BYTES {
                held_back = true;
                break;
            }
            let rest = self.input.get(pos..).unwrap_or(&[]);
            let Some(start) = rest.iter().position(|&b| b == b'<').map(|i| pos + i) else {
                pos = self.input.len();
                break;
            };
            let after = self.input.get(start + 1..).unwrap_or(&[]);
            let Some(end) = after.iter().position(|&b| b == b'>').map(|i| start + 1 + i) else {
                pos = start;
                break;
            };
            let cmd =
                String::from_utf8_lossy(self.input.get(start + 1..end).unwrap_or(&[])).to_string();
            pos = end + 1;
            self.command(&cmd);
        }
        self.input.drain(..pos.min(self.input.len()));
        if !held_back && self.input.len() > INPUT_LIMIT_BYTES {
            self.input.clear();
            bump(&self.shared.counters.bad_commands);
        }
    }

    fn command(&mut self, cmd: &str) {
        let shared = self.shared;
        let words: Vec<&str> = cmd.split_whitespace().collect();
        let reply: Option<String> = match (&self.phase, words.as_slice()) {
            (_, ["echo"]) => Some("< echo >".into()),
            (Phase::NoBus, ["open", ch]) if *ch == shared.config.channel => {
                self.phase = Phase::Opened;
                Some("< ok >".into())
            }
            (Phase::NoBus, ["open", ch]) => Some(format!(
                "< error could not open bus {} >",
                ch.chars().take(ECHO_CHARS).collect::<String>()
            )),
            (Phase::Opened | Phase::Raw { .. }, ["rawmode"]) => {
                self.phase = Phase::Raw {
                    first_frame_at: Instant::now() + shared.config.rawmode_grace,
                };
                self.me.rawmode.store(true, Ordering::Release);
                Some("< ok >".into())
            }
            (Phase::Raw { .. }, ["send", ..]) if !shared.config.allow_send => {
                bump(&shared.counters.sends_refused);
                Some(
                    "< error read-only bus: frames from clients are refused (the server was \
                     started without --socketcand-allow-send) >"
                        .into(),
                )
            }
            (Phase::Raw { .. }, ["send", rest @ ..]) => match parse_send(rest) {
                Ok(f) => {
                    let mut q = lock(&shared.inbound);
                    if q.len() < shared.config.inbound_queue_frames {
                        q.push_back(f);
                        bump(&shared.counters.frames_received);
                    } else {
                        bump(&shared.counters.inbound_dropped);
                    }
                    None
                }
                Err(e) => {
                    bump(&shared.counters.bad_commands);
                    Some(format!(
                        "< error {} >",
                        e.chars().take(2 * ECHO_CHARS).collect::<String>()
                    ))
                }
            },
            _ => {
                bump(&shared.counters.bad_commands);
                let shown: String = words.join(" ").chars().take(ECHO_CHARS).collect();
                Some(format!("< error unexpected command {shown} >"))
            }
        };
        if let Some(r) = reply {
            self.push_out(&r);
        }
    }
}

fn transient(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted
    )
}

/// Serve one client until it closes, fails, stalls or the server stops. The socket is
/// non-blocking: the loop sleeps one poll when nothing moved.
fn serve_client(mut stream: TcpStream, shared: &Shared, me: &ClientState) {
    if stream.set_nonblocking(true).is_err() {
        return;
    }
    let _ = stream.set_nodelay(true);
    // Bounds what the kernel holds for a client that stopped reading (autotuning lets it grow
    // to 4 MiB, which hid a stalled client for minutes).
    let _ = socket2::SockRef::from(&stream)
        .set_send_buffer_size(shared.config.socket_send_buffer_bytes);
    let mut s = Session::new(shared, me);
    s.push_out("< hi >");
    let mut chunk = [0u8; READ_CHUNK_BYTES];
    let connected_at = Instant::now();
    let mut last_progress = connected_at;
    while !shared.stop.load(Ordering::Acquire) {
        let now = Instant::now();
        let mut busy = false;
        if me.evicted.load(Ordering::Acquire) {
            let _ = stream.write(b"< error dropped to make room for a new client >");
            return;
        }
        if !matches!(s.phase, Phase::Raw { .. })
            && now.duration_since(connected_at) > shared.config.open_timeout
        {
            bump(&shared.counters.clients_idle);
            let _ = stream.write(b"< error no bus opened in rawmode in time >");
            return;
        }
        let stuck_full = lock(&me.full_since)
            .is_some_and(|t| now.duration_since(t) > shared.config.write_timeout);
        if stuck_full {
            bump(&shared.counters.clients_stalled);
            return;
        }
        s.take_frames(now);
        if s.pending() > 0 {
            match stream.write(s.out.as_bytes().get(s.out_pos..).unwrap_or(&[])) {
                Ok(0) => return,
                Ok(n) => {
                    s.wrote(n);
                    last_progress = now;
                    busy = true;
                }
                Err(e) if transient(&e) => {}
                Err(_) => return,
            }
            if s.pending() > 0 && now.duration_since(last_progress) > shared.config.write_timeout {
                bump(&shared.counters.clients_stalled);
                return;
            }
        } else {
            last_progress = now;
        }
        if s.pending() < OUT_LIMIT_BYTES {
            match stream.read(&mut chunk) {
                Ok(0) => return,
                Ok(k) => {
                    s.input.extend_from_slice(chunk.get(..k).unwrap_or(&[]));
                    busy = true;
                }
                Err(e) if transient(&e) => {}
                Err(_) => return,
            }
        }
        s.handle_commands();
        if !busy {
            std::thread::sleep(POLL);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A client that reads, but never fast enough for its output to drain completely: the
    /// buffer keeps only what is pending (before the fix it kept every byte ever written,
    /// 1.75 MiB/s against a slow reader flooding commands).
    #[test]
    fn output_of_a_slow_reader_that_never_drains_stays_bounded() {
        let shared = Shared {
            config: ServerConfig::default(),
            stop: AtomicBool::new(false),
            clients: Mutex::new(Vec::new()),
            inbound: Mutex::new(VecDeque::new()),
            counters: Counters::default(),
        };
        let me = ClientState::default();
        let mut s = Session::new(&shared, &me);
        s.push_out("< hi >");
        for _ in 0..200_000 {
            s.push_out("< echo >");
            // Everything but the last byte is written: the output never drains.
            let n = s.pending() - 1;
            s.wrote(n);
            assert_eq!(s.pending(), 1);
        }
        assert!(
            s.out.len() < 4 * OUT_LIMIT_BYTES,
            "output buffer {} bytes for 1 byte pending",
            s.out.len()
        );
    }

    fn read_until(s: &mut TcpStream, want: &str) -> String {
        let mut got = String::new();
        let mut b = [0u8; 1024];
        let end = Instant::now() + Duration::from_secs(5);
        while !got.contains(want) && Instant::now() < end {
            if let Ok(n) = s.read(&mut b) {
                got.push_str(&String::from_utf8_lossy(&b[..n]));
            }
        }
        got
    }

    #[test]
    fn handshake_frames_and_send() {
        let server = SocketcandServer::bind(
            "127.0.0.1:0",
            ServerConfig {
                rawmode_grace: Duration::from_millis(20),
                allow_send: true,
                ..ServerConfig::default()
            },
        )
        .unwrap();
        let mut c = TcpStream::connect(server.local_addr()).unwrap();
        c.set_read_timeout(Some(Duration::from_millis(50))).unwrap();
        assert_eq!(read_until(&mut c, "< hi >"), "< hi >");
        c.write_all(b"< open can7 >").unwrap();
        assert!(read_until(&mut c, ">").starts_with("< error"));
        c.write_all(b"< open vcan0 >").unwrap();
        assert_eq!(read_until(&mut c, ">"), "< ok >");
        c.write_all(b"< rawmode >").unwrap();
        assert_eq!(read_until(&mut c, ">"), "< ok >");
        assert!(server.wait_for_client(Duration::from_secs(5)));
        server
            .publish(&Frame::new(0x72, &[1, 2, 0xAB]).unwrap(), 1_500_000_000)
            .unwrap();
        server
            .publish(&Frame::new(0x61, &[]).unwrap(), 2_000_001_000)
            .unwrap();
        let got = read_until(&mut c, "2.000001  >");
        assert!(got.contains("< frame 072 1.500000 0102AB >"), "{got}");
        assert!(got.contains("< frame 061 2.000001  >"), "{got}");
        c.write_all(b"< send 42 6 1 0 0 0 0 0 >< send 800 0 >< echo >")
            .unwrap();
        let got = read_until(&mut c, "< echo >");
        assert!(got.contains("< error identifier 0x800"), "{got}");
        let inbound = server.take_inbound();
        assert_eq!(
            inbound,
            vec![Frame::new(0x42, &[1, 0, 0, 0, 0, 0]).unwrap()]
        );
        let st = server.stats();
        assert_eq!(
            (st.frames_sent, st.frames_received, st.bad_commands),
            (2, 1, 1)
        );
    }

    #[test]
    fn refuses_non_loopback_and_stops() {
        if let Ok(s) = SocketcandServer::bind("0.0.0.0:0", ServerConfig::default()) {
            panic!("bound to {}", s.local_addr());
        }
        let mut s = SocketcandServer::bind("127.0.0.1:0", ServerConfig::default()).unwrap();
        let addr = s.local_addr();
        let mut c = TcpStream::connect(addr).unwrap();
        // A deadline that only turns a hang into a failure, whatever the machine's load; what
        // is asserted is that the server let go: the client is closed, the port no longer
        // listens.
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            s.shutdown();
            let _ = tx.send(());
        });
        rx.recv_timeout(Duration::from_secs(60))
            .expect("shutdown returns");
        c.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
        let mut rest = Vec::new();
        assert!(c.read_to_end(&mut rest).is_ok(), "the client is closed");
        assert!(TcpStream::connect(addr).is_err(), "{addr} still listens");
    }

    #[test]
    fn a_timestamp_past_u64_is_refused() {
        let server = SocketcandServer::bind(
            "127.0.0.1:0",
            ServerConfig {
                origin_ns: u64::MAX - 10,
                ..ServerConfig::default()
            },
        )
        .unwrap();
        let f = Frame::new(0x72, &[1]).unwrap();
        assert!(server.publish(&f, 10).is_ok());
        let e = server.publish(&f, 11).unwrap_err();
        assert_eq!((e.origin_ns, e.t_ns), (u64::MAX - 10, 11));
    }

    #[test]
    fn parse_send_errors() {
        assert!(parse_send(&["123", "2", "1"])
            .unwrap_err()
            .contains("length 2"));
        assert!(parse_send(&["12345678", "0"]).is_err());
        assert!(parse_send(&["12", "1", "zz"]).unwrap_err().contains("zz"));
        assert_eq!(
            parse_send(&["7FF", "8", "1", "2", "3", "4", "5", "6", "7", "8"]).unwrap(),
            Frame::new(0x7FF, &[1, 2, 3, 4, 5, 6, 7, 8]).unwrap()
        );
    }
}
