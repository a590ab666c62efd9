//! candump log files (`candump -L` format), as python-can's `CanutilsLogReader` /
//! `can.LogReader` reads and `CanutilsLogWriter` writes them.
//!
//! ```text
//! (1700000000.123456) vcan0 123#DEADBEEF
//! (1700000000.123789) vcan0 20000080#0000000000000000
//! (1700000000.124000) vcan0 072#0102 R
//! ```
//!
//! One record per line: timestamp in seconds with (usually six) decimals, channel, identifier
//! (three hex digits: standard, eight: extended; `CAN_ERR_FLAG` 0x20000000 set: error frame),
//! `#`, data as hex pairs (or `R[dlc]` for a remote frame), optionally ` R`/` T` (received or
//! transmitted, written by python-can). [`read_log`] keeps every good line and reports each bad
//! one with its line number. [`parse_line`] documents the grammar, which `python/walker_monitor.py`
//! shares (both read `canbus/tests/fixtures/candump_{good,malformed}.log`).

use std::io::{self, BufRead, Write};

use thiserror::Error;

use crate::bus::BusEvent;
use crate::frame::Frame;
use crate::timestamp::{stamp_ns, TimestampOverflow};

/// Linux `CAN_ERR_FLAG`: the identifier is an error class, not a frame identifier.
pub const CAN_ERR_FLAG: u32 = 0x2000_0000;
/// Linux `CAN_ERR_BUSERROR` (python-can needs it to recognise an error frame).
pub const CAN_ERR_BUSERROR: u32 = 0x0000_0080;
/// Linux `CAN_ERR_PROT` (protocol violation; details in data byte 2).
pub const CAN_ERR_PROT: u32 = 0x0000_0008;
/// Linux `CAN_ERR_BUSOFF`.
pub const CAN_ERR_BUSOFF: u32 = 0x0000_0040;

/// What a log line carries.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LogFrame {
    /// A standard data frame.
    Standard(Frame),
    /// An extended (29-bit) data frame.
    Extended {
        /// Identifier.
        id: u32,
        /// Payload (0..=8 bytes).
        data: Vec<u8>,
    },
    /// A remote frame.
    Remote {
        /// Identifier.
        id: u32,
        /// True for a 29-bit identifier.
        extended: bool,
        /// Requested length.
        dlc: u8,
    },
    /// An error frame: the error class bits (without `CAN_ERR_FLAG`) and its 8 data bytes.
    Error {
        /// Error class bits.
        class: u32,
        /// Error details.
        data: Vec<u8>,
    },
}

/// Direction marker python-can appends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// ` R`.
    Rx,
    /// ` T`.
    Tx,
}

/// One line of a log.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LogRecord {
    /// Timestamp [ns since the Unix epoch, or since whatever origin the log uses].
    pub timestamp_ns: u64,
    /// Interface name.
    pub channel: String,
    /// The frame.
    pub frame: LogFrame,
    /// Direction, when the line has one.
    pub direction: Option<Direction>,
}

/// Why a line is not a log record.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
#[error("line {line_no}: {reason}: `{line}`")]
pub struct LineError {
    /// 1-based line number.
    pub line_no: usize,
    /// The line as read, cut to its first [`QUOTE_BYTES`] bytes (`...` appended when cut),
    /// bytes that are not UTF-8 replaced.
    pub line: String,
    /// What is wrong.
    pub reason: String,
}

