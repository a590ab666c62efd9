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
//! Frames are queued per client in a bounded queue (frames that do not fit are counted and
//! dropped, never blocking the simulation); frames sent by clients are queued in a bounded
//! inbound queue that the simulation drains with [`SocketcandServer::take_inbound`] and puts on
//! the bus as a host node. python-can reads the `< ok >` of `rawmode` with a single `recv` and
//! compares it exactly, so the server waits [`ServerConfig::rawmode_grace`] before the first
//! frame. Only standard identifiers; error frames are not sent (socketcand's rawmode has no
//! form python-can parses). The server stops when dropped or on
//! [`SocketcandServer::shutdown`]: the threads poll a stop flag every 10 ms.

use std::collections::VecDeque;
use std::io::{self, ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream, ToSocketAddrs};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender, TrySendError};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use thiserror::Error;

use crate::frame::Frame;

/// Server parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct ServerConfig {
    /// The one channel served (`< open CHANNEL >`). Default `vcan0`.
    pub channel: String,
    /// Clients served at once; more are refused. Default 8.
    pub max_clients: usize,
    /// Frames queued per client before new ones are dropped. Default 65536.
    pub client_queue_frames: usize,
    /// Frames from clients queued before new ones are dropped. Default 1024.
    pub inbound_queue_frames: usize,
    /// Wait after the `rawmode` answer before the first frame. Default 200 ms.
    pub rawmode_grace: Duration,
    /// Added to simulated time in frame timestamps [ns since the Unix epoch]. Default 0.
    pub origin_ns: u64,
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
        }
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
}

#[derive(Default)]
struct Counters {
    clients_accepted: AtomicU64,
    frames_sent: AtomicU64,
    frames_dropped: AtomicU64,
    frames_received: AtomicU64,
    bad_commands: AtomicU64,
}

struct Client {
    tx: SyncSender<String>,
    rawmode: Arc<AtomicBool>,
    alive: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
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

    /// Send a delivered frame, stamped at simulated time `t_ns`, to every client in rawmode.
    pub fn publish(&self, frame: &Frame, t_ns: u64) {
        let t = self.shared.config.origin_ns + t_ns;
        let data: String = frame.data().iter().map(|b| format!("{b:02X}")).collect();
        let line = format!(
            "< frame {:03X} {}.{:06} {} >",
            frame.id(),
            t / 1_000_000_000,
            (t % 1_000_000_000) / 1000,
            data
        );
        let clients = lock(&self.shared.clients);
        for c in clients.iter() {
            if !c.rawmode.load(Ordering::Acquire) || !c.alive.load(Ordering::Acquire) {
                continue;
            }
            match c.tx.try_send(line.clone()) {
                Ok(()) => {}
                Err(TrySendError::Full(_)) | Err(TrySendError::Disconnected(_)) => {
                    self.shared
                        .counters
                        .frames_dropped
                        .fetch_add(1, Ordering::Relaxed);
                }
            }
        }
    }

    /// Frames clients sent since the last call, in arrival order.
    pub fn take_inbound(&self) -> Vec<Frame> {
        lock(&self.shared.inbound).drain(..).collect()
    }

    /// Number of connected clients in rawmode.
    pub fn rawmode_clients(&self) -> usize {
        lock(&self.shared.clients)
            .iter()
            .filter(|c| c.rawmode.load(Ordering::Acquire) && c.alive.load(Ordering::Acquire))
            .count()
    }

    /// Wait until at least one client is in rawmode and past its grace time, at most
    /// `timeout`. Returns whether one is.
    pub fn wait_for_client(&self, timeout: Duration) -> bool {
        let end = Instant::now() + timeout;
        while Instant::now() < end {
            if self.rawmode_clients() > 0 {
                std::thread::sleep(self.shared.config.rawmode_grace);
                return true;
            }
            std::thread::sleep(POLL);
        }
        false
    }

    /// Block until every client's queue is written out or `timeout` passes.
    pub fn flush(&self, timeout: Duration) {
        let end = Instant::now() + timeout;
        while Instant::now() < end {
            let sent = self.shared.counters.frames_sent.load(Ordering::Relaxed);
            std::thread::sleep(Duration::from_millis(50));
            if self.shared.counters.frames_sent.load(Ordering::Relaxed) == sent {
                return;
            }
        }
    }

    /// Counters so far.
    pub fn stats(&self) -> ServerStats {
        let c = &self.shared.counters;
        ServerStats {
            clients_accepted: c.clients_accepted.load(Ordering::Relaxed),
            frames_sent: c.frames_sent.load(Ordering::Relaxed),
            frames_dropped: c.frames_dropped.load(Ordering::Relaxed),
            frames_received: c.frames_received.load(Ordering::Relaxed),
            bad_commands: c.bad_commands.load(Ordering::Relaxed),
        }
    }

