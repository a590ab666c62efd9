"""The candump log grammar the Rust reader (canbus/src/candump.rs, `parse_line`) accepts, for
the bus monitor: one line at a time, in bounded pieces.

    line       = [blanks] timestamp blanks channel blanks frame [blanks direction] [blanks]
    blanks     = 1*(SP / TAB)          ; a trailing CR is a blank too
    timestamp  = "(" 1*DIGIT "." 1*9DIGIT ")"        ; <= 2**64 - 1 ns
    channel    = 1*VCHAR                              ; printable ASCII, no blank
    frame      = std-id "#" data / ext-id "#" data / (std-id / ext-id) "#" remote
               / err-id "#" data
    std-id     = 3HEXDIG                              ; <= 7FF
    ext-id     = 8HEXDIG                              ; <= 1FFFFFFF
    err-id     = 8HEXDIG                              ; 20000000..3FFFFFFF (CAN_ERR_FLAG)
    data       = 0*8(2HEXDIG)
    remote     = ("R" / "r") [%x30-38]                ; requested length 0..8
    direction  = "R" / "r" / "T" / "t"

Only printable ASCII and tabs, at most MAX_LINE_BYTES bytes before the newline; CAN FD (`##`)
is refused. canbus/tests/fixtures/candump_{good,malformed}.log are the shared examples.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import BinaryIO, Iterator, Optional, Union

import can

#: The longest line accepted, in bytes before the newline (as canbus::candump::MAX_LINE_BYTES).
MAX_LINE_BYTES = 256
#: How much of a bad line is quoted, in bytes (as canbus::candump::QUOTE_BYTES).
QUOTE_BYTES = 120
#: Pieces in which the rest of an over-long line is skipped.
SKIP_CHUNK_BYTES = 1 << 16
MAX_TIMESTAMP_NS = 2**64 - 1
CAN_ERR_FLAG = 0x2000_0000

_TIMESTAMP = re.compile(rb"\(([0-9]+)\.([0-9]{1,9})\)")
_HEX = re.compile(rb"[0-9A-Fa-f]*")
_BLANKS = re.compile(rb"[ \t]+")
_PRINTABLE = re.compile(rb"[\x20-\x7e\t]*")


class Malformed(ValueError):
    """A line that is not a candump record; the message says why."""


@dataclass(frozen=True)
class Record:
    """One line of a log, as canbus::candump::LogRecord."""

    timestamp_ns: int
    channel: str
    #: "std", "ext", "rtr" (standard remote), "xrtr" (extended remote), "err" (id = error class)
    kind: str
    id: int
    dlc: int
    data: bytes
    #: "R", "T" or None
    direction: Optional[str]

    def canonical(self) -> str:
        """The form of canbus/tests/fixtures/candump_good.expected."""
        width = 3 if self.kind in ("std", "rtr") else 8
        return (f"{self.timestamp_ns} {self.channel} {self.kind} {self.id:0{width}X} {self.dlc} "
                f"{self.data.hex().upper() or '-'} {self.direction or '-'}")

    def to_message(self) -> can.Message:
        """The can.Message python-can's reader would make of the line."""
        ts = self.timestamp_ns / 1e9
        is_rx = self.direction != "T"
        if self.kind == "err":
            return can.Message(timestamp=ts, is_error_frame=True, channel=self.channel,
                               arbitration_id=self.id, data=self.data, is_rx=is_rx)
        remote = self.kind in ("rtr", "xrtr")
        return can.Message(timestamp=ts, arbitration_id=self.id,
                           is_extended_id=self.kind in ("ext", "xrtr"), is_remote_frame=remote,
                           dlc=self.dlc, data=None if remote else self.data,
                           channel=self.channel, is_rx=is_rx)


def _timestamp_ns(tok: bytes) -> int:
    m = _TIMESTAMP.fullmatch(tok)
    if m is None:
        raise Malformed(f"timestamp `{tok.decode()}` is not of the form (SECONDS.FRACTION), "
                        "1 to 9 fraction digits")
    ns = int(m.group(1)) * 1_000_000_000 + int(m.group(2).ljust(9, b"0"))
    if ns > MAX_TIMESTAMP_NS:
        raise Malformed(f"timestamp `{tok.decode()}` exceeds {MAX_TIMESTAMP_NS} ns")
    return ns


def _hex(text: bytes) -> bool:
    return _HEX.fullmatch(text) is not None


