#!/usr/bin/env python3
"""Bus monitor for the walker's CAN bus (python-can + cantools with protocol/walker.dbc).

Decodes live traffic from any python-can interface or a candump log and shows per-message
rates, node heartbeats and states, faults (Fault messages, heartbeat fault flags, error
frames, undecodable frames) and the bus load; can record what it sees to a candump log.

    # the simulated bus (canbus-demo or walker sil with --socketcand 127.0.0.1:PORT)
    .venv/bin/python python/walker_monitor.py --interface socketcand --channel vcan0 \
        --host 127.0.0.1 --port PORT --idle-exit 2   # ends when the run ends
    # the robot
    .venv/bin/python python/walker_monitor.py --interface socketcan --channel can0
    .venv/bin/python python/walker_monitor.py --interface slcan --channel /dev/ttyACM0
    # a log
    .venv/bin/python python/walker_monitor.py --log run.log --json
    # ask the left ankle for its identity and fault history (Command opcodes 8 and 9)
    .venv/bin/python python/walker_monitor.py ... --send 042#080000000000 --send 042#090000000000

Each node's `identity` (firmware version, build id, 96-bit chip UID, reset cause, where its
parameters and encoder zero came from), `fault_history` (newest first: code, the node state
it left, detail, uptime) and `command_acks` are in the summary.

Bus load = bits on the wire (actual bit stuffing of each frame, CRC-15 included, plus the
3-bit interframe space, as the Rust simulator counts them) / (bit rate x observed time span).

A log is read line by line in bounded pieces with the grammar of canbus/src/candump.rs
(candump_grammar.py): a malformed line is counted (`malformed_lines`), the first few quoted
(`bad_lines`, cut short), never decoded; memory does not grow with the log. --log and --dbc
must be regular files (a FIFO is refused without waiting for a writer, /dev/zero and other
devices are refused); the DBC at most MAX_DBC_BYTES (1 MiB).

Live socketcand is read by the monitor's own client (SocketcandBus: python-can's interface
raises on a frame it cannot parse and then on every later read). Every element that is not a
frame `< frame ID SECONDS.FRACTION DATA >` (ID 3 hex digits <= 7FF or 8 <= 1FFFFFFF, DATA 0 to
8 bytes), stray bytes between elements, an element longer than 256 bytes, a server's
`< error ... >`, is counted (`malformed_frames`), the first few quoted (`bad_frames`: `frame`,
`text`, `reason`) and named on stderr, never decoded; the next frame is read as usual. Any
frame from any interface with more than 8 bytes, an identifier wider than its format, CAN FD
or a non-finite timestamp is a malformed frame too. python-can's log records pass at most 20,
then one a second, cut to 300 characters (`log_records_suppressed` counts the rest).

Checks, each in the summary and, when it finds something, in `warnings` and on stderr: frames
whose length differs from the DBC's (`faults.wrong_length`, not decoded, also counted in
`undecodable`); frames on another channel than the monitored one (`channel`: --channel, or
the first frame's; `faults.other_channels`, not decoded); timestamps earlier than a frame
before them (`faults.backwards_timestamps`, `largest_step_back_s`); a load the bit rate cannot
carry over the capture or in the busiest window (`faults.impossible_load`,
`bus_load_window_peak`).

Exit codes: 0 the run ended (end of the log, --duration, --idle-exit, the server closed the
connection, Ctrl-C), malformed input included; 1 a run that had started failed (a read
error in the log, the bus or the connection failed, the record file failed): the summary of
what was seen is printed, the reason on stderr; 2 nothing was monitored: bad flags, an unknown
--interface, a channel name socketcand cannot carry, a --log or --dbc that is missing, not a
regular file, over its limit or (the DBC) not the walker protocol, a --record that cannot be
created, a bus that cannot be opened (no server, the server refuses the channel, no handshake
within HANDSHAKE_TIMEOUT_S, python-can cannot open the interface or channel). Never a
traceback for any of these.
"""

from __future__ import annotations

import argparse
import collections
import io
import json
import logging
import math
import os
import pathlib
import re
import select
import socket
import stat
import sys
import time
from dataclasses import dataclass, field
from typing import BinaryIO, Iterable, Iterator, Optional, Union

import can
import cantools

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import candump_grammar  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
DEFAULT_DBC = ROOT / "protocol" / "walker.dbc"
NODES = ("HOST", "LEFT_ANKLE", "RIGHT_ANKLE")
#: Nodes that need not send heartbeats: the host (a PC, or the simulator's host in `walker sil`,
#: which sends commands only). Without heartbeats the table shows what they sent instead of a
#: state; an ankle without heartbeats is shown as not alive.
HEARTBEAT_OPTIONAL = ("HOST",)
#: Malformed log lines quoted in `bad_lines` and on stderr; the rest are only counted.
MAX_QUOTED_LINES = 5
#: Fault-history entries and command acknowledgements kept per node.
MAX_HISTORY_ENTRIES = 32
#: Fault events kept in `faults.events` (`faults.events_total` counts them all).
MAX_FAULT_EVENTS = 1000
#: Distinct unknown identifiers counted one by one (`faults.unknown_ids`); frames with further
#: identifiers go to `faults.unknown_ids_other`.
MAX_UNKNOWN_IDS = 256
#: The bus-load window is summed in this many buckets (its resolution: window / buckets).
WINDOW_BUCKETS = 1000
#: Channels other than the monitored one counted by name (`faults.other_channels`); frames on
#: further channels are counted under "(more)".
MAX_OTHER_CHANNELS = 16
#: A load above 100 % by more than this (after taking off one frame, which may straddle the
#: edge of the span) cannot be: the timestamps are compressed or --bitrate is wrong.
LOAD_TOLERANCE = 0.02
#: The DBC is read whole: at most this many bytes (protocol/walker.dbc is about 19 kB).
MAX_DBC_BYTES = 1 << 20
#: socketcand: the longest `< ... >` element accepted, in bytes (the longest frame,
#: `< frame 1FFFFFFF 18446744073.709551615 0011223344556677 >`, has 57).
MAX_ELEMENT_BYTES = 256
#: socketcand: bytes read from the socket at once.
RECV_BYTES = 1 << 16
#: socketcand: seconds to connect, and for the whole handshake (`< hi >`, `< ok >`, `< ok >`).
CONNECT_TIMEOUT_S = 5.0
HANDSHAKE_TIMEOUT_S = 5.0
#: python-can's log records: the first LOG_BURST pass, then at most one per LOG_INTERVAL_S;
#: each cut to LOG_RECORD_CHARS characters, control characters escaped.
LOG_BURST = 20
LOG_INTERVAL_S = 1.0
LOG_RECORD_CHARS = 300


# --- frame length on the wire -------------------------------------------------------------

def crc15(bits: list[int]) -> int:
    """CRC-15/CAN (polynomial 0x4599, initial value 0)."""
    crc = 0
    for b in bits:
        nxt = b ^ ((crc >> 14) & 1)
        crc = (crc << 1) & 0x7FFF
        if nxt:
            crc ^= 0x4599
    return crc