    /// Stop accepting, close every client and join the threads.
    pub fn shutdown(&mut self) {
        self.shared.stop.store(true, Ordering::Release);
        if let Some(a) = self.acceptor.take() {
            let _ = a.join();
        }
        let threads: Vec<JoinHandle<()>> = lock(&self.shared.clients)
            .iter_mut()
            .filter_map(|c| c.thread.take())
            .collect();
        for t in threads {
            let _ = t.join();
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

fn accept_loop(listener: &TcpListener, shared: &Arc<Shared>) {
    while !shared.stop.load(Ordering::Acquire) {
        match listener.accept() {
            Ok((mut stream, _)) => {
                let mut clients = lock(&shared.clients);
                clients.retain(|c| c.alive.load(Ordering::Acquire) || c.thread.is_some());
                let live = clients
                    .iter()
                    .filter(|c| c.alive.load(Ordering::Acquire))
                    .count();
                if live >= shared.config.max_clients {
                    let _ = stream.write_all(b"< error too many clients >");
                    continue;
                }
                let (tx, rx) = sync_channel(shared.config.client_queue_frames);
                let rawmode = Arc::new(AtomicBool::new(false));
                let alive = Arc::new(AtomicBool::new(true));
                let s2 = Arc::clone(shared);
                let (r2, a2) = (Arc::clone(&rawmode), Arc::clone(&alive));
                let thread = std::thread::Builder::new()
                    .name("socketcand-client".into())
                    .spawn(move || {
                        let _ = serve_client(stream, &s2, &rx, &r2);
                        a2.store(false, Ordering::Release);
                    })
                    .ok();
                shared
                    .counters
                    .clients_accepted
                    .fetch_add(1, Ordering::Relaxed);
                clients.push(Client {
                    tx,
                    rawmode,
                    alive,
                    thread,
                });
            }
            Err(e) if e.kind() == ErrorKind::WouldBlock => std::thread::sleep(POLL),
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

fn serve_client(
    mut stream: TcpStream,
    shared: &Shared,
    rx: &Receiver<String>,
    rawmode: &AtomicBool,
) -> io::Result<()> {
    stream.set_nodelay(true)?;
    stream.set_read_timeout(Some(POLL))?;
    stream.write_all(b"< hi >")?;
    let mut phase = Phase::NoBus;
    let mut buf: Vec<u8> = Vec::new();
    let mut chunk = [0u8; 4096];
    while !shared.stop.load(Ordering::Acquire) {
        if let Phase::Raw { first_frame_at } = phase {
            if Instant::now() >= first_frame_at {
                let mut out = String::new();
                let mut n = 0u64;
                while let Ok(line) = rx.try_recv() {
                    out.push_str(&line);
                    n += 1;
                    if out.len() > 64 * 1024 {
                        break;
                    }
                }
                if n > 0 {
                    stream.write_all(out.as_bytes())?;
                    shared.counters.frames_sent.fetch_add(n, Ordering::Relaxed);
                }
            }
        }
        match stream.read(&mut chunk) {
            Ok(0) => return Ok(()),
            Ok(k) => buf.extend_from_slice(chunk.get(..k).unwrap_or(&[])),
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
            Err(e) => return Err(e),
        }
        if buf.len() > 64 * 1024 {
            buf.clear();
            shared.counters.bad_commands.fetch_add(1, Ordering::Relaxed);
        }
        while let (Some(start), Some(end)) = (
            buf.iter().position(|&b| b == b'<'),
            buf.iter().position(|&b| b == b'>'),
        ) {
            if end < start {
                buf.drain(..=end);
                continue;
            }
            let cmd = String::from_utf8_lossy(buf.get(start + 1..end).unwrap_or(&[])).to_string();
            buf.drain(..=end);
            let words: Vec<&str> = cmd.split_whitespace().collect();
            let reply: Option<String> = match (&phase, words.as_slice()) {
                (_, ["echo"]) => Some("< echo >".into()),
                (Phase::NoBus, ["open", ch]) if *ch == shared.config.channel => {
                    phase = Phase::Opened;
                    Some("< ok >".into())
                }
                (Phase::NoBus, ["open", ch]) => Some(format!("< error could not open bus {ch} >")),
                (Phase::Opened | Phase::Raw { .. }, ["rawmode"]) => {
                    phase = Phase::Raw {
                        first_frame_at: Instant::now() + shared.config.rawmode_grace,
                    };
                    rawmode.store(true, Ordering::Release);
                    Some("< ok >".into())
                }
                (Phase::Raw { .. }, ["send", rest @ ..]) => match parse_send(rest) {
                    Ok(f) => {
                        let mut q = lock(&shared.inbound);
                        if q.len() < shared.config.inbound_queue_frames {
                            q.push_back(f);
                            shared
                                .counters
                                .frames_received
                                .fetch_add(1, Ordering::Relaxed);
                        }
                        None
                    }
                    Err(e) => {
                        shared.counters.bad_commands.fetch_add(1, Ordering::Relaxed);
                        Some(format!("< error {e} >"))
                    }
                },
                _ => {
                    shared.counters.bad_commands.fetch_add(1, Ordering::Relaxed);
                    Some(format!("< error unexpected command {} >", words.join(" ")))
                }
            };
            if let Some(r) = reply {
                stream.write_all(r.as_bytes())?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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
        server.publish(&Frame::new(0x72, &[1, 2, 0xAB]).unwrap(), 1_500_000_000);
        server.publish(&Frame::new(0x61, &[]).unwrap(), 2_000_001_000);
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
        let _c = TcpStream::connect(s.local_addr()).unwrap();
        let t = Instant::now();
        s.shutdown();
        assert!(t.elapsed() < Duration::from_secs(2));
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
