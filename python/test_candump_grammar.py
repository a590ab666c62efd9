"""The monitor's candump reader (candump_grammar.py) against the grammar shared with the Rust
reader (canbus/tests/fixtures/, also read by canbus/tests/candump_fixtures.rs), and the
monitor's bounds on bad input: malformed lines counted and a few quoted, strict JSON, memory
and output that do not grow with the log, bad flags exiting 2.

Run: scripts/python-venv && .venv/bin/python -m pytest python/
"""

import json
import io
import math
import pathlib
import random
import subprocess
import sys

import can
import cantools
import pytest

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import candump_grammar as cg  # noqa: E402
import walker_monitor as wm  # noqa: E402

SHARED = HERE.parent / "canbus" / "tests" / "fixtures"
GOOD = SHARED / "candump_good.log"
MALFORMED = SHARED / "candump_malformed.log"
A_GOOD_LINE = b"(1700000000.000214) vcan0 022#010000000000"


def side_lines(path):
    return [l for l in path.read_text().splitlines() if not l.startswith("#")]


def log_lines(path):
    return [l for l in path.read_bytes().split(b"\n") if l]


def strict_json(text):
    def refuse(c):
        raise ValueError(f"not JSON: {c}")
    return json.loads(text, parse_constant=refuse)


def run_cli(args, capsys):
    rc = wm.main(args)
    out, err = capsys.readouterr()
    return rc, out, err


# --- the shared fixtures ----------------------------------------------------------------

def test_every_good_fixture_line_reads_as_the_expected_record():
    expected = side_lines(GOOD.with_suffix(".expected"))
    assert len(expected) == len(log_lines(GOOD))
    with open(GOOD, "rb") as f:
        got = [rec for _, rec in cg.records(f)]
    assert not [r for r in got if isinstance(r, cg.Malformed)], got
    assert [r.canonical() for r in got] == expected


def test_every_malformed_fixture_line_is_rejected_never_decoded(capsys):
    why = side_lines(MALFORMED.with_suffix(".why"))
    n = len(log_lines(MALFORMED))
    assert [w.split("\t")[0] for w in why] == [str(i) for i in range(1, n + 1)]
    with open(MALFORMED, "rb") as f:
        results = list(cg.records(f))
    accepted = [(raw.quote(), r) for raw, r in results if not isinstance(r, cg.Malformed)]
    assert accepted == []
    assert [raw.number for raw, _ in results] == list(range(1, n + 1))
    # through the monitor: counted, the first few quoted, no frame
    rc, out, err = run_cli(["--log", str(MALFORMED), "--json"], capsys)
    s = strict_json(out)
    assert rc == 0
    assert s["malformed_lines"] == n
    assert s["frames"] == 0 and s["faults"]["error_frames"] == 0
    assert [b["line"] for b in s["bad_lines"]] == list(range(1, wm.MAX_QUOTED_LINES + 1))
    assert f"{n} malformed lines" in err


def test_each_malformed_line_costs_only_itself(tmp_path, capsys):
    bad = log_lines(MALFORMED)
    p = tmp_path / "mixed.log"
    p.write_bytes(b"".join(A_GOOD_LINE + b"\n" + b + b"\n" for b in bad) + A_GOOD_LINE + b"\n")
    rc, out, _ = run_cli(["--log", str(p), "--json"], capsys)
    s = strict_json(out)
    assert (rc, s["frames"], s["malformed_lines"]) == (0, len(bad) + 1, len(bad))
    assert all(b["line"] % 2 == 0 for b in s["bad_lines"])


def test_good_lines_give_the_messages_python_can_reads():
    """For every good line python-can also reads, the same frame (its error-frame test differs:
    it wants CAN_ERR_BUSERROR as well, so error classes are compared by kind only)."""
    for line in log_lines(GOOD):
        rec = cg.parse_line(line)
        ours = rec.to_message()
        theirs = next(iter(can.io.canutils.CanutilsLogReader(io.StringIO(line.decode() + "\n"))))
        assert ours.timestamp == pytest.approx(theirs.timestamp, abs=1e-6), line
        assert ours.is_error_frame == (rec.kind == "err")
        if rec.kind == "err":
            continue
        assert (ours.arbitration_id, ours.is_extended_id, ours.is_remote_frame, ours.dlc,
                bytes(ours.data or b"")) == (theirs.arbitration_id, theirs.is_extended_id,
                                             theirs.is_remote_frame, theirs.dlc,
                                             bytes(theirs.data or b"")), line
        assert ours.is_rx == theirs.is_rx, line


# --- each reported bad input --------------------------------------------------------------

