//! Helpers shared by the socketcand tests: every wait is a deadline that only turns a hang
//! into a failure, never a timing assertion.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::io::{ErrorKind, Read};
use std::net::TcpStream;
use std::time::{Duration, Instant};

/// How long any wait may take before the test fails instead of hanging: far beyond what any
/// of them takes (milliseconds), far below the 600 s write timeout a shutdown that waited on a
/// stalled client would take.
pub const DEADLINE: Duration = Duration::from_secs(60);

/// Read until `want` is in the text, the connection closes or [`DEADLINE`] passes.
pub fn read_until(s: &mut TcpStream, want: &str) -> String {
    s.set_read_timeout(Some(Duration::from_millis(20))).unwrap();
    let mut got = String::new();
    let mut b = [0u8; 4096];
    let end = Instant::now() + DEADLINE;
    while !got.contains(want) && Instant::now() < end {
        match s.read(&mut b) {
            Ok(0) => break,
            Ok(n) => got.push_str(&String::from_utf8_lossy(&b[..n])),
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
            Err(_) => break,
        }
    }
    got
}

/// Whether `done` comes true before [`DEADLINE`].
pub fn wait_until(mut done: impl FnMut() -> bool) -> bool {
    let end = Instant::now() + DEADLINE;
    while Instant::now() < end {
        if done() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    done()
}
