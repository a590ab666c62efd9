#!/usr/bin/env python3
"""Bus monitor for the walker's CAN bus (python-can + cantools with protocol/walker.dbc).

Decodes live traffic from any python-can interface or a candump log and shows per-message
rates, node heartbeats and states, faults (Fault messages, heartbeat fault flags, error
frames, undecodable frames) and the bus load; can record what it sees to a candump log.

    # the simulated bus (canbus-demo or walker sil with --socketcand 127.0.0.1:PORT)
    .venv/bin/python python/walker_monitor.py --interface socketcand --channel vcan0 \
        --host 127.0.0.1 --port PORT --duration 10
    # the robot
    .venv/bin/python python/walker_monitor.py --interface socketcan --channel can0
    .venv/bin/python python/walker_monitor.py --interface slcan --channel /dev/ttyACM0
    # a log
    .venv/bin/python python/walker_monitor.py --log run.log --json

Bus load = bits on the wire (actual bit stuffing of each frame, CRC-15 included, plus the
3-bit interframe space, as the Rust simulator counts them) / (bit rate x observed time span).
"""

from __future__ import annotations

import argparse
import io
import json
import pathlib
import sys
import time
from dataclasses import dataclass, field
from typing import Iterable, Iterator, Optional

import can
import cantools

ROOT = pathlib.Path(__file__).resolve().parent.parent
DEFAULT_DBC = ROOT / "protocol" / "walker.dbc"
NODES = ("HOST", "LEFT_ANKLE", "RIGHT_ANKLE")


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


class Monitor:
    """Accumulates what a stream of can.Message shows."""

    def __init__(self, db, bitrate: int = 500_000, stale_s: float = 0.3, window_s: float = 1.0):
        self.db = db
        self.bitrate = bitrate
        self.stale_s = stale_s
        self.window_s = window_s
        self.messages: dict[int, MessageStats] = {}
        self.nodes: dict[str, NodeStatus] = {n: NodeStatus() for n in NODES}
        self.fault_events: list[dict] = []
        self.error_frames = 0
        self.unknown: dict[int, int] = {}
        self.undecodable = 0
        self.frames = 0
        self.bits = 0
        self.first: Optional[float] = None
        self.last: Optional[float] = None
        self.recent: list[tuple[float, int]] = []  # (timestamp, bits) within the window
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
        self.recent.append((ts, nbits))
        while self.recent and self.recent[0][0] < ts - self.window_s:
            self.recent.pop(0)
        try:
            m = self.db.get_message_by_frame_id(msg.arbitration_id)
        except KeyError:
            self.unknown[msg.arbitration_id] = self.unknown.get(msg.arbitration_id, 0) + 1
            return
        if msg.is_extended_id != m.is_extended_frame:
            self.unknown[msg.arbitration_id] = self.unknown.get(msg.arbitration_id, 0) + 1
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
            self.fault_events.append({"t": ts, "node": sender, **sig})

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
                "undecodable": self.undecodable,
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
        out.write(f"{name:<13}{str(n['state']):<15}{'yes' if n['alive'] else 'NO':<7}"
                  f"{n['heartbeats']:>10}  {','.join(n['faults']) or '-'}\n")
    f = s["faults"]
    out.write(f"fault events {len(f['events'])}  error frames {f['error_frames']}  "
              f"unknown ids {f['unknown_ids'] or '-'}  undecodable {f['undecodable']}\n")
    return out.getvalue()


# --- sources ----------------------------------------------------------------------------

def read_log(path: str, bad_lines: list) -> Iterator[can.Message]:
    """Messages of a candump log; a bad line is reported (line number, text, reason) and
    skipped, every other line kept."""
    with open(path, encoding="ascii", errors="replace") as f:
        for no, line in enumerate(f, 1):
            if not line.strip():
                continue
            try:
                msgs = list(can.io.canutils.CanutilsLogReader(io.StringIO(line)))
            except Exception as e:  # noqa: BLE001 - python-can raises assorted errors
                bad_lines.append({"line": no, "text": line.rstrip("\n"), "reason": repr(e)})
                print(f"{path}:{no}: bad candump line ({e!r}): {line.rstrip()}", file=sys.stderr)
                continue
            yield from msgs


def live(bus: can.BusABC, duration: Optional[float], idle_exit: Optional[float]) -> Iterator[can.Message]:
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
            time.sleep(0.005)
            continue
        last_rx = time.monotonic()
        yield msg


def parse_send(text: str) -> can.Message:
    """`ID#HEXDATA` (cansend syntax, standard identifiers) as a can.Message."""
    ident, _, data = text.partition("#")
    try:
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


def main(argv: Optional[list] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--interface", help="python-can interface: socketcand, socketcan, slcan, ...")
    src.add_argument("--log", help="read a candump log instead of a live bus")
    p.add_argument("--channel", default="vcan0", help="interface channel (default vcan0)")
    p.add_argument("--host", default="127.0.0.1", help="socketcand host (default 127.0.0.1)")
    p.add_argument("--port", type=int, default=29536, help="socketcand port (default 29536)")
    p.add_argument("--bitrate", type=int, default=500_000, help="bus bit rate [bit/s]")
    p.add_argument("--dbc", default=str(DEFAULT_DBC), help="DBC file (default protocol/walker.dbc)")
    p.add_argument("--record", help="also write every received frame to this candump log")
    p.add_argument("--duration", type=float,
                   help="stop after this many seconds (wall clock live, log time for --log)")
    p.add_argument("--idle-exit", type=float,
                   help="live: stop when nothing arrived for this many seconds after the first frame")
    p.add_argument("--interval", type=float, default=1.0, help="live table refresh [s] (text mode)")
    p.add_argument("--stale", type=float, default=0.3,
                   help="a node is not alive when its last heartbeat is older than this [s]")
    p.add_argument("--json", action="store_true", help="print one JSON summary at the end")
    p.add_argument("--send", type=parse_send, action="append", default=[], metavar="ID#DATA",
                   help="live: send this frame once after connecting (repeatable), e.g. 013#03")
    args = p.parse_args(argv)
    if args.send and args.log:
        p.error("--send needs a live --interface, not --log")

    db = cantools.database.load_file(args.dbc, strict=True)
    mon = Monitor(db, bitrate=args.bitrate, stale_s=args.stale)
    writer = can.CanutilsLogWriter(args.record, channel=args.channel) if args.record else None
    bad_lines: list = []
    bus = None
    try:
        if args.log:
            source: Iterable[can.Message] = read_log(args.log, bad_lines)
        else:
            bus = open_bus(args)
            for m in args.send:
                bus.send(m)
            source = live(bus, args.duration, args.idle_exit)
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
    finally:
        if bus is not None:
            bus.shutdown()
        if writer is not None:
            writer.stop()
    summary = mon.summary()
    summary["bad_lines"] = bad_lines
    if args.json:
        json.dump(summary, sys.stdout, indent=1, default=str)
        print()
    else:
        print(render(summary), end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