def _push(bits: list[int], value: int, n: int) -> None:
    bits.extend((value >> i) & 1 for i in range(n - 1, -1, -1))


def frame_bits(can_id: int, data: bytes) -> int:
    """Bits of a standard data frame on the wire, actual stuff bits and interframe space
    included (the same count as canbus::bits::actual_frame_bits)."""
    bits: list[int] = [0]
    _push(bits, can_id & 0x7FF, 11)
    bits += [0, 0, 0]
    _push(bits, len(data), 4)
    for byte in data:
        _push(bits, byte, 8)
    _push(bits, crc15(bits), 15)
    stuffed, run, last = 0, 0, None
    for b in bits:
        if b == last:
            run += 1
        else:
            run, last = 1, b
        if run == 5:
            stuffed += 1
            last, run = 1 - b, 1
    return len(bits) + stuffed + 13


def worst_case_bits(dlc: int) -> int:
    """Worst-case length (Davis et al. 2007) of a standard frame with `dlc` bytes."""
    exposed = 34 + 8 * dlc
    return exposed + 13 + (exposed - 1) // 4


# --- frames that are no CAN frame ----------------------------------------------------------

def frame_problem(msg: can.Message) -> Optional[str]:
    """Why `msg` is no classic CAN frame the monitor can count (None: it is one): a
    non-finite timestamp, CAN FD, more than 8 data bytes, an identifier wider than its format
    (11 bits standard, 29 extended) or negative."""
    ts = msg.timestamp
    if ts is not None and not (isinstance(ts, (int, float)) and math.isfinite(ts)):
        return f"timestamp {ts!r} is not a finite number"
    if getattr(msg, "is_fd", False):
        return "CAN FD frames are not supported"
    data = msg.data if msg.data is not None else b""
    if len(data) > 8 or not 0 <= msg.dlc <= 8:
        return f"{max(len(data), msg.dlc)} data bytes, more than 8"
    ident = msg.arbitration_id
    if msg.is_error_frame:
        return None  # python-can's error frames carry the error class here
    if ident < 0:
        return f"identifier {ident} is negative"
    if msg.is_extended_id and ident > 0x1FFF_FFFF:
        return f"identifier 0x{ident:X} exceeds 29 bits"
    if not msg.is_extended_id and ident > 0x7FF:
        return f"identifier 0x{ident:X} exceeds 11 bits (a standard frame)"
    return None


def describe(msg: can.Message) -> str:
    """`msg` in candump form, cut and escaped as a quoted log line."""
    data = bytes(msg.data or b"")
    text = (f"({msg.timestamp}) {msg.channel} {msg.arbitration_id:X}#{data.hex().upper()}"
            .encode("ascii", "backslashreplace"))
    return candump_grammar.RawLine(0, text[:candump_grammar.QUOTE_BYTES + 1], len(text)).quote()


# --- the monitor ------------------------------------------------------------------------

@dataclass
class MessageStats:
    name: str
    frame_id: int
    count: int = 0
    first: float = 0.0
    last: float = 0.0
    signals: dict = field(default_factory=dict)


@dataclass
class NodeStatus:
    heartbeats: int = 0
    state: Optional[str] = None
    fault_flags: int = 0
    faults: list = field(default_factory=list)
    uptime_s: Optional[float] = None
    last_seen: Optional[float] = None
    identity: dict = field(default_factory=dict)
    fault_history: dict = field(default_factory=dict)
    acks: list = field(default_factory=list)
    #: Frames this node sent (any message the DBC gives it as sender), by message name.
    sent: dict = field(default_factory=dict)


