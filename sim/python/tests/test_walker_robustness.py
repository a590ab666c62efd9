"""``walker.robustness``, ``walker.basin`` and ``stability_map(quantity=)``: the command's JSON
for the same arguments, checked against walks; progress callbacks; bad input."""

from __future__ import annotations

import numpy as np
import pytest

import walker

COMPASS_MEASURES = ["--measures", "gsn,steps,mfpt", "--sigma-m", "0.002", "--mfpt-runs", "12", "--mfpt-strides", "40"]


def test_robustness_equals_the_cli_json_and_walks_agree(cli):
    code, expected, err = cli("robustness", "--scene", "compass", *COMPASS_MEASURES, "--json")
    assert code == 0, err
    seen = []
    r = walker.robustness(
        "compass",
        measures=["gsn", "steps", "mfpt"],
        sigma_m=[0.002],
        mfpt_runs=12,
        mfpt_strides=40,
        progress=lambda done, total: seen.append((done, total)),
    )
    assert r.report == expected
    assert r.errors == {}
    assert r.velocity_perturbation_max is None  # not asked for
    assert r.gait.gait_source == "defaults"
    assert r.gait_sensitivity_norm["both"] > 0
    mfpt = r.mfpt
    assert list(mfpt["sigma_m"]) == [0.002] and int(mfpt["runs"][0]) == 12
    # the progress callable heard every stage: three and one roughness
    assert seen and seen[-1] == (4, 4)
    assert all(d <= t for d, t in seen)
    # independent of the measure's own search: a walk over a step just inside the threshold
    # goes on, just past it (the bracket is 1e-7 m) the walker does not come back
    down = r.step_down_max_m
    assert 1e-4 < down < 0.1
    inside = walker.walk("compass", 30, floor=f"step:at=1,height_m={-down * 0.999}")
    assert inside.failure is None
    bracket = r.report["step_thresholds"]["down"]["bracket"]
    assert bracket <= 1.000001e-7
    again = r.report["survived_again_from_m"]["down"]
    if again is None or again > down + 1e-3:
        past = walker.walk("compass", 100, floor=f"step:at=1,height_m={-(down + 1e-4)}")
        assert past.failure is not None


def test_an_unstable_gait_has_no_measure_and_says_why(cli):
    # the compass at a steep slope walks an unstable period-1 gait
    code, expected, _ = cli("robustness", "--scene", "compass", "--set", "slope_rad=0.2", "--measures", "gsn", "--json")
    if expected is None or expected["gait"].get("converged") is False:
        pytest.skip("no period-1 gait there on this build")  # pragma: no cover
    assert code == 1
    with pytest.warns(RuntimeWarning, match="unstable"):
        r = walker.robustness(walker.Scene.load("compass").with_params(slope_rad=0.2), measures=["gsn"])
    assert r.report == expected
    assert "gait" in r.errors and r.gait_sensitivity_norm is None


def test_basin_equals_the_cli_json(cli):
    code, expected, err = cli(
        "basin", "--scene", "compass", "--x", "stance_leg=0.15:0.25:6",
        "--y", "stance_leg_dot=-1.4:-0.9:5", "--strides", "60", "--json",
    )
    assert code == 0, err
    seen = []
    b = walker.basin(
        "compass",
        ("stance_leg", expected["x"]["values"]),  # the command's grid, to the last bit
        ("stance_leg_dot", expected["y"]["values"]),
        strides=60,
        progress=lambda d, t: seen.append((d, t)),
    )
    assert b.report == expected
    assert b.outcome.shape == (5, 6) and b.strides.shape == (5, 6)
    assert b.fraction_returning == pytest.approx(np.mean(b.returns))
    assert b.solved_coordinate == "swing_leg"
    assert seen[-1] == (30, 30)
    frame = b.to_frame()
    assert len(frame) == 30
    assert list(frame["outcome"]) == [o for row in expected["outcome"] for o in row]
    # cells that return took at most the strides allowed; the others say how they ended
    assert np.all(b.strides[b.returns] <= 60)
    assert b.gait.names == ["stance_leg", "stance_leg_dot", "swing_leg", "swing_leg_dot"]