@pytest.mark.parametrize("bad", [
    b"(nan) vcan0 062#00",
    b"(inf) vcan0 062#00",
    b"(-5.0) vcan0 062#00",
    b"(1.0) vcan0 062#0102030405060708090A0B",  # 11 bytes
    b"(1.0) vcan0 062#ABC",                     # odd-length hex
    b"(1.0) vcan0 FFFFFFFF#00",
    b"(1.0) vcan0 062##100",                    # CAN FD
    b"\xff\xfe garbage \x00\x01",
])
def test_a_reported_bad_line_is_counted_not_decoded(tmp_path, capsys, bad):
    p = tmp_path / "one.log"
    p.write_bytes(bad + b"\n" + A_GOOD_LINE + b"\n")
    rc, out, _ = run_cli(["--log", str(p), "--json"], capsys)
    s = strict_json(out)
    assert rc == 0
    assert s["malformed_lines"] == 1 and [b["line"] for b in s["bad_lines"]] == [1]
    assert s["frames"] == 1 and s["faults"]["error_frames"] == 0
    assert s["span_s"] == 0.0 and math.isfinite(s["bus_load"])


def test_quotes_are_few_and_short(tmp_path, capsys):
    p = tmp_path / "many.log"
    p.write_bytes(b"".join(b"garbage %d " % i + b"x" * 400 + b"\n" for i in range(1000)))
    rc, out, err = run_cli(["--log", str(p), "--json"], capsys)
    s = strict_json(out)
    assert s["malformed_lines"] == 1000
    assert len(s["bad_lines"]) == wm.MAX_QUOTED_LINES
    assert all(len(b["text"]) <= cg.QUOTE_BYTES + 3 and b["text"].endswith("...")
               for b in s["bad_lines"])
    assert "longer than 256 bytes" in s["bad_lines"][0]["reason"]
    assert len(err.splitlines()) == wm.MAX_QUOTED_LINES + 1
    assert len(err) < 2000


def test_json_has_no_nan_or_infinity():
    """A live source can still hand over a non-finite timestamp: that frame is malformed, not
    counted; any non-finite figure would be null in the JSON."""
    db = cantools.database.load_file(str(wm.DEFAULT_DBC), strict=True)
    mon = wm.Monitor(db)
    mon.feed(can.Message(timestamp=0.0, arbitration_id=0x7FF, is_extended_id=False))
    mon.feed(can.Message(timestamp=math.inf, arbitration_id=0x7FF, is_extended_id=False))
    s = mon.summary()
    assert s["span_s"] == 0.0 and s["frames"] == 1
    assert s["malformed_frames"] == 1 and "not a finite" in s["bad_frames"][0]["reason"]
    strict_json(json.dumps(wm.finite_json(s), allow_nan=False))
    text = json.dumps(wm.finite_json({"span_s": math.inf, "x": [math.nan]}), allow_nan=False)
    assert strict_json(text) == {"span_s": None, "x": [None]}


@pytest.mark.parametrize("flags, word", [
    (["--bitrate", "0"], "--bitrate"),
    (["--bitrate", "-5"], "--bitrate"),
    (["--bitrate", "fast"], "--bitrate"),
    (["--bitrate", "5e5"], "--bitrate"),
    (["--duration", "nan"], "--duration"),
    (["--duration", "-1"], "--duration"),
    (["--stale", "inf"], "--stale"),
    (["--interval", "0"], "--interval"),
    (["--idle-exit", "x"], "--idle-exit"),
    (["--port", "0"], "--port"),
    (["--port", "70000"], "--port"),
    (["--dbc", "/nonexistent/walker.dbc"], "--dbc"),
    (["--record", "/nonexistent/dir/rec.log"], "--record"),
])
def test_bad_flags_exit_2_with_a_message(capsys, flags, word):
    with pytest.raises(SystemExit) as e:
        wm.main(["--log", str(GOOD)] + flags)
    assert e.value.code == 2
    assert word in capsys.readouterr().err