class Monitor:
    """Accumulates what a stream of can.Message shows."""

    def __init__(self, db, bitrate: int = 500_000, stale_s: float = 0.3, window_s: float = 1.0,
                 channel: Optional[str] = None, echo=None):
        """`channel`: the channel monitored (None: the first frame's); `echo`: a text stream
        on which the first MAX_QUOTED_LINES malformed frames are named (None: silent)."""
        if isinstance(bitrate, bool) or not isinstance(bitrate, int) or bitrate <= 0:
            raise ValueError(f"bit rate {bitrate!r} is not a positive whole number of bit/s")
        for name, v in (("stale_s", stale_s), ("window_s", window_s)):
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"{name} {v!r} is not a positive finite number of seconds")
        self.db = db
        self.bitrate = bitrate
        self.stale_s = stale_s
        self.window_s = window_s
        self.messages: dict[int, MessageStats] = {}
        self.nodes: dict[str, NodeStatus] = {n: NodeStatus() for n in NODES}
        self.fault_events: list[dict] = []
        self.fault_events_total = 0
        self.error_frames = 0
        self.unknown: dict[int, int] = {}
        self.unknown_other = 0
        self.undecodable = 0
        self.frames = 0
        self.bits = 0
        self.first: Optional[float] = None
        self.last: Optional[float] = None
        # (bucket index, bits) of the last window, oldest first, at most WINDOW_BUCKETS + 1
        self.recent: collections.deque[tuple[int, int]] = collections.deque()
        self.bucket_s = window_s / WINDOW_BUCKETS
        self.window_bits = 0  # the sum over `recent`
        self.window_peak_bits = 0
        self.max_frame_bits = 0
        fault = db.get_message_by_name("Fault_LEFT_ANKLE").get_signal_by_name("code")
        self.fault_names = {int(k): str(v) for k, v in fault.choices.items()}
        #: The monitored channel: frames on others are counted, not decoded. None: the first
        #: frame's channel.
        self.channel = channel
        self.other_channels: dict[str, int] = {}
        self.wrong_length: dict[str, int] = {}
        self.backwards = 0
        self.largest_step_back = 0.0
        #: Frames that are no CAN frame (unparsable live text, identifiers wider than their
        #: format, more than 8 bytes, a non-finite timestamp): counted, the first few quoted.
        self.malformed_frames = 0
        self.bad_frames: list[dict] = []
        self.received = 0  # everything offered: frames, error frames, malformed frames
        self.echo = echo

    def bad_frame(self, text: str, reason: str) -> None:
        """A received frame that is no CAN frame: counted, the first few quoted (`text` is
        already cut and escaped) and named on `echo`."""
        self.received += 1
        self.malformed_frames += 1
        if len(self.bad_frames) < MAX_QUOTED_LINES:
            self.bad_frames.append({"frame": self.received, "text": text, "reason": reason})
            if self.echo is not None:
                print(f"walker_monitor: bad frame #{self.received} ({reason}): {text}",
                      file=self.echo)

    def feed(self, msg: can.Message) -> None:
        problem = frame_problem(msg)
        if problem is not None:
            self.bad_frame(describe(msg), problem)
            return
        self.received += 1
        if msg.channel is not None:
            ch = str(msg.channel)
            if self.channel is None:
                self.channel = ch
            elif ch != self.channel:
                key = ch if (ch in self.other_channels
                             or len(self.other_channels) < MAX_OTHER_CHANNELS) else "(more)"
                self.other_channels[key] = self.other_channels.get(key, 0) + 1
                return
        ts = float(msg.timestamp or 0.0)
        if self.last is not None and ts < self.last:
            self.backwards += 1
            self.largest_step_back = max(self.largest_step_back, self.last - ts)
        self.first = ts if self.first is None else min(self.first, ts)
        self.last = ts if self.last is None else max(self.last, ts)
        if msg.is_error_frame:
            self.error_frames += 1
            return
        self.frames += 1
        if not msg.is_extended_id and not msg.is_remote_frame:
            nbits = frame_bits(msg.arbitration_id, bytes(msg.data))
        else:
            nbits = worst_case_bits(msg.dlc) + 20
        self.bits += nbits
        self.max_frame_bits = max(self.max_frame_bits, nbits)
        self._window_add(ts, nbits)
        try:
            m = self.db.get_message_by_frame_id(msg.arbitration_id)
        except KeyError:
            self._count_unknown(msg.arbitration_id)
            return
        if msg.is_extended_id != m.is_extended_frame:
            self._count_unknown(msg.arbitration_id)
            return
        if not msg.is_remote_frame and len(msg.data) != m.length:
            # shorter or longer than the protocol says: not decoded (cantools would decode a
            # longer one from its first bytes, in silence)
            self.wrong_length[m.name] = self.wrong_length.get(m.name, 0) + 1
            self.undecodable += 1
            return
        try:
            sig = m.decode(bytes(msg.data), decode_choices=True)
        except Exception:  # noqa: BLE001 - any decoding failure is counted, not fatal
            self.undecodable += 1
            return
        sig = {k: (str(v) if not isinstance(v, (int, float)) else v) for k, v in sig.items()}
        st = self.messages.get(m.frame_id)
        if st is None:
            st = self.messages[m.frame_id] = MessageStats(m.name, m.frame_id, first=ts)
        st.count += 1
        st.last = ts
        st.signals = sig
        sender = m.senders[0] if m.senders else None
        if sender in self.nodes:
            sent = self.nodes[sender].sent
            sent[m.name] = sent.get(m.name, 0) + 1
        kind = m.name.split("_", 1)[0]
        if kind == "Heartbeat" and sender in self.nodes:
            n = self.nodes[sender]
            n.heartbeats += 1
            n.state = sig.get("state")
            flags = int(sig.get("fault_flags", 0))
            n.fault_flags = flags
            n.faults = [self.fault_names.get(b + 1, f"bit{b}") for b in range(16) if flags >> b & 1]
            n.uptime_s = sig.get("uptime")
            n.last_seen = ts
        elif kind == "Fault":
            self.fault_events_total += 1
            if len(self.fault_events) < MAX_FAULT_EVENTS:
                self.fault_events.append({"t": ts, "node": sender, **sig})
        elif kind == "ClockInfo" and sender in self.nodes:
            ident = self.nodes[sender].identity
            for k in ("clock_source", "crystal"):
                ident[k] = sig[k]
            for k in ("oscillator_error", "tolerated_error", "crystal_freq"):
                ident[k] = float(sig[k])
        elif kind in ("Version", "Identity", "BootInfo") and sender in self.nodes:
            ident = self.nodes[sender].identity
            if kind == "Version":
                ident["firmware"] = "{}.{}.{}".format(
                    int(sig["fw_major"]), int(sig["fw_minor"]), int(sig["fw_patch"]))
                ident["build_id"] = f"{int(sig['build_id']):08x}"
                ident["protocol_version"] = int(sig["protocol_version"])
            elif kind == "Identity":
                ident["uid_low"] = int(sig["uid_low"])
                ident["uid_mid"] = int(sig["uid_mid"])
            else:
                ident["uid_high"] = int(sig["uid_high"])
                for k in ("reset_cause", "params_source", "calibration_source"):
                    ident[k] = sig[k]
                ident["fault_history_len"] = int(sig["fault_history_len"])
            if all(k in ident for k in ("uid_low", "uid_mid", "uid_high")):
                # 96-bit unique ID, most significant word first, as ST prints it.
                ident["uid"] = "{:08x}{:08x}{:08x}".format(
                    ident["uid_high"], ident["uid_mid"], ident["uid_low"])
        elif kind == "FaultHistory" and sender in self.nodes:
            entry = int(sig["entry"])
            if 0 <= entry < MAX_HISTORY_ENTRIES:
                self.nodes[sender].fault_history[entry] = {
                    "code": sig["code"], "state_after": sig["state_after"],
                    "detail": int(sig["detail"]), "uptime": sig["uptime"]}
        elif kind == "CommandAck" and sender in self.nodes:
            acks = self.nodes[sender].acks
            if len(acks) < MAX_HISTORY_ENTRIES:
                acks.append({"t": ts, "opcode": sig["opcode"], "result": sig["result"]})

    def _count_unknown(self, ident: int) -> None:
        if ident in self.unknown or len(self.unknown) < MAX_UNKNOWN_IDS:
            self.unknown[ident] = self.unknown.get(ident, 0) + 1
        else:
            self.unknown_other += 1

    def _window_add(self, ts: float, nbits: int) -> None:
        """Bits into the window's buckets; a frame older than the newest bucket (timestamps
        out of order) counts in the newest."""
        if not math.isfinite(ts):
            return
        key = math.floor(ts / self.bucket_s)
        if self.recent and key <= self.recent[-1][0]:
            k, b = self.recent[-1]
            self.recent[-1] = (k, b + nbits)
        else:
            self.recent.append((key, nbits))
        self.window_bits += nbits
        newest = self.recent[-1][0]
        while self.recent and self.recent[0][0] < newest - WINDOW_BUCKETS:
            self.window_bits -= self.recent.popleft()[1]
        self.window_peak_bits = max(self.window_peak_bits, self.window_bits)

    def span(self) -> float:
        if self.first is None or self.last is None:
            return 0.0
        return self.last - self.first

    def impossible_load(self) -> bool:
        """Whether more bits arrived than the bit rate can carry in the time they span, over
        the whole capture or in the busiest window (one frame taken off: it may straddle the
        edge; the window's buckets can span one bucket more than the window)."""
        if self.frames < 2:
            return False
        slack = 1 + LOAD_TOLERANCE
        over_span = self.bits - self.max_frame_bits > self.bitrate * self.span() * slack
        window_capacity = self.bitrate * self.window_s * (1 + 1 / WINDOW_BUCKETS) * slack
        over_window = self.window_peak_bits - self.max_frame_bits > window_capacity
        return over_span or over_window

    def warnings(self, load: float, peak: float) -> list[str]:
        """One sentence for each check that found something."""
        out = []
        if self.impossible_load():
            out.append(f"impossible bus load: {100 * load:.1f} % over the capture, "
                       f"{100 * peak:.1f} % at most in {self.window_s:g} s, more than "
                       f"{self.bitrate} bit/s can carry (timestamps compressed or a wrong "
                       f"--bitrate)")
        if self.backwards:
            out.append(f"{self.backwards} frames with a timestamp earlier than a frame before "
                       f"them (by up to {self.largest_step_back:.6f} s)")
        if self.other_channels:
            n = sum(self.other_channels.values())
            out.append(f"{n} frames on other channels than {self.channel} not decoded: "
                       + ", ".join(f"{k} x{v}" for k, v in self.other_channels.items()))
        if self.wrong_length:
            n = sum(self.wrong_length.values())
            out.append(f"{n} frames with another length than the DBC's not decoded: "
                       + ", ".join(f"{k} x{v}" for k, v in sorted(self.wrong_length.items())))
        if self.malformed_frames:
            out.append(f"{self.malformed_frames} malformed frames not decoded")
        return out

    def summary(self) -> dict:
        span = self.span()
        end = self.last or 0.0
        window_bits = self.window_bits
        msgs = {}
        for st in sorted(self.messages.values(), key=lambda s: s.frame_id):
            msgs[st.name] = {
                "id": st.frame_id,
                "count": st.count,
                "rate_hz": st.count / span if span > 0 else 0.0,
                "last": st.signals,
            }
        nodes = {}
        for name, n in self.nodes.items():
            alive = n.last_seen is not None and end - n.last_seen <= self.stale_s
            nodes[name] = {
                "heartbeats": n.heartbeats,
                "state": n.state,
                "alive": alive,
                "last_seen_s_ago": None if n.last_seen is None else end - n.last_seen,
                "fault_flags": n.fault_flags,
                "faults": n.faults,
                "uptime_s": n.uptime_s,
                "identity": n.identity,
                # newest first, as the node numbers them
                "fault_history": [n.fault_history[k] for k in sorted(n.fault_history)],
                "command_acks": n.acks,
                # what the node sent; a node without heartbeats (the simulator's host in
                # `walker sil`) is shown by these instead of its state
                "sends_heartbeats": n.heartbeats > 0,
                "frames_sent": sum(n.sent.values()),
                "messages_sent": dict(sorted(n.sent.items())),
            }
        load = self.bits / (self.bitrate * span) if span > 0 else 0.0
        peak = self.window_peak_bits / (self.bitrate * self.window_s)
        return {
            "span_s": span,
            "frames": self.frames,
            "bitrate_bps": self.bitrate,
            "bus_load": load,
            "bus_load_window": window_bits / (self.bitrate * self.window_s),
            "bus_load_window_peak": peak,
            "messages": msgs,
            "nodes": nodes,
            "faults": {
                "events": self.fault_events,
                "error_frames": self.error_frames,
                "unknown_ids": {f"0x{k:03X}": v for k, v in sorted(self.unknown.items())},
                "unknown_ids_other": self.unknown_other,
                # frames of a known identifier not decoded, wrong_length included
                "undecodable": self.undecodable,
                "events_total": self.fault_events_total,
                "wrong_length": dict(sorted(self.wrong_length.items())),
                "other_channels": dict(self.other_channels),
                "backwards_timestamps": self.backwards,
                "largest_step_back_s": self.largest_step_back,
                "impossible_load": self.impossible_load(),
            },
            "channel": self.channel,
            "malformed_frames": self.malformed_frames,
            "bad_frames": list(self.bad_frames),
            "warnings": self.warnings(load, peak),
        }


