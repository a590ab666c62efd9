//! The candump grammar shared with `python/walker_monitor.py`: every line of
//! `tests/fixtures/candump_good.log` reads through `candump::read_log` as the record
//! `candump_good.expected` describes, every line of `candump_malformed.log` (reasons in
//! `candump_malformed.why`) is rejected with its line number. `python/test_candump_grammar.py`
//! reads the same files through the monitor's reader.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::path::PathBuf;

use canbus::candump::{read_log, Direction, LogFrame, LogRecord, MAX_LINE_BYTES, QUOTE_BYTES};

fn fixture(name: &str) -> Vec<u8> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Lines of a side file, `#` comments left out.
fn side_lines(name: &str) -> Vec<String> {
    String::from_utf8(fixture(name))
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(str::to_string)
        .collect()
}

fn hex(data: &[u8]) -> String {
    if data.is_empty() {
        return "-".to_string();
    }
    data.iter().map(|b| format!("{b:02X}")).collect()
}

/// The canonical form of `candump_good.expected`.
fn canonical(r: &LogRecord) -> String {
    let (kind, id, dlc, data) = match &r.frame {
        LogFrame::Standard(f) => (
            "std",
            format!("{:03X}", f.id()),
            f.data().len(),
            hex(f.data()),
        ),
        LogFrame::Extended { id, data } => ("ext", format!("{id:08X}"), data.len(), hex(data)),
        LogFrame::Remote {
            id,
            extended: false,
            dlc,
        } => ("rtr", format!("{id:03X}"), usize::from(*dlc), "-".into()),
        LogFrame::Remote {
            id,
            extended: true,
            dlc,
        } => ("xrtr", format!("{id:08X}"), usize::from(*dlc), "-".into()),
        LogFrame::Error { class, data } => ("err", format!("{class:08X}"), data.len(), hex(data)),
    };
    let dir = match r.direction {
        None => "-",
        Some(Direction::Rx) => "R",
        Some(Direction::Tx) => "T",
    };
    format!(
        "{} {} {kind} {id} {dlc} {data} {dir}",
        r.timestamp_ns, r.channel
    )
}

#[test]
fn every_good_line_parses_to_its_expected_record() {
    let log = fixture("candump_good.log");
    let expected = side_lines("candump_good.expected");
    let lines = log.split(|&b| b == b'\n').filter(|l| !l.is_empty()).count();
    assert_eq!(lines, expected.len(), "one expected record per good line");
    let (records, errors) = read_log(log.as_slice()).unwrap();
    assert!(errors.is_empty(), "{errors:#?}");
    let got: Vec<String> = records.iter().map(canonical).collect();
    assert_eq!(got, expected);
}

#[test]
fn every_malformed_line_is_rejected_with_its_line_number() {
    let log = fixture("candump_malformed.log");
    let why = side_lines("candump_malformed.why");
    let lines = log.split(|&b| b == b'\n').filter(|l| !l.is_empty()).count();
    assert_eq!(lines, why.len(), "one reason per malformed line");
    for (i, w) in why.iter().enumerate() {
        assert!(w.starts_with(&format!("{}\t", i + 1)), "{w}");
    }
    let (records, errors) = read_log(log.as_slice()).unwrap();
    assert!(records.is_empty(), "accepted: {records:#?}");
    let numbers: Vec<usize> = errors.iter().map(|e| e.line_no).collect();
    assert_eq!(numbers, (1..=lines).collect::<Vec<_>>());
    for e in &errors {
        assert!(!e.reason.is_empty());
        assert!(e.line.len() <= QUOTE_BYTES + 3 * 4, "{}", e.line.len());
    }
}

#[test]
fn each_malformed_line_is_rejected_between_good_lines() {
    // a bad line costs only itself: good, bad, good for every bad line
    let good = fixture("candump_good.log");
    let first_good = good.split(|&b| b == b'\n').next().unwrap().to_vec();
    let log = fixture("candump_malformed.log");
    let mut text = Vec::new();
    let mut bad = 0;
    for line in log.split(|&b| b == b'\n').filter(|l| !l.is_empty()) {
        for l in [first_good.as_slice(), line] {
            text.extend_from_slice(l);
            text.push(b'\n');
        }
        bad += 1;
    }
    text.extend_from_slice(&first_good);
    let (records, errors) = read_log(text.as_slice()).unwrap();
    assert_eq!(records.len(), bad + 1);
    assert_eq!(errors.len(), bad);
    assert!(errors.iter().all(|e| e.line_no % 2 == 0));
}

#[test]
fn an_over_long_line_is_reported_without_being_held() {
    // 8 MiB without a newline, then a good line: one error quoting the head, one record
    let mut text = vec![b'A'; 8 << 20];
    text.extend_from_slice(b"\n(1.0) vcan0 123#00\n");
    let (records, errors) = read_log(text.as_slice()).unwrap();
    assert_eq!(records.len(), 1);
    assert_eq!(errors.len(), 1);
    assert!(errors[0].reason.contains(&(8usize << 20).to_string()));
    assert!(errors[0].reason.contains(&MAX_LINE_BYTES.to_string()));
    assert_eq!(errors[0].line.len(), QUOTE_BYTES + 3);
    assert!(errors[0].line.ends_with("..."));
}

#[test]
fn blank_lines_are_skipped_and_a_missing_final_newline_is_fine() {
    let (records, errors) =
        read_log(&b"\n  \t\r\n(1.0) vcan0 123#00\n\n(2.0) vcan0 123#00"[..]).unwrap();
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(records.len(), 2);
    assert_eq!(records[1].timestamp_ns, 2_000_000_000);
}

proptest::proptest! {
    /// Whatever the writer's formatter writes, of any kind, the reader reads back.
    #[test]
    fn every_formatted_record_reads_back(kind in 0u8..5, id in 0u32..0x2000_0000,
                                         data in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..=8),
                                         dlc in 0u8..=8, ts_us in 0u64..u64::MAX / 1000, dir in 0u8..3) {
        let frame = match kind {
            0 => LogFrame::Standard(canbus::frame::Frame::new(id & 0x7FF, &data).unwrap()),
            1 => LogFrame::Extended { id, data },
            2 => LogFrame::Remote { id: id & 0x7FF, extended: false, dlc },
            3 => LogFrame::Remote { id, extended: true, dlc },
            _ => LogFrame::Error { class: id, data },
        };
        let r = LogRecord {
            timestamp_ns: ts_us * 1000,
            channel: "vcan0".into(),
            frame,
            direction: [None, Some(Direction::Rx), Some(Direction::Tx)][usize::from(dir)],
        };
        let line = canbus::candump::format_record(&r);
        proptest::prop_assert_eq!(canbus::candump::parse_line(&line), Ok(r));
    }
}
