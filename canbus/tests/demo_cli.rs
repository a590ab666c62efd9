//! `canbus-demo` on bad input (exit code 2, a message naming the option, never a panic), on
//! a far timestamp origin (no wrapped timestamps), and with a socketcand client that never
//! reads (the process still exits at the end of the run instead of hanging; every wait is a
//! deadline that only turns a hang into a failure, never a timing assertion).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::io::{BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};
use walker_tools::announced::announced_address;

use canbus::candump::read_log;

fn demo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_canbus-demo"))
        .args(args)
        .output()
        .unwrap()
}

/// Exit code 2 and a message on stderr containing every one of `names`, no panic.
fn assert_bad_input(args: &[&str], names: &[&str]) {
    let out = demo(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    for n in names {
        assert!(err.contains(n), "{args:?}: `{n}` not in {err}");
    }
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("canbus-demo-cli-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn absurd_speeds_are_bad_input_not_panics() {
    for (s, shown) in [
        ("1e-300", "1e-300"),
        ("-1", "-1"),
        ("NaN", "NaN"),
        ("inf", "inf"),
        ("1e7", "10000000"),
    ] {
        let arg = format!("--speed={s}");
        assert_bad_input(&["--seconds", "0.01", &arg], &["--speed", shown]);
    }
    // the limits themselves run
    let out = demo(&["--seconds", "0.01", "--speed", "1e6"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn absurd_client_waits_are_bad_input_not_panics() {
    for (w, shown) in [
        ("1e300", "1e300"),
        ("-1", "-1"),
        ("NaN", "NaN"),
        ("86401", "86401"),
    ] {
        assert_bad_input(
            &[
                "--seconds",
                "0.01",
                "--socketcand",
                "127.0.0.1:0",
                &format!("--wait-client={w}"),
            ],
            &["--wait-client", shown],
        );
    }
}

#[test]
fn other_bad_input_exits_2() {
    assert_bad_input(&["--seconds", "0"], &["--seconds"]);
    assert_bad_input(&["--seconds", "0.01", "--bitrate", "0"], &["bit rate"]);
    assert_bad_input(
        &["--seconds", "0.01", "--origin", "soon"],
        &["--origin", "soon"],
    );
    assert_bad_input(&["--seconds", "0.01", "--channel", "a b"], &["--channel"]);
    assert_bad_input(
        &["--seconds", "0.01", "--socketcand", "0.0.0.0:0"],
        &["--socketcand", "loopback"],
    );
    assert_bad_input(
        &["--seconds", "0.01", "--fault", "busoff:node=nobody"],
        &["nobody"],
    );
    // A fault on an identifier no node sends did nothing, silently (the old example 0x101).
    assert_bad_input(
        &["--seconds", "0.01", "--fault", "drop:id=0x101,count=5"],
        &["0x101", "0x022 HeelStrike"],
    );
}

#[test]
fn candump_errors_name_the_path() {
    let bad = temp_dir("nopath").join("no").join("such").join("dir.log");
    let bad_s = bad.to_str().unwrap();
    assert_bad_input(
        &["--seconds", "0.01", "--candump", bad_s],
        &["--candump", bad_s],
    );
}

#[test]
fn a_far_origin_is_refused_or_stamped_without_wrapping() {
    // 18446744073 s + 5 s is past u64 nanoseconds: the log's timestamps used to wrap to 1970
    assert_bad_input(&["--origin", "18446744073"], &["--origin", "18446744073"]);
    assert_bad_input(
        &["--origin", "18446744074", "--seconds", "0.01"],
        &["18446744074"],
    );
    assert_bad_input(
        &["--origin", "99999999999999999999", "--seconds", "0.01"],
        &["--origin"],
    );
    // 0.5 s still fits: every timestamp follows the origin, in order
    let log = temp_dir("origin").join("far.log");
    let out = demo(&[
        "--origin",
        "18446744073",
        "--seconds",
        "0.5",
        "--candump",
        log.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (records, errors) = read_log(BufReader::new(std::fs::File::open(&log).unwrap())).unwrap();
    assert!(errors.is_empty(), "{errors:?}");
    assert!(records.len() > 100, "{}", records.len());
    let origin_ns = 18_446_744_073_000_000_000u64;
    let mut last = origin_ns;
    for r in &records {
        assert!(r.timestamp_ns >= last, "{} after {last}", r.timestamp_ns);
        last = r.timestamp_ns;
    }
    assert!(last <= origin_ns + 501_000_000, "{last}");
}

/// A client that opens rawmode and never reads used to keep the demo alive for ever after its
/// run (the server's shutdown joined a thread stuck in `write_all`).
#[test]
fn a_client_that_never_reads_does_not_keep_the_demo_alive() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_canbus-demo"))
        .args([
            "--seconds",
            "3000",
            "--speed",
            "0",
            "--socketcand",
            "127.0.0.1:0",
            "--wait-client",
            "60",
            "--json",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let addr = announced_address(
        &mut err,
        "socketcand: listening on ",
        Duration::from_secs(60),
    )
    .unwrap_or_else(|last| {
        let _ = child.kill();
        panic!("no address announced: {last}")
    });
    let mut client = TcpStream::connect(addr).unwrap();
    client.write_all(b"< open vcan0 >< rawmode >").unwrap();
    let t0 = Instant::now();
    // The demo runs 3000 simulated seconds as fast as it can (measured: about 2 s), far more
    // than the socket buffers hold. The deadline only turns a hang (the bug: for ever) into a
    // failure; how long the exit takes is printed, not asserted (a loaded machine may take
    // seconds). That shutdown does not wait on the stalled client's write timeout is
    // `socketcand_stress.rs`'s `a_client_that_never_reads_loses_frames_and_does_not_hold_shutdown`.
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if t0.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("canbus-demo still running 120 s after its client connected");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let elapsed_s = t0.elapsed().as_secs_f64();
    let mut stdout = String::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut stdout)
        .unwrap();
    assert!(status.success(), "{status:?}");
    let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let sc = &j["socketcand"];
    assert!(sc["frames_dropped"].as_u64().unwrap() > 0, "{sc}");
    // The client was not waited for: either the server dropped it as stalled (its queue
    // stayed full for the write timeout: a run that lasts over 5 s on a loaded machine) or
    // the final flush gave up on it.
    assert!(
        sc["clients_stalled"].as_u64().unwrap() == 1 || sc["flushed"] == false,
        "{sc}"
    );
    let wall_s = j["wall_s"].as_f64().unwrap();
    // After the run: the rawmode grace (0.2 s) before it, the flush and the shutdown after
    // it; measured: about 0.35 s.
    eprintln!("exited {elapsed_s:.3} s after the client connected, the run took {wall_s:.3} s");
    drop(client);
}

/// Flags `canbus-demo` would have ignored, or taken at a value where its answer means
/// nothing, are refused with exit 2 naming the flag.
#[test]
fn server_flags_without_a_server_are_refused() {
    assert_bad_input(
        &["--seconds", "0.01", "--wait-client", "1"],
        &["--wait-client", "needs --socketcand"],
    );
    assert_bad_input(
        &["--seconds", "0.01", "--socketcand-allow-send"],
        &["--socketcand-allow-send", "needs --socketcand"],
    );
}

/// `--bitrate 1` reported a bus load of 0.00 %: no frame ends within a run.
#[test]
fn bit_rates_outside_classic_can_are_refused() {
    for bad in ["1", "9999", "1000001", "4294967295"] {
        assert_bad_input(
            &["--seconds", "0.01", "--bitrate", bad],
            &["--bitrate", bad, "10000", "1000000"],
        );
    }
    for good in ["10000", "125000", "1000000"] {
        let out = demo(&["--seconds", "0.01", "--bitrate", good]);
        assert!(
            out.status.success(),
            "{good}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// `drop:…,count=0` did nothing, silently; a count past u32 was called "not a non-negative
/// integer".
#[test]
fn fault_counts_that_hit_nothing_or_overflow_are_refused() {
    for (count, shown) in [
        ("0", "`0`"),
        ("18446744073709551615", "18446744073709551615"),
    ] {
        let spec = format!("drop:id=0x072,count={count}");
        assert_bad_input(
            &["--seconds", "0.01", "--fault", &spec],
            &["count", shown, "from 1 to 4294967295"],
        );
    }
}
