//! Clients that would lock a monitor out, and clients that would drive the walker: idle
//! connections give way and are dropped, a client that stops reading is dropped even while
//! the kernel still buffers its output, and the server is read-only unless told otherwise.
//!
//! Every wait here is a deadline that only turns a hang into a failure; what is asserted is
//! what the server did (counters, answers), never how long it took.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::io::Write;
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

use canbus::frame::Frame;
use canbus::socketcand::{ServerConfig, SocketcandServer};

mod common;
use common::{read_until, wait_until, DEADLINE};

/// A monitor: connects, opens the bus in rawmode.
fn monitor(addr: SocketAddr) -> TcpStream {
    let mut c = TcpStream::connect(addr).unwrap();
    c.write_all(b"< open vcan0 >< rawmode >").unwrap();
    let got = read_until(&mut c, "< hi >< ok >< ok >");
    assert_eq!(got, "< hi >< ok >< ok >");
    c
}

fn frame(i: u32) -> Frame {
    Frame::new(0x072, &i.to_le_bytes()).unwrap()
}

/// The lock-out: eight connections that never say `< open >` took every place, and a
/// monitor got `< error too many clients >` for the whole walk. Now a new connection takes the
/// place of the oldest idle one at once, and idle ones are dropped after `open_timeout`.
#[test]
fn idle_connections_never_lock_a_monitor_out() {
    let server = SocketcandServer::bind(
        "127.0.0.1:0",
        ServerConfig {
            rawmode_grace: Duration::from_millis(1),
            // long enough that the idle ones are still there when the monitor comes
            open_timeout: Duration::from_secs(30),
            ..ServerConfig::default()
        },
    )
    .unwrap();
    let addr = server.local_addr();
    let max = ServerConfig::default().max_clients;
    let idle: Vec<TcpStream> = (0..max)
        .map(|_| TcpStream::connect(addr).unwrap())
        .collect();
    assert!(wait_until(|| server.connected_clients() == max));
    let mut m = monitor(addr);
    assert_eq!(server.stats().clients_refused, 0);
    assert_eq!(server.stats().clients_idle, 1);
    assert!(wait_until(|| server.rawmode_clients() == 1));
    server.publish(&frame(7), 1_000).unwrap();
    assert!(read_until(&mut m, "< frame 072").contains("< frame 072 0.000001 07000000 >"));
    // every idle one can be displaced, one per new monitor; the monitors in rawmode cannot
    let mut monitors = vec![m];
    for _ in 1..max {
        monitors.push(monitor(addr));
    }
    assert_eq!(server.stats().clients_idle, max as u64);
    let mut late = TcpStream::connect(addr).unwrap();
    let got = read_until(&mut late, ">");
    assert!(got.contains("< error too many clients"), "{got}");
    drop(idle);
}

/// A connection that never opens the bus is dropped after `open_timeout`, told why.
#[test]
fn a_connection_that_never_opens_the_bus_is_dropped() {
    let server = SocketcandServer::bind(
        "127.0.0.1:0",
        ServerConfig {
            open_timeout: Duration::from_millis(300),
            ..ServerConfig::default()
        },
    )
    .unwrap();
    let mut never_opens = TcpStream::connect(server.local_addr()).unwrap();
    let mut opens_only = TcpStream::connect(server.local_addr()).unwrap();
    opens_only.write_all(b"< open vcan0 >").unwrap();
    let got = read_until(&mut never_opens, "in time >");
    assert!(
        got.ends_with("< error no bus opened in rawmode in time >"),
        "{got}"
    );
    let got = read_until(&mut opens_only, "in time >");
    assert!(
        got.contains("< ok >") && got.ends_with("in time >"),
        "{got}"
    );
    assert!(wait_until(|| server.connected_clients() == 0));
    assert_eq!(server.stats().clients_idle, 2);
}