def render(summary: dict) -> str:
    out = io.StringIO()
    s = summary
    out.write(f"span {s['span_s']:.3f} s  frames {s['frames']}  bus load {100 * s['bus_load']:.2f} % "
              f"(last {100 * s['bus_load_window']:.2f} %)\n")
    out.write(f"{'message':<28}{'id':>6}{'count':>8}{'rate Hz':>10}  last\n")
    for name, m in s["messages"].items():
        last = ", ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}"
                         for k, v in m["last"].items())
        out.write(f"{name:<28}{m['id']:>#6x}{m['count']:>8}{m['rate_hz']:>10.2f}  {last}\n")
    out.write("node         state          alive  heartbeats  faults\n")
    for name, n in s["nodes"].items():
        out.write(node_row(name, n))
    f = s["faults"]
    out.write(f"fault events {f['events_total']}  error frames {f['error_frames']}  "
              f"unknown ids {f['unknown_ids'] or '-'}  undecodable {f['undecodable']}\n")
    if s.get("malformed_lines"):
        out.write(f"malformed log lines {s['malformed_lines']}\n")
    for w in s.get("warnings", []):
        out.write(f"warning: {w}\n")
    return out.getvalue()


def node_row(name: str, n: dict) -> str:
    """One node's row of the table: its state, whether it is alive and its faults. The host
    without heartbeats (the simulator's host in `walker sil` sends commands only) is no
    heartbeat node: its row shows what it sent instead of a state that would read as dead."""
    if name not in HEARTBEAT_OPTIONAL or n["heartbeats"] > 0:
        return (f"{name:<13}{str(n['state']):<15}{'yes' if n['alive'] else 'NO':<7}"
                f"{n['heartbeats']:>10}  {','.join(n['faults']) or '-'}\n")
    sent = n.get("messages_sent") or {}
    what = ", ".join(f"{k} x{v}" for k, v in sent.items()) if sent else "nothing seen"
    return (f"{name:<13}{'-':<15}{'-':<7}{'-':>10}  host without heartbeat (the simulator's "
            f"host sends commands only); sent: {what}\n")


# --- sources ----------------------------------------------------------------------------

@dataclass
class ReadStats:
    """What reading a log found besides its frames."""

    malformed: int = 0
    lines: int = 0


def read_log(path: Union[str, BinaryIO], bad_lines: list,
             stats: Optional[ReadStats] = None) -> Iterator[can.Message]:
    """Messages of a candump log (a path or a binary file), streamed line by line. A malformed
    line is counted in `stats` and, for the first MAX_QUOTED_LINES, appended to `bad_lines`
    (line number, quoted text cut to candump_grammar.QUOTE_BYTES, reason) and named on stderr;
    every other line is kept."""
    stats = stats if stats is not None else ReadStats()
    name = path if isinstance(path, str) else getattr(path, "name", "log")
    f = open(path, "rb") if isinstance(path, str) else path
    try:
        for raw, rec in candump_grammar.records(f):
            stats.lines = raw.number
            if isinstance(rec, candump_grammar.Malformed):
                stats.malformed += 1
                if len(bad_lines) < MAX_QUOTED_LINES:
                    text = raw.quote()
                    bad_lines.append({"line": raw.number, "text": text, "reason": str(rec)})
                    print(f"{name}:{raw.number}: bad candump line ({rec}): {text}",
                          file=sys.stderr)
                continue
            yield rec.to_message()
    finally:
        if isinstance(path, str):
            f.close()
    if stats.malformed > len(bad_lines):
        print(f"{name}: {stats.malformed} malformed lines in all (the first "
              f"{len(bad_lines)} named)", file=sys.stderr)


# --- socketcand ---------------------------------------------------------------------------

