//! The candump logs in `python/fixtures/` (read by the Python tests) are what the demo bus
//! writes today, and the Rust reader reads them back frame for frame.
//!
//! Regenerate after an intended change: `UPDATE_GOLDEN=1 cargo test -p canbus --test golden_logs`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::path::PathBuf;

use canbus::candump::{read_log, CandumpWriter, LogFrame};
use canbus::demo::Demo;
use canbus::{BusConfig, BusEvent, FaultSpec};

const ORIGIN_NS: u64 = 1_700_000_000_000_000_000;

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../python/fixtures")
}

/// Runs the demo for `seconds` with `faults`; returns the log text, the stats JSON and the
/// events.
fn run(seconds: u64, faults: &[&str]) -> (String, String, Vec<BusEvent>) {
    let faults: Vec<FaultSpec> = faults.iter().map(|f| f.parse().unwrap()).collect();
    let mut demo = Demo::new(BusConfig::default(), &faults).unwrap();
    let mut w = CandumpWriter::new(Vec::new(), "vcan0", ORIGIN_NS);
    let mut events = Vec::new();
    while demo.now_ns() < seconds * 1_000_000_000 {
        for e in demo.tick().unwrap() {
            w.write_event(&e).unwrap();
            events.push(e);
        }
    }
    let log = String::from_utf8(w.finish().unwrap()).unwrap();
    let stats = serde_json::to_string_pretty(&demo.bus.stats()).unwrap() + "\n";
    (log, stats, events)
}

fn check(name: &str, content: &str) {
    let path = fixtures().join(name);
    if std::env::var_os("UPDATE_GOLDEN").is_some() {
        std::fs::write(&path, content).unwrap();
        return;
    }
    let old = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        old == content,
        "{} is stale; regenerate with UPDATE_GOLDEN=1 cargo test -p canbus --test golden_logs",
        path.display()
    );
}

#[test]
fn fixtures_are_fresh_and_read_back() {
    for (name, faults) in [
        ("demo-nominal", &[][..]),
        (
            "demo-faults",
            &[
                "busoff:node=right,from_ms=2000",
                "corrupt:id=0x072,count=3",
                "drop:id=0x062,count=4",
            ][..],
        ),
    ] {
        let (log, stats, events) = run(3, faults);
        check(&format!("{name}.log"), &log);
        check(&format!("{name}.json"), &stats);
        let (records, errors) = read_log(log.as_bytes()).unwrap();
        assert!(errors.is_empty(), "{errors:?}");
        assert_eq!(records.len(), events.len());
        for (r, e) in records.iter().zip(&events) {
            match (e, &r.frame) {
                (BusEvent::Delivered(d), LogFrame::Standard(f)) => {
                    assert_eq!(*f, d.frame);
                    assert_eq!(r.timestamp_ns, ORIGIN_NS + d.t_end_ns / 1000 * 1000);
                }
                (BusEvent::ErrorFrame { .. } | BusEvent::BusOff { .. }, LogFrame::Error { .. }) => {
                }
                other => panic!("{other:?}"),
            }
        }
    }
}