/// Errors of [`read_log`] that stop reading altogether.
#[derive(Debug, Error)]
pub enum ReadError {
    /// The reader failed.
    #[error("reading the log: {0}")]
    Io(#[from] io::Error),
}

/// The longest line [`read_log`] and [`parse_line`] accept, in bytes before the newline
/// (a `\r` before it included); a longer line is malformed. The longest record python-can or
/// [`CandumpWriter`] write is about 60 bytes plus the channel name. `python/walker_monitor.py`
/// uses the same bound.
pub const MAX_LINE_BYTES: usize = 256;

/// How much of a bad line a [`LineError`] keeps (bytes, before lossy UTF-8 decoding).
pub const QUOTE_BYTES: usize = 120;

/// The largest timestamp, in ns, that fits a `u64`.
const MAX_TIMESTAMP_NS: u64 = u64::MAX;

/// `(SECONDS.FRACTION)`: ASCII digits, 1 to 9 fraction digits, the value in ns within 64 bits.
fn parse_timestamp(s: &str) -> Result<u64, String> {
    let inner = s
        .strip_prefix('(')
        .and_then(|t| t.strip_suffix(')'))
        .ok_or_else(|| format!("timestamp `{s}` is not of the form (SECONDS.FRACTION)"))?;
    let bad = || format!("timestamp `{s}` is not of the form (SECONDS.FRACTION), digits only");
    let (secs, frac) = inner.split_once('.').ok_or_else(bad)?;
    if secs.is_empty() || !secs.bytes().all(|b| b.is_ascii_digit()) {
        return Err(bad());
    }
    if frac.is_empty() || frac.len() > 9 || !frac.bytes().all(|b| b.is_ascii_digit()) {
        return Err(format!(
            "timestamp `{s}` needs 1 to 9 digits after the decimal point"
        ));
    }
    let too_big = || format!("timestamp `{s}` exceeds {MAX_TIMESTAMP_NS} ns");
    // leading zeros are allowed; the value decides
    let secs = secs.trim_start_matches('0');
    if secs.len() > 11 {
        return Err(too_big());
    }
    let mut secs_n: u64 = 0;
    for b in secs.bytes() {
        secs_n = secs_n * 10 + u64::from(b - b'0');
    }
    let mut frac_ns: u64 = 0;
    for b in frac.bytes().chain(std::iter::repeat(b'0')).take(9) {
        frac_ns = frac_ns * 10 + u64::from(b - b'0');
    }
    secs_n
        .checked_mul(1_000_000_000)
        .and_then(|n| n.checked_add(frac_ns))
        .ok_or_else(too_big)
}

/// Hex digits only (`u8::from_str_radix` would take a leading `+`).
fn is_hex(s: &str) -> bool {
    s.bytes().all(|b| b.is_ascii_hexdigit())
}

fn hex_value(b: u8) -> u8 {
    match b {
        b'0'..=b'9' => b - b'0',
        b'a'..=b'f' => b - b'a' + 10,
        b'A'..=b'F' => b - b'A' + 10,
        _ => 0,
    }
}

fn parse_hex_bytes(s: &str) -> Result<Vec<u8>, String> {
    if !is_hex(s) {
        return Err(format!("data `{s}` is not hex"));
    }
    if !s.len().is_multiple_of(2) {
        return Err(format!("data `{s}` has an odd number of hex digits"));
    }
    if s.len() > 16 {
        return Err(format!("data `{s}` is longer than 8 bytes"));
    }
    Ok(s.as_bytes()
        .chunks_exact(2)
        .map(|p| hex_value(p[0]) << 4 | hex_value(p[1]))
        .collect())
}

/// Space or tab: the only field separators.
fn is_blank(c: char) -> bool {
    c == ' ' || c == '\t'
}

/// Parse one line (without the newline). The grammar (docs/canbus.md, "candump logs"):
///
/// ```text
/// line       = [blanks] timestamp blanks channel blanks frame [blanks direction] [blanks]
/// blanks     = 1*(SP / TAB)          ; a trailing CR is a blank too
/// timestamp  = "(" 1*DIGIT "." 1*9DIGIT ")"        ; ≤ u64::MAX ns
/// channel    = 1*VCHAR                              ; printable ASCII, no blank
/// frame      = std-id "#" data / ext-id "#" data / (std-id / ext-id) "#" remote
///            / err-id "#" data
/// std-id     = 3HEXDIG                              ; ≤ 7FF
/// ext-id     = 8HEXDIG                              ; ≤ 1FFFFFFF
/// err-id     = 8HEXDIG                              ; 20000000..3FFFFFFF (CAN_ERR_FLAG)
/// data       = 0*8(2HEXDIG)
/// remote     = ("R" / "r") [%x30-38]                ; requested length 0..8
/// direction  = "R" / "r" / "T" / "t"
/// ```
///
/// Only printable ASCII and tabs; at most [`MAX_LINE_BYTES`] bytes. CAN FD (`##`) is refused.
///
/// # Errors
/// A description of the first problem; [`read_log`] wraps it in a [`LineError`].
pub fn parse_line(line: &str) -> Result<LogRecord, String> {
    if line.len() > MAX_LINE_BYTES {
        return Err(format!(
            "line of {} bytes is longer than {MAX_LINE_BYTES} bytes",
            line.len()
        ));
    }
    let line = line.trim_matches(|c| is_blank(c) || c == '\r');
    if let Some(c) = line
        .chars()
        .find(|c| !(c.is_ascii_graphic() || is_blank(*c)))
    {
        return Err(format!(
            "character `{}` is not printable ASCII",
            c.escape_default()
        ));
    }
    let mut parts = line.split(is_blank).filter(|p| !p.is_empty());
    let (Some(ts), Some(channel), Some(body)) = (parts.next(), parts.next(), parts.next()) else {
        return Err("expected `(TIMESTAMP) CHANNEL ID#DATA`".to_string());
    };
    let direction = match parts.next() {
        None => None,
        Some("R" | "r") => Some(Direction::Rx),
        Some("T" | "t") => Some(Direction::Tx),
        Some(other) => return Err(format!("unexpected `{other}` after the frame")),
    };
    if let Some(extra) = parts.next() {
        return Err(format!("unexpected `{extra}` after the frame"));
    }
    let timestamp_ns = parse_timestamp(ts)?;
    let (id_s, data_s) = body
        .split_once('#')
        .ok_or_else(|| format!("frame `{body}` has no `#`"))?;
    if data_s.starts_with('#') {
        return Err("CAN FD frames (`##`) are not supported".to_string());
    }
    let extended = match id_s.len() {
        3 => false,
        8 => true,
        _ => return Err(format!("identifier `{id_s}` must have 3 or 8 hex digits")),
    };
    if !is_hex(id_s) {
        return Err(format!("identifier `{id_s}` is not hexadecimal"));
    }
    let id = u32::from_str_radix(id_s, 16)
        .map_err(|_| format!("identifier `{id_s}` is not hexadecimal"))?;
    let error_frame = extended && id & CAN_ERR_FLAG != 0;
    if extended && id > (CAN_ERR_FLAG | 0x1FFF_FFFF) {
        return Err(format!(
            "identifier `{id_s}` exceeds 29 bits (error frames: 20000000..3FFFFFFF)"
        ));
    }
    let frame = if let Some(r) = data_s.strip_prefix(['R', 'r']) {
        if error_frame {
            return Err(format!(
                "identifier `{id_s}` exceeds 29 bits (an error class cannot be a remote frame)"
            ));
        }
        let dlc = match r.as_bytes() {
            [] => 0,
            [d @ b'0'..=b'8'] => d - b'0',
            _ => return Err(format!("remote length `{r}` is not one digit 0..8")),
        };
        LogFrame::Remote { id, extended, dlc }
    } else {
        let data = parse_hex_bytes(data_s)?;
        if error_frame {
            LogFrame::Error {
                class: id & !CAN_ERR_FLAG,
                data,
            }
        } else if extended {
            LogFrame::Extended { id, data }
        } else {
            LogFrame::Standard(Frame::new(id, &data).map_err(|e| e.to_string())?)
        }
    };
    Ok(LogRecord {
        timestamp_ns,
        channel: channel.to_string(),
        frame,
        direction,
    })
}

/// One line of a byte stream, read in bounded pieces.
enum RawLine {
    /// The line (without its `\n`), at most [`MAX_LINE_BYTES`] bytes.
    Fits(Vec<u8>),
    /// Longer than [`MAX_LINE_BYTES`]: its first [`QUOTE_BYTES`] + 1 bytes and its length.
    TooLong(Vec<u8>, usize),
}

/// Read the next line without holding more than [`MAX_LINE_BYTES`] + 1 bytes of it; the rest
/// of an over-long line is skipped. `None` at the end of the input.
fn next_line<R: BufRead>(reader: &mut R) -> io::Result<Option<RawLine>> {
    let mut kept: Vec<u8> = Vec::new();
    let mut len = 0usize;
    let mut any = false;
    // each pass consumes at least one byte of the reader (or ends): bounded by the input
    loop {
        let buf = match reader.fill_buf() {
            Ok(b) => b,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        if buf.is_empty() {
            break;
        }
        any = true;
        let (piece, done) = match buf.iter().position(|&b| b == b'\n') {
            Some(i) => (&buf[..i], Some(i + 1)),
            None => (buf, None),
        };
        let room = (MAX_LINE_BYTES + 1).saturating_sub(kept.len());
        kept.extend_from_slice(&piece[..piece.len().min(room)]);
        len = len.saturating_add(piece.len());
        let used = done.unwrap_or(buf.len());
        reader.consume(used);
        if done.is_some() {
            break;
        }
    }
    if !any {
        return Ok(None);
    }
    Ok(Some(if len > MAX_LINE_BYTES {
        kept.truncate(QUOTE_BYTES + 1);
        RawLine::TooLong(kept, len)
    } else {
        RawLine::Fits(kept)
    }))
}

/// At most [`QUOTE_BYTES`] of a line, lossily decoded, `...` appended when cut.
fn quote(bytes: &[u8]) -> String {
    let mut q = String::from_utf8_lossy(&bytes[..bytes.len().min(QUOTE_BYTES)]).into_owned();
    if bytes.len() > QUOTE_BYTES {
        q.push_str("...");
    }
    q
}

/// A candump log read as a stream: one record or one bad line at a time, never holding more
/// than [`MAX_LINE_BYTES`] + 1 bytes of the input, so memory does not grow with the log
/// (`read_log` collects it for logs known to be small: fixtures, tests). Blank lines are
/// skipped; a line longer than [`MAX_LINE_BYTES`] is reported without being held, and bytes
/// that are not UTF-8 make their line bad, not the read. After a reader error it ends.
pub struct LogReader<R> {
    reader: R,
    line_no: usize,
    failed: bool,
}

impl<R: BufRead> LogReader<R> {
    /// A stream over `reader`.
    pub fn new(reader: R) -> Self {
        Self {
            reader,
            line_no: 0,
            failed: false,
        }
    }

    /// Lines read so far (blank ones included).
    pub fn lines_read(&self) -> usize {
        self.line_no
    }
}

impl<R: BufRead> Iterator for LogReader<R> {
    /// A record, or why a line is not one; [`ReadError`] when the reader fails (then the
    /// stream ends).
    type Item = Result<Result<LogRecord, LineError>, ReadError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        // each pass reads one line: bounded by the input
        loop {
            let raw = match next_line(&mut self.reader) {
                Ok(Some(raw)) => raw,
                Ok(None) => return None,
                Err(e) => {
                    self.failed = true;
                    return Some(Err(ReadError::Io(e)));
                }
            };
            self.line_no += 1;
            let (bytes, result) = match raw {
                RawLine::TooLong(head, len) => (
                    head,
                    Err(format!(
                        "line of {len} bytes is longer than {MAX_LINE_BYTES} bytes"
                    )),
                ),
                RawLine::Fits(bytes) => {
                    let result = match std::str::from_utf8(&bytes) {
                        Err(_) => Err("bytes that are not ASCII".to_string()),
                        Ok(t) if t.trim_matches(|c| is_blank(c) || c == '\r').is_empty() => {
                            continue
                        }
                        Ok(t) => parse_line(t),
                    };
                    (bytes, result)
                }
            };
            return Some(Ok(result.map_err(|reason| LineError {
                line_no: self.line_no,
                line: quote(&bytes),
                reason,
            })));
        }
    }
}

/// Read every record of a log known to be small (fixtures, tests): a [`LogReader`] collected,
/// so memory grows with the log; stream with [`LogReader`] otherwise. Bad lines are reported
/// (their text cut to [`QUOTE_BYTES`]), the others kept.
///
/// # Errors
/// [`ReadError::Io`] when the reader fails (not for bad lines).
pub fn read_log<R: BufRead>(reader: R) -> Result<(Vec<LogRecord>, Vec<LineError>), ReadError> {
    let mut records = Vec::new();
    let mut errors = Vec::new();
    for item in LogReader::new(reader) {
        match item? {
            Ok(r) => records.push(r),
            Err(e) => errors.push(e),
        }
    }
    Ok((records, errors))
}

fn hex(data: &[u8]) -> String {
    data.iter().map(|b| format!("{b:02X}")).collect()
}

/// Format one record as a line (without the newline).
pub fn format_record(r: &LogRecord) -> String {
    let ts = format!(
        "({}.{:06})",
        r.timestamp_ns / 1_000_000_000,
        (r.timestamp_ns % 1_000_000_000) / 1_000
    );
    let body = match &r.frame {
        LogFrame::Standard(f) => format!("{:03X}#{}", f.id(), hex(f.data())),
        LogFrame::Extended { id, data } => format!("{id:08X}#{}", hex(data)),
        LogFrame::Remote { id, extended, dlc } => {
            let id = if *extended {
                format!("{id:08X}")
            } else {
                format!("{id:03X}")
            };
            if *dlc == 0 {
                format!("{id}#R")
            } else {
                format!("{id}#R{dlc}")
            }
        }
        LogFrame::Error { class, data } => format!("{:08X}#{}", class | CAN_ERR_FLAG, hex(data)),
    };
    let dir = match r.direction {
        None => "",
        Some(Direction::Rx) => " R",
        Some(Direction::Tx) => " T",
    };
    format!("{ts} {} {body}{dir}", r.channel)
}

/// Errors of [`CandumpWriter::write_event`].
#[derive(Debug, Error)]
pub enum WriteError {
    /// The writer failed.
    #[error("writing the log: {0}")]
    Io(#[from] io::Error),
    /// The event's timestamp (origin plus simulated time) does not fit.
    #[error(transparent)]
    Timestamp(#[from] TimestampOverflow),
}

/// What a candump log records of a bus event, and when on the bus clock \[ns\]: a delivered
/// frame (stamped at the end of its interframe space), an error frame (`CAN_ERR_PROT |
/// CAN_ERR_BUSERROR`, data byte 2 = `CAN_ERR_PROT_BIT`) or a bus-off (`CAN_ERR_BUSOFF |
/// CAN_ERR_BUSERROR`). [`CandumpWriter`] writes these; a run that keeps its frames in memory
/// (the Python package's `walker.sil`) keeps the same.
pub fn event_frame(ev: &BusEvent) -> (u64, LogFrame) {
    match ev {
        BusEvent::Delivered(d) => (d.t_end_ns, LogFrame::Standard(d.frame)),
        BusEvent::ErrorFrame { t_end_ns, .. } => (
            *t_end_ns,
            LogFrame::Error {
                class: CAN_ERR_PROT | CAN_ERR_BUSERROR,
                data: vec![0, 0, 0x01, 0, 0, 0, 0, 0],
            },
        ),
        BusEvent::BusOff { t_ns, .. } => (
            *t_ns,
            LogFrame::Error {
                class: CAN_ERR_BUSOFF | CAN_ERR_BUSERROR,
                data: vec![0; 8],
            },
        ),
    }
}

/// Writes bus events as a candump log.
#[derive(Debug)]
pub struct CandumpWriter<W: Write> {
    out: W,
    channel: String,
    origin_ns: u64,
}

impl<W: Write> CandumpWriter<W> {
    /// A writer on `channel` whose timestamps are `origin_ns` + simulated time.
    pub fn new(out: W, channel: &str, origin_ns: u64) -> Self {
        CandumpWriter {
            out,
            channel: channel.to_string(),
            origin_ns,
        }
    }

    /// Write one record.
    ///
    /// # Errors
    /// The writer's.
    pub fn write_record(&mut self, r: &LogRecord) -> io::Result<()> {
        writeln!(self.out, "{}", format_record(r))
    }

    /// The record for a bus event ([`event_frame`]).
    ///
    /// # Errors
    /// [`TimestampOverflow`] when the origin plus the event's time does not fit.
    pub fn record_for(&self, ev: &BusEvent) -> Result<LogRecord, TimestampOverflow> {
        let (t, frame) = event_frame(ev);
        Ok(LogRecord {
            timestamp_ns: stamp_ns(self.origin_ns, t)?,
            channel: self.channel.clone(),
            frame,
            direction: None,
        })
    }

    /// Write one bus event.
    ///
    /// # Errors
    /// [`WriteError::Timestamp`] when its timestamp does not fit (nothing is written),
    /// [`WriteError::Io`] when the writer fails.
    pub fn write_event(&mut self, ev: &BusEvent) -> Result<(), WriteError> {
        let r = self.record_for(ev)?;
        Ok(self.write_record(&r)?)
    }

    /// Flush and return the writer.
    ///
    /// # Errors
    /// The writer's.
    pub fn finish(mut self) -> io::Result<W> {
        self.out.flush()?;
        Ok(self.out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A log read as a stream holds no more than a line: an endless log of records (and one
    /// of bad lines) yields entry after entry, where collecting it would never end.
    #[test]
    fn an_endless_log_streams_entry_by_entry() {
        let line = b"(1.000000) vcan0 123#0011\n";
        let endless = Endless { line, pos: 0 };
        let mut reader = LogReader::new(std::io::BufReader::new(endless));
        for _ in 0..200_000 {
            let r = reader.next().unwrap().unwrap().unwrap();
            assert_eq!(r.channel, "vcan0");
        }
        assert_eq!(reader.lines_read(), 200_000);
        let bad = Endless {
            line: b"garbage\n",
            pos: 0,
        };
        let mut reader = LogReader::new(std::io::BufReader::new(bad));
        for n in 1..=200_000 {
            let e = reader.next().unwrap().unwrap().unwrap_err();
            assert_eq!(e.line_no, n);
        }
        // no newline ever: one over-long line per read, never the whole input held (the
        // reader ends when the input does; here a bounded one of 8 MiB of zeros)
        let zeros = std::io::Read::take(std::io::repeat(0), 8 << 20);
        let mut reader = LogReader::new(std::io::BufReader::new(zeros));
        let e = reader.next().unwrap().unwrap().unwrap_err();
        assert!(e.reason.contains("longer than 256 bytes"), "{e}");
        assert!(reader.next().is_none());
    }

    /// `line`, repeated for ever.
    struct Endless {
        line: &'static [u8],
        pos: usize,
    }

    impl std::io::Read for Endless {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            for b in buf.iter_mut() {
                *b = self.line[self.pos];
                self.pos = (self.pos + 1) % self.line.len();
            }
            Ok(buf.len())
        }
    }
    use proptest::prelude::*;

    #[test]
    fn parses_the_reference_line() {
        let r = parse_line("(1700000000.123456) vcan0 123#DEADBEEF").unwrap();
        assert_eq!(r.timestamp_ns, 1_700_000_000_123_456_000);
        assert_eq!(r.channel, "vcan0");
        assert_eq!(
            r.frame,
            LogFrame::Standard(Frame::new(0x123, &[0xDE, 0xAD, 0xBE, 0xEF]).unwrap())
        );
        assert_eq!(format_record(&r), "(1700000000.123456) vcan0 123#DEADBEEF");
    }

    #[test]
    fn python_can_variants() {
        let r = parse_line("(0.000000) can0 072#01 R").unwrap();
        assert_eq!(r.direction, Some(Direction::Rx));
        let r = parse_line("(1.5) vcan0 20000080#").unwrap();
        assert_eq!(
            r.frame,
            LogFrame::Error {
                class: CAN_ERR_BUSERROR,
                data: vec![]
            }
        );
        let r = parse_line("(1.0) vcan0 12345678#00").unwrap();
        assert!(matches!(
            r.frame,
            LogFrame::Extended {
                id: 0x1234_5678,
                ..
            }
        ));
        let r = parse_line("(1.0) vcan0 123#R4").unwrap();
        assert_eq!(
            r.frame,
            LogFrame::Remote {
                id: 0x123,
                extended: false,
                dlc: 4
            }
        );
        assert_eq!(format_record(&r), "(1.000000) vcan0 123#R4");
    }

    #[test]
    fn bad_lines_are_named_and_nothing_else_is_lost() {
        let text = "(1.000000) vcan0 062#0100000A000000\n\
                    garbage\n\
                    \n\
                    (2.000000) vcan0 8000#00\n\
                    (x.1) vcan0 062#00\n\
                    (3.000000) vcan0 062#0G\n\
                    (4.000000) vcan0 800#00\n\
                    (5.000000) vcan0 072#000102030405060708\n\
                    (6.000000) vcan0 072#0102 Q\n\
                    (7.000000) vcan0 073#0102030405060A\n";
        let (recs, errs) = read_log(text.as_bytes()).unwrap();
        assert_eq!(recs.len(), 2);
        assert_eq!(recs[1].timestamp_ns, 7_000_000_000);
        let lines: Vec<usize> = errs.iter().map(|e| e.line_no).collect();
        assert_eq!(lines, vec![2, 4, 5, 6, 7, 8, 9]);
        let msg = errs[0].to_string();
        assert!(
            msg.starts_with("line 2:") && msg.contains("garbage"),
            "{msg}"
        );
        assert!(errs[1].reason.contains("8000"), "{}", errs[1].reason);
        assert!(errs[4].reason.contains("0x800"), "{}", errs[4].reason);
        assert!(errs[5].reason.contains("8 bytes"), "{}", errs[5].reason);
    }

    #[test]
    fn a_timestamp_past_u64_is_an_error_not_a_wrap() {
        let ev = BusEvent::BusOff {
            node: crate::bus::NodeHandle(0),
            t_ns: 2_000_000_000,
        };
        let origin_ns = 18_446_744_073_000_000_000;
        let mut w = CandumpWriter::new(Vec::new(), "vcan0", origin_ns);
        match w.write_event(&ev) {
            Err(WriteError::Timestamp(e)) => {
                assert_eq!((e.origin_ns, e.t_ns), (origin_ns, 2_000_000_000));
            }
            other => panic!("{other:?}"),
        }
        let early = BusEvent::BusOff {
            node: crate::bus::NodeHandle(0),
            t_ns: 500_000_000,
        };
        w.write_event(&early).unwrap();
        let text = String::from_utf8(w.finish().unwrap()).unwrap();
        assert_eq!(text.lines().count(), 1, "{text}");
        assert!(text.starts_with("(18446744073.500000) vcan0 "), "{text}");
    }

    proptest! {
        #[test]
        fn standard_frames_round_trip(ts in 0u64..4_000_000_000_000_000, id in 0u32..0x800,
                                      data in proptest::collection::vec(any::<u8>(), 0..=8)) {
            let r = LogRecord {
                timestamp_ns: ts / 1000 * 1000,
                channel: "vcan0".into(),
                frame: LogFrame::Standard(Frame::new(id, &data).unwrap()),
                direction: None,
            };
            let line = format_record(&r);
            prop_assert_eq!(parse_line(&line), Ok(r));
        }

        #[test]
        fn arbitrary_lines_never_panic(s in ".{0,60}") {
            let _ = parse_line(&s);
        }
    }
}