class SocketcandStream:
    """The text of a socketcand connection cut into `< ... >` elements, in bounded pieces:
    `feed` and, at the end of the stream, `finish` give ("element", bytes) for each element of
    at most MAX_ELEMENT_BYTES and ("bad", RawLine, reason) for anything else: bytes outside
    elements (blanks between elements are skipped), an element with a `<` before its `>`, one
    without a `>` within MAX_ELEMENT_BYTES (the rest is skipped up to its `>` or the next `<`).
    A run of stray bytes is reported once, as soon as QUOTE_BYTES of it are known or it ends.
    It holds at most MAX_ELEMENT_BYTES of one element and QUOTE_BYTES + 1 of stray bytes."""

    def __init__(self) -> None:
        self.buf = bytearray()  # the element being read, from its `<`
        self.mode = "out"  # "out" (between elements), "in" (in buf), "skip" (a cut element)
        self.junk = bytearray()
        self.junk_len = 0
        self.junk_reported = False

    def _junk(self, seg: bytes, out: list) -> None:
        if not self.junk_len:  # a run starts at its first byte that is not blank
            seg = seg.lstrip(b" \t\r\n")
            if not seg:
                return
        if len(self.junk) <= candump_grammar.QUOTE_BYTES:
            self.junk += seg[:candump_grammar.QUOTE_BYTES + 1 - len(self.junk)]
        self.junk_len += len(seg)
        if not self.junk_reported and self.junk_len > candump_grammar.QUOTE_BYTES:
            self.junk_reported = True
            # reported before its end is known: "more than QUOTE_BYTES" as its length
            out.append(("bad", candump_grammar.RawLine(0, bytes(self.junk),
                                                       candump_grammar.QUOTE_BYTES + 1),
                        "bytes outside `< ... >`: not socketcand"))

    def _end_junk(self, out: list) -> None:
        if self.junk_len and not self.junk_reported:
            out.append(("bad", candump_grammar.RawLine(0, bytes(self.junk), self.junk_len),
                        "bytes outside `< ... >`: not socketcand"))
        self.junk = bytearray()
        self.junk_len = 0
        self.junk_reported = False

    def feed(self, data: bytes) -> list:
        out: list = []
        pos, n = 0, len(data)
        while pos < n:
            if self.mode == "skip":
                ends = [i for i in (data.find(b">", pos), data.find(b"<", pos)) if i >= 0]
                if not ends:
                    return out
                end = min(ends)
                self.mode = "out"
                pos = end + 1 if data[end:end + 1] == b">" else end
            elif self.mode == "out":
                start = data.find(b"<", pos)
                self._junk(data[pos:] if start < 0 else data[pos:start], out)
                if start < 0:
                    return out
                self._end_junk(out)
                self.mode = "in"
                self.buf = bytearray(b"<")
                pos = start + 1
            else:
                close, reopen = data.find(b">", pos), data.find(b"<", pos)
                end = close if close >= 0 and (reopen < 0 or close < reopen) else -1
                take = (end + 1 if end >= 0 else reopen if reopen >= 0 else n) - pos
                room = MAX_ELEMENT_BYTES - len(self.buf)
                self.buf += data[pos:pos + min(take, room)]
                if take > room:
                    out.append(("bad", self._raw(MAX_ELEMENT_BYTES + 1),
                                f"no `>` within {MAX_ELEMENT_BYTES} bytes"))
                    self.buf = bytearray()
                    self.mode = "skip"
                    pos += room
                elif end >= 0:
                    out.append(("element", bytes(self.buf)))
                    self.buf = bytearray()
                    self.mode = "out"
                    pos = end + 1
                elif reopen >= 0:
                    out.append(("bad", self._raw(len(self.buf)),
                                "an element without its `>` (a `<` came first)"))
                    self.buf = bytearray()
                    self.mode = "out"
                    pos = reopen
                else:
                    pos = n
        return out

    def _raw(self, length: int) -> candump_grammar.RawLine:
        return candump_grammar.RawLine(0, bytes(self.buf[:candump_grammar.QUOTE_BYTES + 1]),
                                       length)

    def finish(self) -> list:
        """What is left at the end of the stream: an unfinished element, stray bytes."""
        out: list = []
        if self.mode == "in" and self.buf:
            out.append(("bad", self._raw(len(self.buf)),
                        "the stream ended inside an element (no `>`)"))
        self.buf = bytearray()
        self.mode = "out"
        self._end_junk(out)
        return out


_SOCKETCAND_TIMESTAMP = re.compile(rb"([0-9]{1,20})\.([0-9]{1,9})")
_HEX_DIGITS = re.compile(rb"[0-9A-Fa-f]*")


def parse_socketcand_frame(element: bytes, channel: str) -> Optional[can.Message]:
    """One socketcand element, `< frame ID SECONDS.FRACTION DATA >` (ID 3 hex digits <= 7FF
    or 8 <= 1FFFFFFF; DATA 0 to 8 bytes in hex, no blanks), as a can.Message; None for the
    harmless `< ok >` and `< echo >`; Malformed (why) for anything else, a server's
    `< error ... >` included."""
    inner = element[1:-1]
    if candump_grammar._PRINTABLE.fullmatch(inner) is None:
        bad = next(c for c in inner if not (0x20 <= c <= 0x7E or c == 0x09))
        raise candump_grammar.Malformed(f"byte 0x{bad:02X} is not printable ASCII")
    words = inner.split()
    if not words:
        raise candump_grammar.Malformed("an empty element")
    what = words[0].decode()
    if what in ("ok", "echo") and len(words) == 1:
        return None
    if what == "error":
        raise candump_grammar.Malformed("the server reports an error (not a frame)")
    if what != "frame":
        raise candump_grammar.Malformed(f"`{what}` is not a frame")
    if len(words) not in (3, 4):
        raise candump_grammar.Malformed(
            "expected `< frame ID SECONDS.FRACTION DATA >`, DATA without blanks")
    id_s, ts_s = words[1], words[2]
    data_s = words[3] if len(words) == 4 else b""
    if len(id_s) not in (3, 8) or _HEX_DIGITS.fullmatch(id_s) is None:
        raise candump_grammar.Malformed(f"identifier `{id_s.decode()}` is not 3 or 8 hex digits")
    ident = int(id_s, 16)
    extended = len(id_s) == 8
    if not extended and ident > 0x7FF:
        raise candump_grammar.Malformed(f"identifier `{id_s.decode()}` exceeds 0x7FF")
    if extended and ident > 0x1FFF_FFFF:
        raise candump_grammar.Malformed(f"identifier `{id_s.decode()}` exceeds 29 bits")
    m = _SOCKETCAND_TIMESTAMP.fullmatch(ts_s)
    if m is None:
        raise candump_grammar.Malformed(
            f"timestamp `{ts_s.decode()}` is not of the form SECONDS.FRACTION")
    if int(m.group(1)) * 10**9 + int(m.group(2).ljust(9, b"0")) > candump_grammar.MAX_TIMESTAMP_NS:
        raise candump_grammar.Malformed(
            f"timestamp `{ts_s.decode()}` exceeds {candump_grammar.MAX_TIMESTAMP_NS} ns")
    if _HEX_DIGITS.fullmatch(data_s) is None:
        raise candump_grammar.Malformed(f"data `{data_s.decode()}` is not hex")
    if len(data_s) % 2:
        raise candump_grammar.Malformed(f"data `{data_s.decode()}` has an odd number of hex digits")
    if len(data_s) > 16:
        raise candump_grammar.Malformed(f"data `{data_s.decode()}` is longer than 8 bytes")
    data = bytes.fromhex(data_s.decode())
    return can.Message(timestamp=float(ts_s.decode()), arbitration_id=ident,
                       is_extended_id=extended, data=data, dlc=len(data), channel=channel,
                       is_rx=True)


