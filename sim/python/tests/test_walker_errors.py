"""Bad input gives a clear Python exception carrying the CLI's message and the values it names."""

from __future__ import annotations

import _thread
import threading

import pytest

import walker


def cli_error(cli, *args: str) -> str:
    code, _, err = cli(*args)
    assert code == 2, err
    assert err.startswith("error: "), err
    return err.removeprefix("error: ").strip()


def test_unknown_scene(cli):
    with pytest.raises(walker.SceneError) as e:
        walker.Scene.load("no-such-scene")
    assert e.value.kind == "unknown_scene"
    assert e.value.name == "no-such-scene"
    assert "compass" in e.value.available
    assert str(e.value) == cli_error(cli, "gait", "--scene", "no-such-scene")
    assert isinstance(e.value, walker.WalkerError) and isinstance(e.value, ValueError)


def test_unknown_parameter(cli):
    with pytest.raises(walker.SceneError) as e:
        walker.Scene.load("compass").with_params(no_such_param=1.0)
    assert e.value.kind == "unknown_parameter"
    assert (e.value.scene, e.value.name) == ("compass", "no_such_param")
    assert str(e.value) == cli_error(cli, "gait", "--scene", "compass", "--set", "no_such_param=1")


def test_out_of_range_value(cli):
    with pytest.raises(walker.SceneError) as e:
        walker.Scene.load("compass").with_params(leg_mass_kg=-1.0)
    assert e.value.kind == "out_of_range"
    assert e.value.name == "leg_mass_kg" and e.value.value == -1.0
    assert e.value.min == 0.0 or e.value.min > 0.0
    assert str(e.value) == cli_error(cli, "gait", "--scene", "compass", "--set", "leg_mass_kg=-1")


def test_not_a_number_and_not_finite():
    with pytest.raises(walker.SceneError) as e:
        walker.Scene.load("compass").with_params(slope_rad=float("nan"))
    assert e.value.kind == "not_a_number"
    with pytest.raises(walker.InputError):
        walker.Scene.load("compass").with_params(slope_rad="steep")
    with pytest.raises(walker.InputError, match="already set"):
        walker.Scene.load("compass").with_params(slope_rad=0.05, slope=0.05)


def interrupted_after(seconds: float, call) -> float:
    """Runs ``call()`` with a Ctrl-C (``_thread.interrupt_main``) delivered after ``seconds``;
    asserts it raised ``KeyboardInterrupt`` and returns the seconds it took."""
    import time

    timer = threading.Timer(seconds, _thread.interrupt_main)
    started = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
    finally:
        timer.cancel()
    return time.monotonic() - started


def test_ctrl_c_stops_a_long_sweep():
    # A wisse3d sweep of 200 points takes minutes (the review measured 16 s to a Ctrl-C when
    # the continuation had no cancel hook); its budget stops it at the next stride.
    took = interrupted_after(1.0, lambda: walker.sweep("wisse3d", "slope_rad", 0.001, 0.05, 200, progress=False))
    assert took < 5.0


def test_ctrl_c_stops_a_sweep_still_looking_for_its_first_gait():
    # At these slopes the first gait's search tries many starts (24 s to a Ctrl-C when the
    # cancelled budget did not reach it): the family refuses every setup once cancelled.
    took = interrupted_after(1.0, lambda: walker.sweep("wisse3d", "slope_rad", 0.3, 0.35, 40, progress=False))
    assert took < 5.0


def test_a_raising_alarm_handler_stops_a_walk_promptly():
    import signal
    import time

    def on_alarm(signum, frame):
        raise TimeoutError("alarm")

    old = signal.signal(signal.SIGALRM, on_alarm)
    started = time.monotonic()
    signal.setitimer(signal.ITIMER_REAL, 0.3)
    try:
        with pytest.raises(TimeoutError):
            walker.walk("wisse3d", 1000)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    assert time.monotonic() - started < 1.5


def test_a_sigint_handler_that_does_not_raise_does_not_cut_a_walk_short():
    import signal

    heard = []
    old = signal.signal(signal.SIGINT, lambda signum, frame: heard.append(signum))
    timer = threading.Timer(0.2, _thread.interrupt_main)
    timer.start()
    try:
        walked = walker.walk("wisse3d", 300)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, old)
    assert heard and walked.failure is None and walked.steps_completed == 300


@pytest.mark.parametrize("steps", [-1, walker.MAX_WALK_STEPS + 1])
def test_bad_steps(steps):
    with pytest.raises(walker.InputError, match="steps must be an integer between 0 and 100000"):
        walker.walk("compass", steps)


