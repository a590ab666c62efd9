"""``walker.sil``: the ``walker sil --json`` report, the nodes and their faults, and the bus
frames (what ``--candump`` logs) decoded with the project's DBC."""

from __future__ import annotations

import _thread
import pathlib
import threading
import time

import pytest

import walker

ROOT = pathlib.Path(__file__).resolve().parents[3]


def read_candump(path: pathlib.Path) -> list[tuple[float, int, str]]:
    """``(time_s, id, data hex)`` of each line of a candump log."""
    out = []
    for line in path.read_text().splitlines():
        stamp, _channel, frame = line.split()[:3]
        ident, data = frame.split("#")
        out.append((float(stamp.strip("()")), int(ident, 16), data.upper()))
    return out


def cli_error(cli, *args: str) -> str:
    code, _, err = cli(*args)
    assert code == 2, err
    assert err.startswith("error: "), err
    return err.removeprefix("error: ").strip()


@pytest.fixture(scope="module")
def nominal():
    return walker.sil("wisse3d", 6)


def test_report_equals_the_cli_json_and_frames_the_candump_log(cli, tmp_path, nominal):
    log = tmp_path / "bus.log"
    code, expected, err = cli("sil", "--scene", "wisse3d", "--steps", "6", "--json", "--candump", str(log))
    assert code == 0, err
    # The whole object, every key and number (floats read back bit for bit).
    assert nominal.report == expected
    assert nominal.steps_completed == 6 and nominal.failure is None
    assert nominal.gait == expected["gait"] and nominal.gait is not None
    assert nominal.ideal_gait == expected["ideal_gait"]
    assert nominal.start["gait_source"] == "defaults"
    # The frames are the run's: the candump log's, one for one.
    logged = read_candump(log)
    frames = nominal.frames
    assert len(frames) == len(logged) == expected["frames"] > 1000
    assert nominal.frames_cut_at_time_s is None and nominal.frames_not_kept == 0
    assert frames["id"].tolist() == [i for _, i, _ in logged]
    assert frames["data"].tolist() == [d for _, _, d in logged]
    assert frames["dlc"].tolist() == [len(d) // 2 for _, _, d in logged]
    # The log writes microseconds, truncated.
    for t, (t_log, _, _) in zip(frames["time_s"], logged):
        assert t_log <= t < t_log + 1e-6 + 1e-12
    assert not frames["error"].any()


def test_frames_are_decoded_with_the_dbc(nominal):
    frames = nominal.frames
    assert frames["name"].notna().all()
    # Heartbeats: from the ankles (node 2 left, 3 right: the id's low nibble), every node
    # enabled after start-up, uptime growing, no fault flags on the nominal walk.
    beats = frames[frames["name"].str.startswith("Heartbeat_")]
    assert set(beats["sender"]) == {"LEFT_ANKLE", "RIGHT_ANKLE"}
    for sender, node in (("LEFT_ANKLE", 2), ("RIGHT_ANKLE", 3)):
        own = beats[beats["sender"] == sender]
        assert len(own) > 20
        assert set(own["id"]) == {0x060 | node}
        assert own["name"].iloc[0] == f"Heartbeat_{sender}"
        assert own["state"].iloc[-1] == "Enabled"
        assert (own["uptime"].diff().dropna() > 0).all()
        assert (own["fault_flags"] == 0).all()
    # Ankle states: angles in radians within the joint's travel, phases by name.
    states = nominal.messages("AnkleState_LEFT_ANKLE")
    assert {"angle", "rate", "actuator_position", "reflex_phase"} <= set(states.columns)
    assert states["angle"].abs().max() < 1.0
    assert {"Swing", "Free", "Push"} <= set(states["reflex_phase"])
    # Heel strikes: one frame per strike each node reports sending.
    for side, sender in (("Left", "LEFT_ANKLE"), ("Right", "RIGHT_ANKLE")):
        strikes = frames[frames["name"] == f"HeelStrike_{sender}"]
        assert len(strikes) == nominal.nodes.loc[side, "heel_strikes_sent"] >= 1
    # The host enabled both nodes with a broadcast command first.
    first = frames.iloc[0]
    assert (first["name"], first["opcode"]) == ("Command_ALL", "Enable")


def test_dbc_is_the_projects_file():
    text = walker.dbc()
    assert text == (ROOT / "protocol" / "walker.dbc").read_text()
    import cantools

    db = cantools.database.load_string(text, database_format="dbc")
    assert db.get_message_by_name("Heartbeat_LEFT_ANKLE").frame_id == 0x062


def test_nodes_and_steps_tables(nominal):
    nodes = nominal.nodes
    assert list(nodes.index) == ["Left", "Right"]
    assert (nodes["state"] == "Enabled").all()
    assert nodes.loc["Left", "parameters.taut_angle_rad"] == nominal.report["nodes"]["Left"]["parameters"]["taut_angle_rad"]
    assert nominal.node_faults.empty and list(nominal.node_faults.columns) == ["time_s", "side", "fault", "raised", "detail"]
    steps = nominal.steps
    assert steps["step"].tolist() == list(range(6))
    assert steps["duration_s"].tolist() == [s["duration_s"] for s in nominal.report["steps"]]


def test_a_lost_heartbeat_is_a_node_fault_as_the_cli_reports_it(cli, tmp_path):
    log = tmp_path / "bus.log"
    fault = "drop:id=0x062,count=1000"
    code, expected, err = cli(
        "sil", "--scene", "wisse3d", "--steps", "6", "--fault", fault, "--json", "--candump", str(log)
    )
    assert code in (0, 3), err
    ran = walker.sil("wisse3d", 6, faults=[fault])
    assert ran.report == expected
    faults = ran.node_faults
    lost = faults[(faults["fault"] == "PeerHeartbeatLost") & (faults["side"] == "Right")]
    assert len(lost) >= 1 and lost["raised"].iloc[0]
    assert lost["time_s"].iloc[0] == expected["node_faults"][0]["t_s"]
    # The left node's heartbeats never reached the bus; the right node told of its fault.
    frames = ran.frames
    assert 0x062 not in set(frames["id"])
    assert [i for _, i, _ in read_candump(log)] == frames["id"].tolist()
    told = frames[frames["name"] == "Fault_RIGHT_ANKLE"]
    assert "PeerHeartbeatLost" in set(told["code"])
    assert set(told["transition"]) <= {"Raised", "Cleared"}
    # A fall is a result (the command's exit code 3), not an error.
    assert (ran.failure is None) == (code == 0)


def test_an_encoder_fault_is_a_node_fault(cli):
    spec = "spi:side=right,from_ms=500"
    code, expected, err = cli("sil", "--scene", "wisse3d", "--steps", "4", "--sensor-fault", spec, "--json")
    assert code in (0, 3), err
    ran = walker.sil("wisse3d", 4, sensor_faults=[spec])
    assert ran.report == expected
    faults = ran.node_faults
    comms = faults[(faults["fault"] == "EncoderComms") & (faults["side"] == "Right")]
    assert comms["raised"].iloc[0] and comms["time_s"].iloc[0] == pytest.approx(0.5)
    assert ran.sensor_faults_applied["kind"].tolist() == ["spi"]
    assert ran.nodes.loc["Right", "fault_raises.EncoderComms"] >= 1
    # A fall is put down to the first safety-relevant fault before it (none without a fall).
    assert ran.fall_cause == expected["fall_cause"]
    if ran.failure is not None:
        assert ran.fall_cause["code"] == "EncoderComms" and ran.fall_cause["side"] == "Right"


def test_firmware_params_estop_and_keep_steps_as_the_cli(cli):
    code, expected, err = cli(
        "sil", "--scene", "wisse3d", "--steps", "5", "--firmware-param", "taut_angle_rad=-0.07",
        "--estop-at", "1.5", "--keep-steps", "10", "--json",
    )
    assert code in (0, 3), err
    ran = walker.sil(
        "wisse3d", 5, firmware_params={"taut_angle_rad": -0.07}, estop_at_s=1.5, keep_steps=10
    )
    assert ran.report == expected
    assert ran.firmware_params_written == {"taut_angle_rad": -0.07}
    assert ran.nodes.loc["Left", "parameters.taut_angle_rad"] == pytest.approx(-0.07)
    assert ran.emergency_stop_sent_s == pytest.approx(1.5, abs=1e-3)
    stops = ran.frames[ran.frames["name"] == "EmergencyStop_ALL"]
    assert len(stops) == 1 and stops["time_s"].iloc[0] >= 1.5
    # The same parameter as text gives the same run.
    assert walker.sil(
        "wisse3d", 5, firmware_params=["taut_angle_rad=-0.07"], estop_at_s=1.5, keep_steps=10
    ).report == expected


def test_frames_past_max_frames_are_cut_with_a_warning(nominal):
    with pytest.warns(RuntimeWarning, match="max_frames"):
        cut = walker.sil("wisse3d", 6, max_frames=100)
    assert cut.report == nominal.report
    assert len(cut.frames) == 100
    assert cut.frames_not_kept == len(nominal.frames) - 100
    assert cut.frames_cut_at_time_s == cut.frames["time_s"].iloc[-1] == nominal.frames["time_s"].iloc[99]
    assert cut.frames["data"].tolist() == nominal.frames["data"].iloc[:100].tolist()
    none = walker.sil("wisse3d", 2, max_frames=0)
    assert none.frames.empty and none.frames_not_kept == none.report["frames"]


@pytest.mark.parametrize(
    ("kwargs", "cli_args"),
    [
        ({"faults": ["bogus"]}, ["--fault", "bogus"]),
        ({"faults": ["drop:id=0x101,count=5"]}, ["--fault", "drop:id=0x101,count=5"]),
        ({"sensor_faults": ["stuck:side=middle,from_ms=5"]}, ["--sensor-fault", "stuck:side=middle,from_ms=5"]),
        ({"firmware_params": {"taut_angle_rad": 5}}, ["--firmware-param", "taut_angle_rad=5"]),
        ({"firmware_params": ["no_such=1"]}, ["--firmware-param", "no_such=1"]),
        ({"actuator": "piston"}, ["--actuator", "piston"]),
        ({"estop_at_s": -1.0}, ["--estop-at", "-1"]),
    ],
)
def test_bad_input_is_the_cli_message(cli, kwargs, cli_args):
    with pytest.raises(walker.InputError) as e:
        walker.sil("wisse3d", 2, **kwargs)
    assert str(e.value) == cli_error(cli, "sil", "--scene", "wisse3d", "--steps", "2", *cli_args)


def test_bad_steps_and_a_scene_without_ankles(cli):
    too_many = walker.MAX_WALK_STEPS + 1
    with pytest.raises(walker.InputError) as e:
        walker.sil("wisse3d", too_many)
    assert str(e.value) == cli_error(cli, "sil", "--scene", "wisse3d", "--steps", str(too_many))
    with pytest.raises(walker.InputError, match=r"steps must be an integer between 0 and 100000, got -1"):
        walker.sil("wisse3d", -1)
    with pytest.raises(walker.InputError) as e:
        walker.sil("compass", 2)
    assert str(e.value) == cli_error(cli, "sil", "--scene", "compass", "--steps", "2")
    assert "no actuated ankles" in str(e.value)
    with pytest.raises(walker.InputError, match="max_frames"):
        walker.sil("wisse3d", 2, max_frames=walker.MAX_SIL_FRAMES + 1)
    with pytest.raises(walker.SceneError):
        walker.sil("no-such-scene", 2)


def test_no_gait_to_start_from_raises_gait_not_found(cli):
    code, _, err = cli("sil", "--scene", "wisse3d", "--set", "pelvic_ring_radius_m=0.43", "--steps", "2")
    assert code == 1 and "no ideal-actuator gait to start from" in err
    with pytest.raises(walker.GaitNotFound) as e:
        walker.sil(walker.Scene.load("wisse3d").with_params(pelvic_ring_radius_m=0.43), 2)
    assert e.value.report["converged"] is False


def test_ctrl_c_stops_a_long_sil_walk():
    # Delivered while the walk runs without the GIL: the walk stops at its next step.
    timer = threading.Timer(1.0, _thread.interrupt_main)
    started = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            walker.sil("wisse3d", walker.MAX_WALK_STEPS, keep_steps=10, max_frames=0)
    finally:
        timer.cancel()
    assert time.monotonic() - started < 30.0


def test_solver_options_as_the_clis_integrator_flags(cli):
    # the walk with the firmware takes the options; the ideal-actuator gait it starts from is
    # found with the scene's own integrator, as the command does
    code, expected, err = cli("sil", "--scene", "wisse3d", "--steps", "2", "--rtol", "1e-8", "--newton-tol", "1e-10", "--json")
    assert code in (0, 3), err
    ran = walker.sil(walker.Scene.load("wisse3d").with_solver(rtol=1e-8, newton_tol=1e-10), 2)
    assert ran.report == expected
    assert ran.report["integrator"] != walker.sil("wisse3d", 2).report["integrator"]
