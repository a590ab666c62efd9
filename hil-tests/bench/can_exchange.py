#!/usr/bin/env python3
"""Bench helper of the hardware tier (hil-tests/tests/hardware.rs): puts frames on a
SocketCAN bus and prints every frame received, candump style, one per line:
``(1700000000.123456) can0 0A2#0123456789ABCDEF``.

The Rust tests encode and decode the frames with the protocol crate (the one definition of
the messages); this script only moves bytes.

    can_exchange.py --channel can0 --duration 3 [--at 0.5 042#080000000000]...
                    [--every 0.05 063#01...]...

``--at T ID#DATA`` sends once, T seconds after the start; ``--every P ID#DATA`` sends every
P seconds for the whole duration (e.g. the other ankle's heartbeat, which an ankle needs
before it may be enabled). Ends after ``--duration`` seconds (at most 60).
"""
import argparse
import sys
import time

import can


def frame(text):
    ident, _, data = text.partition("#")
    arb = int(ident, 16)
    payload = bytes.fromhex(data)
    if arb > 0x7FF or len(payload) > 8:
        raise argparse.ArgumentTypeError(f"{text!r}: 11-bit identifier, at most 8 bytes")
    return can.Message(arbitration_id=arb, data=payload, is_extended_id=False)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--channel", required=True)
    p.add_argument("--duration", type=float, required=True)
    p.add_argument("--at", nargs=2, action="append", default=[], metavar=("T", "ID#DATA"))
    p.add_argument("--every", nargs=2, action="append", default=[], metavar=("P", "ID#DATA"))
    args = p.parse_args(argv)
    duration = min(max(args.duration, 0.0), 60.0)
    once = sorted((float(t), frame(f)) for t, f in args.at)
    periodic = [[float(per), frame(f), 0.0] for per, f in args.every]
    if any(per <= 0.0 for per, _, _ in periodic):
        p.error("--every needs a positive period")
    with can.Bus(interface="socketcan", channel=args.channel) as bus:
        start = time.monotonic()
        while True:
            now = time.monotonic() - start
            if now >= duration:
                break
            while once and once[0][0] <= now:
                bus.send(once.pop(0)[1])
            for entry in periodic:
                if entry[2] <= now:
                    bus.send(entry[1])
                    entry[2] = now + entry[0]
            msg = bus.recv(timeout=0.005)
            if msg is not None and not msg.is_error_frame and not msg.is_extended_id:
                print(f"({msg.timestamp:.6f}) {args.channel} {msg.arbitration_id:03X}#{msg.data.hex().upper()}")
    sys.stdout.flush()


if __name__ == "__main__":
    main()