/// Rawmode clients that never read: the kernel takes their output for a while (with
/// autotuning it took 4 MiB each, minutes of a walk, so they were never dropped); with a
/// bounded send buffer their output stalls and they are dropped, freeing every place.
#[test]
fn rawmode_clients_that_never_read_are_dropped_despite_kernel_buffers() {
    let server = SocketcandServer::bind(
        "127.0.0.1:0",
        ServerConfig {
            rawmode_grace: Duration::from_millis(1),
            write_timeout: Duration::from_millis(300),
            client_queue_frames: 1024,
            ..ServerConfig::default()
        },
    )
    .unwrap();
    let addr = server.local_addr();
    let max = ServerConfig::default().max_clients;
    let silent: Vec<TcpStream> = (0..max).map(|_| monitor(addr)).collect();
    assert!(wait_until(|| server.rawmode_clients() == max));
    // a walk's worth of frames, paced, until every silent client is gone
    let mut i = 0u32;
    let end = Instant::now() + DEADLINE;
    let mut bytes_published = 0u64;
    while server.connected_clients() > 0 && Instant::now() < end {
        for _ in 0..500 {
            server.publish(&frame(i), u64::from(i) * 1000).unwrap();
            i = i.wrapping_add(1);
            bytes_published += "< frame 072 0.000000 00000000 >".len() as u64;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let st = server.stats();
    assert_eq!(server.connected_clients(), 0, "{st:?}");
    assert_eq!(st.clients_stalled, max as u64, "{st:?}");
    // what each silent client was written before it stalled: its socket buffers, not 4 MiB
    let written_each = st.frames_sent * 31 / max as u64;
    eprintln!("written per silent client before the stall: {written_each} B ({bytes_published} B published each)");
    assert!(
        written_each < 2 * 1024 * 1024,
        "{written_each} B each: {st:?}"
    );
    // and a monitor gets in
    let mut m = monitor(addr);
    server.publish(&frame(1), 5_000).unwrap();
    assert!(read_until(&mut m, "< frame 072").contains("< frame 072"));
    drop(silent);
}

/// A monitor needs no write access: `send` is refused unless the server allows it, and
/// nothing reaches the bus.
#[test]
fn the_server_is_read_only_unless_sending_is_allowed() {
    for allow_send in [false, true] {
        let server = SocketcandServer::bind(
            "127.0.0.1:0",
            ServerConfig {
                rawmode_grace: Duration::from_millis(1),
                allow_send,
                ..ServerConfig::default()
            },
        )
        .unwrap();
        let mut c = monitor(server.local_addr());
        // EmergencyStop_ALL, then an echo to know both were handled
        c.write_all(b"< send 010 1 03 >< echo >").unwrap();
        let got = read_until(&mut c, "< echo >");
        let inbound = server.take_inbound();
        let st = server.stats();
        if allow_send {
            assert_eq!(got, "< echo >");
            assert_eq!(inbound, vec![Frame::new(0x010, &[3]).unwrap()]);
            assert_eq!((st.frames_received, st.sends_refused), (1, 0));
        } else {
            assert!(
                got.starts_with("< error read-only bus") && got.contains("--socketcand-allow-send"),
                "{got}"
            );
            assert!(inbound.is_empty());
            assert_eq!((st.frames_received, st.sends_refused), (0, 1));
        }
    }
}

/// Rawmode clients that stopped reading do not lock a monitor out while they wait for their
/// write timeout (the review found 21 s of lock-out): when the server is full, a new monitor
/// takes the place of one whose queue is full, and that one is told why.
#[test]
fn stalled_clients_give_way_to_a_new_monitor_at_once() {
    let server = SocketcandServer::bind(
        "127.0.0.1:0",
        ServerConfig {
            rawmode_grace: Duration::from_millis(1),
            // only eviction can free a place within the test
            write_timeout: Duration::from_secs(600),
            client_queue_frames: 256,
            ..ServerConfig::default()
        },
    )
    .unwrap();
    let addr = server.local_addr();
    let max = ServerConfig::default().max_clients;
    let mut silent: Vec<TcpStream> = (0..max).map(|_| monitor(addr)).collect();
    assert!(wait_until(|| server.rawmode_clients() == max));
    // frames until every silent client's queue is full
    let mut i = 0u32;
    assert!(wait_until(|| {
        for _ in 0..2000 {
            server.publish(&frame(i), u64::from(i) * 1000).unwrap();
            i = i.wrapping_add(1);
        }
        server.stats().frames_dropped >= 8 * 100
    }));
    let mut m = monitor(addr);
    let st = server.stats();
    assert_eq!(st.clients_refused, 0, "{st:?}");
    assert_eq!(st.clients_stalled, 1, "{st:?}");
    server.publish(&frame(7), 1_000).unwrap();
    assert!(read_until(&mut m, "< frame 072").contains("< frame 072"));
    // the oldest silent client was closed, told why when its socket had room for it (after
    // whatever frames it had been sent)
    let told = read_until(&mut silent[0], "make room for a new client >");
    let mut rest = [0u8; 64];
    assert!(
        matches!(std::io::Read::read(&mut silent[0], &mut rest), Ok(0)),
        "the evicted client is closed; read so far ends {}",
        &told[told.len().saturating_sub(200)..]
    );
}