def test_bad_walk_options():
    with pytest.raises(walker.InputError, match="floor"):
        walker.walk("compass", 2, floor="bumpy")
    with pytest.raises(walker.InputError, match="not an entry of the stride map"):
        walker.walk("compass", 2, perturb={"knee": 0.1})
    with pytest.raises(walker.InputError, match="start"):
        walker.walk("compass", 2, start="standing")
    with pytest.raises(walker.InputError, match="not a finite number"):
        walker.walk("compass", 2, perturb={"stance_leg": float("nan")})
    with pytest.raises(walker.InputError, match="not a finite number"):
        walker.walk("compass", 2, start={"stance_leg": float("inf")})
    with pytest.raises(walker.InputError, match="path_interval_s"):
        walker.walk("compass", 2, path_interval_s=-1.0)
    with pytest.raises(walker.InputError, match="max_strides"):
        walker.gait("compass", max_strides=0)


def test_gait_not_found_carries_the_cli_report(cli):
    code, expected, _ = cli("gait", "--scene", "compass", "--max-strides", "3", "--json")
    assert code == 1 and expected["converged"] is False
    with pytest.raises(walker.GaitNotFound) as e:
        walker.gait("compass", max_strides=3)
    assert e.value.report == expected
    assert str(e.value) == expected["error"]
    assert e.value.newton_iterations == expected["newton_iterations"]
    # A stride of the search ran out of the budget: the failure says so.
    assert isinstance(e.value, walker.StrideFailed)
    assert e.value.failure == expected["failure"] and e.value.failure is not None


def test_ctrl_c_stops_a_long_walk():
    # Delivered while the walk runs without the GIL: the walk stops at its next stride.
    interrupted_after(0.5, lambda: walker.walk("compass", walker.MAX_WALK_STEPS, path_interval_s=10.0))


def test_ctrl_c_stops_a_long_stability_map():
    import numpy as np

    # 400 gait searches of the 3D walker take minutes; Ctrl-C ends the map at the next search.
    took = interrupted_after(
        0.5,
        lambda: walker.stability_map(
            "wisse3d",
            x=("slope_rad", np.linspace(0.04, 0.06, 20)),
            y=("pelvic_ring_radius_m", np.linspace(0.40, 0.44, 20)),
        ),
    )
    assert took < 30.0


@pytest.mark.parametrize(
    "call",
    [
        lambda: walker.gait("compass", max_strides=-1),
        lambda: walker.gait("compass", max_strides=0),
        lambda: walker.walk("compass", 10**30),
        lambda: walker.walk("compass", 2, max_strides=-1),
        lambda: walker.walk("compass", 2, max_path_samples=0),
        lambda: walker.walk("compass", 2, max_path_samples=10**12),
        lambda: walker.sweep("simplest", "slope", 0.01, 0.012, points=-5),
        lambda: walker.sweep("simplest", "slope", 0.01, 0.012, points=4, max_period=-1),
        lambda: walker.walk("compass", 2.5),
    ],
)
def test_counts_out_of_range_are_input_errors_naming_the_range(call):
    # not Python's own OverflowError / TypeError ("can't convert negative int to unsigned")
    with pytest.raises(walker.InputError, match=r"must be an integer between \d+ and \d+, got"):
        call()


def test_a_path_like_and_start_none_are_accepted(tmp_path):
    import pathlib
    import shutil

    import numpy as np

    src = pathlib.Path(__file__).resolve().parents[2] / "scenes" / "compass.toml"
    copy = tmp_path / "compass.toml"
    shutil.copy(src, copy)
    by_path = walker.Scene.load(copy)
    assert by_path.name == "compass"
    a = walker.walk(copy, 2, start=None)
    b = walker.walk("compass", 2)
    assert np.array_equal(a.q, b.q)


def test_a_path_past_its_bound_stops_warns_and_the_walk_goes_on():
    whole = walker.walk("compass", 3)
    assert whole.path_cut_at_time_s is None
    bound = len(whole.time_s) // 3
    with pytest.warns(RuntimeWarning, match="max_path_samples"):
        cut = walker.walk("compass", 3, max_path_samples=bound)
    assert len(cut.time_s) == bound
    assert cut.path_cut_at_time_s == whole.time_s[bound - 1]
    assert cut.steps_completed == whole.steps_completed == 3
    assert (cut.q == whole.q[:bound]).all()
