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
(`bad_lines`, cut short), never decoded; memory does not grow with the log. Bad flags exit 2.
"""

from __future__ import annotations

import argparse
import collections
import io
import json
import logging
import math
import pathlib
import select
import socket
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

    def __init__(self, db, bitrate: int = 500_000, stale_s: float = 0.3, window_s: float = 1.0):
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
        fault = db.get_message_by_name("Fault_LEFT_ANKLE").get_signal_by_name("code")
        self.fault_names = {int(k): str(v) for k, v in fault.choices.items()}

    def feed(self, msg: can.Message) -> None:
        ts = float(msg.timestamp or 0.0)
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
        self._window_add(ts, nbits)
        try:
            m = self.db.get_message_by_frame_id(msg.arbitration_id)
        except KeyError:
            self._count_unknown(msg.arbitration_id)
            return
        if msg.is_extended_id != m.is_extended_frame:
            self._count_unknown(msg.arbitration_id)
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
        newest = self.recent[-1][0]
        while self.recent and self.recent[0][0] < newest - WINDOW_BUCKETS:
            self.recent.popleft()

    def span(self) -> float:
        if self.first is None or self.last is None:
            return 0.0
        return self.last - self.first

    def summary(self) -> dict:
        span = self.span()
        end = self.last or 0.0
        window_bits = sum(b for _, b in self.recent)
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
        return {
            "span_s": span,
            "frames": self.frames,
            "bitrate_bps": self.bitrate,
            "bus_load": self.bits / (self.bitrate * span) if span > 0 else 0.0,
            "bus_load_window": window_bits / (self.bitrate * self.window_s),
            "messages": msgs,
            "nodes": nodes,
            "faults": {
                "events": self.fault_events,
                "error_frames": self.error_frames,
                "unknown_ids": {f"0x{k:03X}": v for k, v in sorted(self.unknown.items())},
                "unknown_ids_other": self.unknown_other,
                "undecodable": self.undecodable,
                "events_total": self.fault_events_total,
            },
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
    this peeks at its socket: readable with nothing to read is the end of the stream. Other
    interfaces: False."""
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


def open_bus(args) -> can.BusABC:
    kwargs = {"interface": args.interface, "channel": args.channel}
    if args.interface == "socketcand":
        kwargs.update(host=args.host, port=args.port)
    if args.interface == "slcan":
        kwargs["bitrate"] = args.bitrate
    return can.Bus(**kwargs)


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
    src.add_argument("--log", help="read a candump log instead of a live bus")
    p.add_argument("--channel", default="vcan0", help="interface channel (default vcan0)")
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

    try:
        db = cantools.database.load_file(args.dbc, strict=True)
    except Exception as e:  # noqa: BLE001 - cantools raises assorted errors
        p.error(f"--dbc {args.dbc}: {e}")
    mon = Monitor(db, bitrate=args.bitrate, stale_s=args.stale)
    log_file = None
    if args.log:
        try:
            log_file = open(args.log, "rb")
        except OSError as e:
            p.error(f"--log {args.log}: {e.strerror or e}")
    try:
        writer = can.CanutilsLogWriter(args.record, channel=args.channel) if args.record else None
    except OSError as e:
        if log_file is not None:
            log_file.close()
        p.error(f"--record {args.record}: {e.strerror or e}")
    bad_lines: list = []
    stats = ReadStats()
    bus = None
    failed = None
    closed: list = []
    try:
        if log_file is not None:
            source: Iterable[can.Message] = read_log(log_file, bad_lines, stats)
        else:
            quiet_partial_reads()
            bus = open_bus(args)
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
    except OSError as e:  # the log or the record file failed mid-way: report what was seen
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