class BusOpenError(Exception):
    """The bus could not be opened (the message says why); nothing was monitored."""


class SocketcandBus(can.BusABC):
    """A socketcand client in rawmode, for the monitor. python-can's own `socketcand`
    interface (4.4) raises on a frame it cannot parse and keeps that frame in its buffer, so
    every later read raises again and the frames after it are never delivered; it logs every
    1024-byte read of a stream that is not socketcand (837 MB of stderr in 10 s) and spins for
    10 s logging when the server is not there. This one connects within CONNECT_TIMEOUT_S,
    shakes hands within HANDSHAKE_TIMEOUT_S (a server's `< error ... >` is the reason given),
    reads in RECV_BYTES pieces through SocketcandStream and hands every element that is no
    frame to `on_bad(text, reason)`, one at a time, and goes on with the next."""

    def __init__(self, channel: str, host: str, port: int, on_bad=None, **kwargs):
        self.channel = channel
        self.channel_info = f"socketcand on {channel}@{host}:{port}"
        self.where = f"socketcand server {host}:{port}"
        self.on_bad = on_bad
        self.server_closed = False
        self._stream = SocketcandStream()
        self._items: collections.deque = collections.deque()
        try:
            self.sock = socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S)
        except OSError as e:
            raise BusOpenError(f"{self.where}: cannot connect: {e.strerror or e}") from None
        try:
            deadline = time.monotonic() + HANDSHAKE_TIMEOUT_S
            self._expect(b"hi", "a greeting", deadline)
            self._send_text(f"< open {channel} >")
            self._expect(b"ok", f"channel {channel} opened", deadline)
            self._send_text("< rawmode >")
            self._expect(b"ok", "rawmode", deadline)
            self.sock.setblocking(False)
        except BaseException:
            self.sock.close()
            raise
        super().__init__(channel=channel, **kwargs)

    def _send_text(self, text: str) -> None:
        try:
            self.sock.sendall(text.encode("ascii"))
        except OSError as e:
            raise BusOpenError(f"{self.where}: sending `{text}`: {e.strerror or e}") from None

    def _expect(self, word: bytes, what: str, deadline: float) -> None:
        """The next element is `< WORD >`, or BusOpenError says what came instead."""
        while not self._items:
            left = deadline - time.monotonic()
            if left <= 0:
                raise BusOpenError(f"{self.where}: no answer ({what}) within "
                                   f"{HANDSHAKE_TIMEOUT_S:g} s: not a socketcand server?")
            self.sock.settimeout(left)
            try:
                data = self.sock.recv(RECV_BYTES)
            except socket.timeout:
                continue
            except OSError as e:
                raise BusOpenError(f"{self.where}: {e.strerror or e}") from None
            if not data:
                self._items.extend(self._stream.finish())
                if not self._items:
                    raise BusOpenError(f"{self.where}: closed the connection before {what}")
            else:
                self._items.extend(self._stream.feed(data))
        kind, *rest = self._items.popleft()
        if kind == "element" and rest[0][1:-1].split() == [word]:
            return
        text = (candump_grammar.RawLine(0, rest[0][:candump_grammar.QUOTE_BYTES + 1],
                                        len(rest[0])).quote() if kind == "element"
                else rest[0].quote())
        if kind == "element" and rest[0][1:-1].split()[:1] == [b"error"]:
            raise BusOpenError(f"{self.where} refused ({what} expected): {text}")
        raise BusOpenError(f"{self.where}: expected `< {word.decode()} >` ({what}), got: {text}")

    def _next_message(self) -> Optional[can.Message]:
        while self._items:
            kind, *rest = self._items.popleft()
            if kind == "bad":
                raw, reason = rest
                self._report(raw.quote(), reason)
                continue
            element = rest[0]
            try:
                msg = parse_socketcand_frame(element, self.channel)
            except candump_grammar.Malformed as e:
                raw = candump_grammar.RawLine(0, element[:candump_grammar.QUOTE_BYTES + 1],
                                              len(element))
                self._report(raw.quote(), str(e))
                continue
            if msg is not None:
                return msg
        return None

    def _report(self, text: str, reason: str) -> None:
        if self.on_bad is not None:
            self.on_bad(text, reason)

    def _recv_internal(self, timeout):
        msg = self._next_message()
        if msg is not None or self.server_closed:
            if msg is None and timeout:
                time.sleep(min(timeout, 0.05))
            return msg, False
        try:
            readable, _, _ = select.select([self.sock], [], [], timeout)
            if not readable:
                return None, False
            data = self.sock.recv(RECV_BYTES)
        except (BlockingIOError, InterruptedError):
            return None, False
        except OSError as e:
            raise can.CanOperationError(f"{self.where}: {e.strerror or e}") from None
        if data:
            self._items.extend(self._stream.feed(data))
        else:
            self.server_closed = True
            self._items.extend(self._stream.finish())
        return self._next_message(), False

    def send(self, msg: can.Message, timeout=None) -> None:
        """`< send ID LEN B0 B1 ... >` (hex), as python-can's interface writes it."""
        ident = (f"{msg.arbitration_id & 0x1FFF_FFFF:08X}" if msg.is_extended_id
                 else f"{msg.arbitration_id & 0x7FF:03X}")
        data = bytes(msg.data)
        text = f"< send {ident} {len(data):X} {' '.join(f'{b:x}' for b in data)} >"
        try:
            self.sock.setblocking(True)
            self.sock.settimeout(CONNECT_TIMEOUT_S)
            self.sock.sendall(text.encode("ascii"))
        except OSError as e:
            raise can.CanOperationError(f"{self.where}: sending: {e.strerror or e}") from None
        finally:
            self.sock.setblocking(False)

    def shutdown(self) -> None:
        super().shutdown()
        self.sock.close()


def channel_name(text: str) -> str:
    """argparse type: a channel name socketcand can carry (`< open NAME >`): 1 to 64
    printable ASCII characters, no blank, `<` or `>`."""
    if not 1 <= len(text) <= 64 or not all(0x21 <= ord(c) <= 0x7E and c not in "<>"
                                           for c in text):
        raise argparse.ArgumentTypeError(
            f"{text[:80]!r} is not a channel name (1 to 64 printable ASCII characters, "
            "no blank, < or >)")
    return text


# --- python-can's logging ---------------------------------------------------------------

