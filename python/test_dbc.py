"""The generated DBC file loads in cantools' strict mode and decodes the frames that the Rust
codec encoded (protocol/test-vectors.json) to the same physical values.

Run: scripts/python-venv && .venv/bin/python -m pytest python/
"""

import json
import math
import pathlib

import cantools
import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
DBC = ROOT / "protocol" / "walker.dbc"
VECTORS = ROOT / "protocol" / "test-vectors.json"


@pytest.fixture(scope="module")
def db():
    return cantools.database.load_file(str(DBC), strict=True)


@pytest.fixture(scope="module")
def vectors():
    return json.loads(VECTORS.read_text())


def test_strict_load_has_every_node_and_message(db):
    assert sorted(n.name for n in db.nodes) == ["HOST", "LEFT_ANKLE", "RIGHT_ANKLE"]
    # 20 identifiers of v1, plus Identity, BootInfo, CommandAck, FaultHistory and ClockInfo
    # per ankle
    assert len(db.messages) == 30
    for m in db.messages:
        assert not m.is_extended_frame
        assert m.frame_id < 0x800


def test_priorities(db):
    ids = {m.name: m.frame_id for m in db.messages}
    telemetry = min(ids["AnkleState_LEFT_ANKLE"], ids["Heartbeat_HOST"])
    assert ids["EmergencyStop_ALL"] < telemetry
    assert ids["HeelStrike_LEFT_ANKLE"] < telemetry


def test_vectors_cover_every_message(db, vectors):
    assert {v["name"] for v in vectors} == {m.name for m in db.messages}


def test_rust_encoded_frames_decode_identically(db, vectors):
    assert len(vectors) > 40
    for v in vectors:
        msg = db.get_message_by_frame_id(v["id"])
        assert msg.name == v["name"]
        data = bytes.fromhex(v["data"])
        assert len(data) == msg.length
        decoded = db.decode_message(
            v["id"], data, decode_choices=False, scaling=True
        )
        assert set(decoded) == set(v["signals"]), v["name"]
        for name, want in v["signals"].items():
            got = decoded[name]
            assert math.isclose(got, want, rel_tol=1e-12, abs_tol=1e-12), (
                v["name"], name, got, want)


def test_cantools_encodes_back_to_rust_bytes(db, vectors):
    for v in vectors:
        decoded = db.decode_message(v["id"], bytes.fromhex(v["data"]), decode_choices=False,
                                    scaling=False)
        again = db.encode_message(v["id"], decoded, scaling=False, strict=True)
        assert again.hex() == v["data"], v["name"]


def test_enumerations_named(db):
    st = db.get_message_by_name("AnkleState_RIGHT_ANKLE")
    phase = st.get_signal_by_name("reflex_phase")
    assert {int(k): str(v) for k, v in phase.choices.items()} == {
        0: "Inactive", 1: "Swing", 2: "Free", 3: "Push", 4: "Hold"}