def test_stability_map_of_a_quantity_equals_the_cli_json(cli):
    code, expected, err = cli(
        "stability-map", "--scene", "compass", "--x", "slope_rad=0.01:0.02:2",
        "--y", "leg_mass_kg=5:6:2", "--quantity", "step_down", "--json",
    )
    assert code == 0, err
    m = walker.stability_map(
        "compass", ("slope_rad", [0.01, 0.02]), ("leg_mass_kg", [5.0, 6.0]), quantity="step_down", progress=False
    )
    assert m.report == expected
    assert m.quantity_name == "step_down"
    assert m.quantity.shape == (2, 2) and np.all(m.quantity > 0)
    assert list(m.to_frame()["step_down"]) == [v for row in expected["quantity"]["values"] for v in row]
    # the map's cell is the robustness measure at that cell
    r = walker.robustness(walker.Scene.load("compass").with_params(slope_rad=0.02, leg_mass_kg=5.0), measures=["steps"])
    assert r.step_down_max_m == m.quantity[0, 1]


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"measures": ["gsn", "bogus"]}, "measures: unknown measure `bogus`"),
        ({"measures": ["gsn"], "sigma_m": [0.001]}, "sigma_m is the rough floor"),
        ({"sigma_m": [-1.0]}, "sigma_m -1"),
        ({"mfpt_runs": 0}, "mfpt_runs must be"),
        ({"mfpt_runs": -3}, "mfpt_runs must be"),
        ({"mfpt_runs": 100_000, "mfpt_strides": 1_000_000}, "at most 100000000 strides"),
        ({"rate_scan_step": 0.0}, "rate_scan_step must be"),
        ({"rate_scan_step": float("nan")}, "rate_scan_step must be"),
        ({"return_strides": 10**30}, "return_strides must be"),
        ({"mfpt_seed": -1}, "mfpt_seed"),
        ({"progress": "yes"}, "progress must be"),
        ({"measures": []}, "measures: name at least one measure"),
        ({"sigma_m": []}, "sigma_m: give at least one roughness"),
    ],
)
def test_robustness_bad_input_is_an_input_error(kwargs, match):
    with pytest.raises(walker.InputError, match=match):
        walker.robustness("compass", **kwargs)


@pytest.mark.parametrize(
    "x, y, kwargs, match",
    [
        (("stance_leg", [0.1]), ("stance_leg", [0.2]), {}, "both slice"),
        (("nope", [0.1]), ("stance_leg", [0.2]), {}, "not a stride-map coordinate of compass"),
        (("stance_leg", []), ("swing_leg", [0.2]), {}, "no values"),
        (("stance_leg", [float("nan")]), ("swing_leg", [0.2]), {}, "finite"),
        (("stance_leg", [0.1]), ("swing_leg", [0.2]), {"strides": 0}, "strides must be"),
        (("stance_leg", list(range(300))), ("swing_leg", list(range(300))), {}, "at most"),
    ],
)
def test_basin_bad_input_is_an_input_error(x, y, kwargs, match):
    with pytest.raises(walker.InputError, match=match):
        walker.basin("compass", x, y, **kwargs)


def test_stability_map_quantity_bad_input():
    axes = (("slope_rad", [0.01]), ("leg_mass_kg", [5.0]))
    with pytest.raises(walker.InputError, match="expected one of"):
        walker.stability_map("compass", *axes, quantity="nope")
    with pytest.raises(walker.InputError, match="sigma_m"):
        walker.stability_map("compass", *axes, quantity="mfpt")
    with pytest.raises(walker.InputError, match="sigma_m is the rough floor"):
        walker.stability_map("compass", *axes, sigma_m=0.001)
    with pytest.raises(walker.InputError, match="^sigma_m NaN: a standard deviation") as e:
        walker.stability_map("compass", *axes, quantity="mfpt", sigma_m=float("nan"))
    assert "--" not in str(e.value)


def test_one_measure_by_name():
    r = walker.robustness("compass", measures="gsn", progress=False)
    assert r.gait_sensitivity_norm is not None and r.step_down_max_m is None


def test_a_progress_callable_that_raises_stops_the_study():
    class Stop(Exception):
        pass

    def stop(done, total):
        raise Stop()

    with pytest.raises(Stop):
        walker.stability_map("compass", ("slope_rad", list(np.linspace(0.01, 0.08, 40))), ("leg_mass_kg", [4.0, 5.0, 6.0]), progress=stop)


def test_gaits_reports_progress():
    seen = []
    found = walker.gaits("compass", progress=lambda d, t: seen.append((d, t)))
    assert found.gaits and seen
    done, total = seen[-1]
    assert 0 < done <= total


def test_sweep_of_a_quantity_equals_the_cli_json(cli):
    code, expected, err = cli(
        "sweep", "--scene", "compass", "--param", "slope_rad", "--from", "0.01", "--to", "0.02",
        "--points", "4", "--quantity", "step_down", "--json",
    )
    assert code == 0, err
    seen = []
    s = walker.sweep("compass", "slope_rad", 0.01, 0.02, 4, quantity="step_down", progress=lambda d, t: seen.append((d, t)))
    assert s.report == expected
    points = s.points()
    assert "step_down" in points and points["step_down"].notna().all()
    assert seen[-1] == (4, 4)  # the measuring stage, after the continuation's thousandths
    assert any(t == 1000 for _, t in seen)
    # the sweep's value at a point is the robustness measure there
    at = walker.robustness(walker.Scene.load("compass").with_params(slope_rad=float(points["value"][0])), measures="steps", progress=False)
    assert at.step_down_max_m == pytest.approx(points["step_down"][0], rel=1e-6)