class RateLimitedLogs(logging.Filter):
    """Lets the first LOG_BURST records through, then at most one per LOG_INTERVAL_S; counts
    the rest in `suppressed`. Each record passed is cut to LOG_RECORD_CHARS characters with
    its control characters escaped (python-can quotes whole receive buffers)."""

    def __init__(self) -> None:
        super().__init__()
        self.passed = 0
        self.suppressed = 0
        self.last_pass = -math.inf

    def filter(self, record: logging.LogRecord) -> bool:
        now = time.monotonic()
        if self.passed >= LOG_BURST and now - self.last_pass < LOG_INTERVAL_S:
            self.suppressed += 1
            return False
        self.passed += 1
        self.last_pass = now
        try:
            text = record.getMessage()
        except Exception:  # noqa: BLE001 - a record that cannot format: show its template
            text = str(record.msg)
        shown = "".join(c if c.isprintable() else repr(c)[1:-1]
                        for c in text[:LOG_RECORD_CHARS])
        record.msg = shown[:LOG_RECORD_CHARS] + ("..." if len(shown) > LOG_RECORD_CHARS
                                                 or len(text) > LOG_RECORD_CHARS else "")
        record.args = None
        return True


LOG_GUARD = RateLimitedLogs()


def guard_library_logs() -> RateLimitedLogs:
    """Puts LOG_GUARD on python-can's logger `can` and on every `can.*` logger that exists
    (interfaces are imported when a bus is opened: call again then). A logger's filter sees
    the records made on that logger, hence one filter on each."""
    names = ["can"] + [n for n in logging.root.manager.loggerDict if n.startswith("can.")]
    for name in names:
        logger = logging.getLogger(name)
        if LOG_GUARD not in logger.filters:
            logger.addFilter(LOG_GUARD)
    return LOG_GUARD


# --- files ------------------------------------------------------------------------------

def open_regular(path: str, flag: str, limit: Optional[int] = None) -> BinaryIO:
    """`path` opened for reading, if it is a regular file (of at most `limit` bytes). A FIFO
    is opened without waiting for a writer and then refused, as are devices (/dev/zero never
    ends) and directories; ValueError says why, OSError when it cannot be opened."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            kind = ("a FIFO" if stat.S_ISFIFO(st.st_mode) else
                    "a character device" if stat.S_ISCHR(st.st_mode) else
                    "a block device" if stat.S_ISBLK(st.st_mode) else
                    "a directory" if stat.S_ISDIR(st.st_mode) else
                    "a socket" if stat.S_ISSOCK(st.st_mode) else "not a file")
            raise ValueError(f"{flag} {path}: {kind}, not a regular file (only regular files "
                             "are read)")
        if limit is not None and st.st_size > limit:
            raise ValueError(f"{flag} {path}: {st.st_size} bytes, more than the limit of "
                             f"{limit} bytes")
        os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def load_dbc(path: str):
    """The DBC (or another format cantools reads, by its suffix), strict: a regular file of at
    most MAX_DBC_BYTES. ValueError or cantools' errors say why not."""
    with open_regular(path, "--dbc", MAX_DBC_BYTES) as f:
        raw = f.read(MAX_DBC_BYTES + 1)
    if len(raw) > MAX_DBC_BYTES:
        raise ValueError(f"--dbc {path}: more than the limit of {MAX_DBC_BYTES} bytes")
    # as cantools.database.load_file: the format from the suffix, cp1252 for dbc and sym
    fmt = os.path.splitext(path)[1][1:].lower()
    text = raw.decode("cp1252" if fmt in ("dbc", "sym") else "utf-8", errors="replace")
    return cantools.database.load(io.StringIO(text), fmt, strict=True)


class _DropPartialReadWarnings(logging.Filter):
    """python-can's socketcand interface logs a warning ("Got incomplete message => waiting for
    more data") whenever one read from the TCP stream ends inside a frame's text. TCP keeps no
    message boundaries, so that is an ordinary partial read, not an error (the interface keeps
    the rest and parses it with the next read): these records are dropped, the interface's
    other warnings kept."""

    def filter(self, record: logging.LogRecord) -> bool:
        return not record.getMessage().startswith("Got incomplete message")


def quiet_partial_reads() -> None:
    """Installs the filter on python-can's socketcand logger (once)."""
    logger = logging.getLogger("can.interfaces.socketcand.socketcand")
    if not any(isinstance(f, _DropPartialReadWarnings) for f in logger.filters):
        logger.addFilter(_DropPartialReadWarnings())


def connection_closed(bus: can.BusABC) -> bool:
    """Whether a socketcand bus's server closed the connection (the run ended). python-can's
    socketcand interface reads an empty string then and returns no message, as on a quiet bus;
    this peeks at its socket: readable with nothing to read is the end of the stream. The
    monitor's own SocketcandBus knows (`server_closed`). Other interfaces: False."""
    if getattr(bus, "server_closed", False) is True:
        return True
    sock = getattr(bus, "_SocketCanDaemonBus__socket", None)
    if not isinstance(sock, socket.socket):
        return False
    try:
        readable, _, _ = select.select([sock], [], [], 0)
        if not readable:
            return False
        return sock.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) == b""
    except (BlockingIOError, InterruptedError):
        return False
    except (OSError, ValueError):
        return True


def live(bus: can.BusABC, duration: Optional[float], idle_exit: Optional[float],
         closed: Optional[list] = None) -> Iterator[can.Message]:
    """Messages from `bus` until `duration` passed, nothing arrived for `idle_exit` after the
    first frame, or the server closed the connection (then `closed` gets True appended)."""
    start = time.monotonic()
    last_rx = None
    while True:
        now = time.monotonic()
        if duration is not None and now - start >= duration:
            return
        if idle_exit is not None and last_rx is not None and now - last_rx >= idle_exit:
            return
        msg = bus.recv(timeout=0.1)
        if msg is None:
            if connection_closed(bus):
                if closed is not None:
                    closed.append(True)
                return
            time.sleep(0.005)
            continue
        last_rx = time.monotonic()
        yield msg


def parse_send(text: str) -> can.Message:
    """`ID#HEXDATA` (cansend syntax, standard identifiers) as a can.Message."""
    ident, _, data = text.partition("#")
    hexdigits = set("0123456789abcdefABCDEF")
    try:
        if not ident or not set(ident) <= hexdigits or not set(data) <= hexdigits:
            raise ValueError("hex digits only")
        arb = int(ident, 16)
        payload = bytes.fromhex(data)
    except ValueError as e:
        raise argparse.ArgumentTypeError(f"--send {text!r}: expected ID#HEXDATA ({e})") from e
    if len(ident) > 3 or arb > 0x7FF or len(payload) > 8:
        raise argparse.ArgumentTypeError(
            f"--send {text!r}: 11-bit identifier (3 hex digits) and at most 8 data bytes")
    return can.Message(arbitration_id=arb, data=payload, is_extended_id=False)