def test_a_missing_log_exits_2(tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        wm.main(["--log", str(tmp_path / "missing.log")])
    assert e.value.code == 2
    assert "missing.log" in capsys.readouterr().err


def test_monitor_refuses_a_bit_rate_that_is_not_positive():
    db = cantools.database.load_file(str(wm.DEFAULT_DBC), strict=True)
    for bad in (0, -5, 0.5, True):
        with pytest.raises(ValueError, match="bit rate"):
            wm.Monitor(db, bitrate=bad)


# --- bounded state and memory ----------------------------------------------------------------

def test_monitor_state_is_bounded():
    db = cantools.database.load_file(str(wm.DEFAULT_DBC), strict=True)
    mon = wm.Monitor(db)
    fault = db.get_message_by_name("Fault_LEFT_ANKLE")
    payload = fault.encode({"code": 1, "transition": 0, "detail": 0, "uptime": 1.0})
    for i in range(1500):
        mon.feed(can.Message(timestamp=1.0, arbitration_id=fault.frame_id, data=payload,
                             is_extended_id=False))
    for i in range(2000):  # distinct unknown identifiers, all at one instant
        mon.feed(can.Message(timestamp=1.0 + i * 1e-3, arbitration_id=0x100000 + i, data=b"",
                             is_extended_id=True))
    s = mon.summary()
    assert len(s["faults"]["events"]) == wm.MAX_FAULT_EVENTS
    assert s["faults"]["events_total"] == 1500
    assert len(s["faults"]["unknown_ids"]) == wm.MAX_UNKNOWN_IDS
    assert s["faults"]["unknown_ids_other"] == 2000 - wm.MAX_UNKNOWN_IDS
    assert len(mon.recent) <= wm.WINDOW_BUCKETS + 1


def test_window_load_matches_the_steady_load():
    db = cantools.database.load_file(str(wm.DEFAULT_DBC), strict=True)
    mon = wm.Monitor(db)
    for m in wm.read_log(str(HERE / "fixtures" / "demo-nominal.log"), []):
        mon.feed(m)
    s = mon.summary()
    # 3 s of a steady schedule: the last second carries the average load (within 5 %)
    assert s["bus_load_window"] == pytest.approx(s["bus_load"], rel=0.05)


HWM = """
import runpy, sys
script = sys.argv[1]
sys.argv = [script] + sys.argv[2:]
code = 0
try:
    runpy.run_path(script, run_name="__main__")
except SystemExit as e:
    code = e.code
finally:
    with open("/proc/self/status") as f:
        hwm = next(l for l in f if l.startswith("VmHWM")).split()[1]
    sys.stderr.write(f"\\nVmHWM_KiB {hwm}\\n")
sys.exit(code)
"""


def peak_kib_and_outputs(tmp_path, log):
    out, err = tmp_path / "out.json", tmp_path / "err.txt"
    with open(out, "wb") as o, open(err, "wb") as e:
        rc = subprocess.run([sys.executable, "-c", HWM, str(HERE / "walker_monitor.py"),
                             "--log", str(log), "--json"], stdout=o, stderr=e,
                            timeout=600).returncode
    text = err.read_text(errors="replace")
    hwm = int(text.rsplit("VmHWM_KiB", 1)[1])
    return rc, hwm, out.read_bytes(), text


@pytest.mark.skipif(not pathlib.Path("/proc/self/status").exists(), reason="needs /proc")
def test_a_large_garbage_log_takes_bounded_memory_and_output(tmp_path):
    """A 50 MB line without a newline, 32 MB of random bytes, then good lines: the monitor's
    peak resident memory and its output do not grow with the log. Measured (2 cores): peak
    +0.1 MiB over the same run on a 3 s log, 2.4 kB of JSON, 1.4 kB on stderr, 3 s; before
    the grammar: 264 MB for 33 MB of garbage, 88 MB of output, 1.7 GB for a 50 MB line."""
    big = tmp_path / "garbage.log"
    rnd = random.Random(14)
    with open(big, "wb") as f:
        f.write(b"(1.0) vcan0 ")
        for _ in range(50):
            f.write(b"7" * (1 << 20))
        f.write(b"\n")
        for _ in range(32):
            f.write(rnd.randbytes(1 << 20))
        f.write(b"\n" + b"\n".join(log_lines(GOOD)) + b"\n")
    rc0, base_kib, _, _ = peak_kib_and_outputs(tmp_path, HERE / "fixtures" / "demo-nominal.log")
    rc, kib, out, err = peak_kib_and_outputs(tmp_path, big)
    assert rc0 == 0 and rc == 0, err[-2000:]
    s = strict_json(out)
    # every good line counted: decoded, an error frame or on another channel than the first
    assert s["frames"] + s["faults"]["error_frames"] + sum(
        s["faults"]["other_channels"].values()) == len(log_lines(GOOD))
    assert s["malformed_lines"] > 100_000  # random bytes: a newline every 256 bytes or so
    assert len(s["bad_lines"]) == wm.MAX_QUOTED_LINES
    assert kib - base_kib < 32 * 1024, (kib, base_kib)  # holding the 50 MB line would fail
    assert len(out) < 64 * 1024
    assert len(err) < 8 * 1024