def _frame(body: bytes) -> tuple[str, int, int, bytes]:
    """(kind, id, dlc, data) of `ID#DATA`."""
    b = body.decode()
    id_s, sep, data_s = body.partition(b"#")
    if not sep:
        raise Malformed(f"frame `{b}` has no `#`")
    if data_s.startswith(b"#"):
        raise Malformed("CAN FD frames (`##`) are not supported")
    if len(id_s) not in (3, 8):
        raise Malformed(f"identifier `{id_s.decode()}` must have 3 or 8 hex digits")
    if not _hex(id_s):
        raise Malformed(f"identifier `{id_s.decode()}` is not hexadecimal")
    extended = len(id_s) == 8
    ident = int(id_s, 16)
    if not extended and ident > 0x7FF:
        raise Malformed(f"identifier `{id_s.decode()}` exceeds 0x7FF")
    if extended and ident > (CAN_ERR_FLAG | 0x1FFF_FFFF):
        raise Malformed(f"identifier `{id_s.decode()}` exceeds 29 bits "
                        "(error frames: 20000000..3FFFFFFF)")
    error = extended and bool(ident & CAN_ERR_FLAG)
    if data_s[:1] in (b"R", b"r"):
        if error:
            raise Malformed(f"identifier `{id_s.decode()}` is an error class, not a remote frame")
        rest = data_s[1:]
        if rest and not (len(rest) == 1 and b"0"[0] <= rest[0] <= b"8"[0]):
            raise Malformed(f"remote length `{rest.decode()}` is not one digit 0..8")
        return ("xrtr" if extended else "rtr"), ident, int(rest or b"0"), b""
    if not _hex(data_s):
        raise Malformed(f"data `{data_s.decode()}` is not hex")
    if len(data_s) % 2:
        raise Malformed(f"data `{data_s.decode()}` has an odd number of hex digits")
    if len(data_s) > 16:
        raise Malformed(f"data `{data_s.decode()}` is longer than 8 bytes")
    data = bytes.fromhex(data_s.decode())
    if error:
        return "err", ident & ~CAN_ERR_FLAG, len(data), data
    return ("ext" if extended else "std"), ident, len(data), data


def parse_line(line: Union[bytes, str]) -> Record:
    """One line (without its newline) as a Record; Malformed says why it is not one."""
    raw = line.encode("utf-8", "surrogateescape") if isinstance(line, str) else line
    if len(raw) > MAX_LINE_BYTES:
        raise Malformed(f"line of {len(raw)} bytes is longer than {MAX_LINE_BYTES} bytes")
    raw = raw.strip(b" \t\r")
    if _PRINTABLE.fullmatch(raw) is None:
        bad = next(c for c in raw if not (0x20 <= c <= 0x7E or c == 0x09))
        raise Malformed(f"byte 0x{bad:02X} is not printable ASCII")
    parts = [p for p in _BLANKS.split(raw) if p]
    if len(parts) < 3:
        raise Malformed("expected `(TIMESTAMP) CHANNEL ID#DATA`")
    direction = None
    if len(parts) >= 4:
        if parts[3] not in (b"R", b"r", b"T", b"t"):
            raise Malformed(f"unexpected `{parts[3].decode()}` after the frame")
        direction = parts[3].decode().upper()
    if len(parts) > 4:
        raise Malformed(f"unexpected `{parts[4].decode()}` after the frame")
    ts = _timestamp_ns(parts[0])
    kind, ident, dlc, data = _frame(parts[2])
    return Record(ts, parts[1].decode(), kind, ident, dlc, data, direction)


@dataclass(frozen=True)
class RawLine:
    """A line as read: its number, its first bytes (all of it when it fits) and its length."""

    number: int
    head: bytes
    length: int

    @property
    def fits(self) -> bool:
        return self.length <= MAX_LINE_BYTES

    def quote(self) -> str:
        """At most QUOTE_BYTES of the line, `...` appended when cut, bytes that are not
        printable ASCII escaped."""
        text = self.head[:QUOTE_BYTES].decode("ascii", "backslashreplace")
        text = "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)
        return text + ("..." if self.length > QUOTE_BYTES else "")


def raw_lines(f: BinaryIO) -> Iterator[RawLine]:
    """The lines of a binary stream (split at `\\n` only), never holding more than
    MAX_LINE_BYTES + 1 bytes of one: the rest of an over-long line is skipped in pieces."""
    number = 0
    # each pass reads at least one byte or ends: bounded by the stream's length
    while True:
        piece = f.readline(MAX_LINE_BYTES + 1)
        if not piece:
            return
        number += 1
        if piece.endswith(b"\n"):
            yield RawLine(number, piece[:-1], len(piece) - 1)
            continue
        length = len(piece)
        if length > MAX_LINE_BYTES:
            # each pass reads at least one byte or ends
            while True:
                more = f.readline(SKIP_CHUNK_BYTES)
                if not more:
                    break
                if more.endswith(b"\n"):
                    length += len(more) - 1
                    break
                length += len(more)
            piece = piece[:QUOTE_BYTES + 1]
        yield RawLine(number, piece, length)


def records(f: BinaryIO) -> Iterator[tuple[RawLine, Union[Record, Malformed]]]:
    """Every non-blank line with its Record or why it is malformed. Blank lines (blanks and
    CR only, within MAX_LINE_BYTES) are skipped."""
    for raw in raw_lines(f):
        if not raw.fits:
            yield raw, Malformed(f"line of {raw.length} bytes is longer than "
                                 f"{MAX_LINE_BYTES} bytes")
            continue
        if not raw.head.strip(b" \t\r"):
            continue
        try:
            yield raw, parse_line(raw.head)
        except Malformed as e:
            yield raw, e