def open_bus(args, on_bad=None) -> can.BusABC:
    """The live bus: the monitor's SocketcandBus for socketcand (malformed frames to
    `on_bad`), python-can's interface otherwise. BusOpenError says why it cannot be opened."""
    channel = args.channel or "vcan0"
    if args.interface == "socketcand":
        return SocketcandBus(channel, args.host, args.port, on_bad=on_bad)
    kwargs = {"interface": args.interface, "channel": channel}
    if args.interface == "slcan":
        kwargs["bitrate"] = args.bitrate
    try:
        return can.Bus(**kwargs)
    except (can.CanError, OSError, ValueError, TypeError, ImportError, NotImplementedError) as e:
        what = getattr(e, "strerror", None) or str(e) or type(e).__name__
        raise BusOpenError(f"--interface {args.interface} --channel {channel}: cannot open "
                           f"the bus: {what}") from None


def positive_int(text: str) -> int:
    """argparse type: a whole number > 0 (a bit rate)."""
    try:
        v = int(text, 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if v <= 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not positive")
    return v


def port_number(text: str) -> int:
    """argparse type: a TCP port, 1..65535."""
    try:
        v = int(text, 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if not 1 <= v <= 65535:
        raise argparse.ArgumentTypeError(f"{text!r} is not a port number 1..65535")
    return v


def seconds(text: str) -> float:
    """argparse type: a finite number of seconds > 0."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(v) or v <= 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number of seconds > 0")
    return v


def finite_json(value):
    """`value` with every non-finite float replaced by None (strict JSON has no NaN/Infinity)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: finite_json(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite_json(v) for v in value]
    return value


def main(argv: Optional[list] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--interface", help="python-can interface: socketcand, socketcan, slcan, ...")
    src.add_argument("--log", help="read a candump log (a regular file) instead of a live bus")
    p.add_argument("--channel", type=channel_name,
                   help="interface channel (default vcan0); with --log, frames on other "
                        "channels are counted, not decoded (default: the first frame's)")
    p.add_argument("--host", default="127.0.0.1", help="socketcand host (default 127.0.0.1)")
    p.add_argument("--port", type=port_number, default=29536, help="socketcand port (default 29536)")
    p.add_argument("--bitrate", type=positive_int, default=500_000, help="bus bit rate [bit/s]")
    p.add_argument("--dbc", default=str(DEFAULT_DBC), help="DBC file (default protocol/walker.dbc)")
    p.add_argument("--record", help="also write every received frame to this candump log")
    p.add_argument("--duration", type=seconds,
                   help="stop after this many seconds (wall clock live, log time for --log)")
    p.add_argument("--idle-exit", type=seconds,
                   help="live: stop when nothing arrived for this many seconds after the first frame")
    p.add_argument("--interval", type=seconds, default=1.0, help="live table refresh [s] (text mode)")
    p.add_argument("--stale", type=seconds, default=0.3,
                   help="a node is not alive when its last heartbeat is older than this [s]")
    p.add_argument("--json", action="store_true", help="print one JSON summary at the end")
    p.add_argument("--send", type=parse_send, action="append", default=[], metavar="ID#DATA",
                   help="live: send this frame once after connecting (repeatable), e.g. 013#03")
    args = p.parse_args(argv)
    if args.send and args.log:
        p.error("--send needs a live --interface, not --log")
    if args.interface is not None and args.interface not in can.interfaces.VALID_INTERFACES:
        p.error(f"--interface {args.interface[:80]!r} is not a python-can interface; one of: "
                + ", ".join(sorted(can.interfaces.VALID_INTERFACES)))

    try:
        db = load_dbc(args.dbc)
    except Exception as e:  # noqa: BLE001 - cantools raises assorted errors
        p.error(f"--dbc {args.dbc}: {e.strerror or e}" if isinstance(e, OSError) else
                str(e) if isinstance(e, ValueError) and str(e).startswith("--dbc") else
                f"--dbc {args.dbc}: {e}")
    try:
        mon = Monitor(db, bitrate=args.bitrate, stale_s=args.stale,
                      channel=args.channel if args.log else None, echo=sys.stderr)
    except (KeyError, ValueError) as e:
        p.error(f"--dbc {args.dbc}: not the walker protocol ({e})")
    guard = guard_library_logs()
    suppressed_before = guard.suppressed
    log_file = None
    bus = None
    if args.log:
        try:
            log_file = open_regular(args.log, "--log")
        except OSError as e:
            p.error(f"--log {args.log}: {e.strerror or e}")
        except ValueError as e:
            p.error(str(e))
    else:
        quiet_partial_reads()
        try:
            bus = open_bus(args, on_bad=mon.bad_frame)
        except BusOpenError as e:
            p.error(str(e))
        finally:
            guard_library_logs()  # the interface's module is imported now
    try:
        writer = (can.CanutilsLogWriter(args.record, channel=args.channel or "vcan0")
                  if args.record else None)
    except OSError as e:
        if log_file is not None:
            log_file.close()
        if bus is not None:
            bus.shutdown()
        p.error(f"--record {args.record}: {e.strerror or e}")
    bad_lines: list = []
    stats = ReadStats()
    failed = None
    closed: list = []
    try:
        if log_file is not None:
            source: Iterable[can.Message] = read_log(log_file, bad_lines, stats)
        else:
            for m in args.send:
                bus.send(m)
            source = live(bus, args.duration, args.idle_exit, closed)
        next_print = time.monotonic() + args.interval
        for msg in source:
            if args.log and args.duration is not None and mon.first is not None \
                    and msg.timestamp - mon.first > args.duration:
                break
            mon.feed(msg)
            if writer is not None:
                writer.on_message_received(msg)
            if bus is not None and not args.json and time.monotonic() >= next_print:
                print(render(mon.summary()), flush=True)
                next_print = time.monotonic() + args.interval
    except KeyboardInterrupt:
        pass
    except (OSError, can.CanError) as e:  # the log, the bus or the record file failed mid-way
        failed = f"walker_monitor: {e}"
    finally:
        if bus is not None:
            bus.shutdown()
        if writer is not None:
            writer.stop()
        if log_file is not None:
            log_file.close()
    if closed:
        print("walker_monitor: the server closed the connection (the run ended)", file=sys.stderr)
    summary = mon.summary()
    summary["bad_lines"] = bad_lines
    summary["malformed_lines"] = stats.malformed
    summary["log_records_suppressed"] = guard.suppressed - suppressed_before
    if mon.malformed_frames > len(mon.bad_frames):
        print(f"walker_monitor: {mon.malformed_frames} malformed frames in all (the first "
              f"{len(mon.bad_frames)} named)", file=sys.stderr)
    if summary["log_records_suppressed"]:
        print(f"walker_monitor: {summary['log_records_suppressed']} log records of python-can "
              f"suppressed (at most {LOG_BURST}, then one a second)", file=sys.stderr)
    for w in summary["warnings"]:
        if not w.endswith("malformed frames not decoded"):
            print(f"walker_monitor: warning: {w}", file=sys.stderr)
    if args.json:
        json.dump(finite_json(summary), sys.stdout, indent=1, default=str, allow_nan=False)
        print()
    else:
        print(render(summary), end="")
    if failed is not None:
        print(failed, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
