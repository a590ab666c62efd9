"""The package's numbers equal the ``walker`` command's ``--json`` for the same command."""

from __future__ import annotations

import numpy as np
import pytest

import walker


@pytest.mark.parametrize(
    ("scene", "params"),
    [
        ("compass", {"slope_rad": 0.05}),
        ("wisse3d", {"foot_yaw_damping_n_m_s_per_rad": 0.12}),
    ],
)
def test_gait_report_equals_the_cli_json(cli, scene, params):
    sets = [a for k, v in params.items() for a in ("--set", f"{k}={v!r}")]
    code, expected, err = cli("gait", "--scene", scene, *sets, "--json")
    assert code == 0, err
    g = walker.gait(walker.Scene.load(scene).with_params(**params))
    # The whole object, every key and number (floats read back bit for bit).
    assert g.report == expected
    assert g.gait_source == expected["gait_source"]
    assert g.max_abs_eigenvalue == expected["max_abs_eigenvalue"]
    assert g.speed_m_s == expected["speed_m_s"]
    assert g.step_period_s == expected["step_period_s"]
    assert g.progress_m_per_step == expected["progress_m_per_step"]
    assert list(g.events["name"]) == [e["name"] for e in expected["events"]]
    np.testing.assert_array_equal(g.jacobian, np.array(expected["jacobian"]["rows"]))
    np.testing.assert_array_equal(
        g.fixed_point, [expected["fixed_point"][k] for k in expected["jacobian"]["names"]]
    )
    np.testing.assert_array_equal(
        g.eigenvalues, [complex(re, im) for re, im in expected["eigenvalues"]]
    )


def test_a_gait_not_found_is_the_cli_report(cli):
    # Off the defaults the 3D walker's gait is not followed this far: exit 1, converged false.
    code, expected, _ = cli("gait", "--scene", "wisse3d", "--set", "pelvic_ring_radius_m=0.43", "--json")
    assert code == 1 and expected["converged"] is False
    with pytest.raises(walker.GaitNotFound) as e:
        walker.gait(walker.Scene.load("wisse3d").with_params(pelvic_ring_radius_m=0.43))
    assert e.value.report == expected
    assert str(e.value) == expected["error"]


def test_wisse3d_default_gait_is_the_papers():
    g = walker.gait(walker.Scene.load("wisse3d"))
    # the README's value, to the central-difference Jacobian's noise (a few 1e-9)
    assert abs(g.max_abs_eigenvalue - 0.98773638) < 1e-8
    assert g.gait_source == "defaults"
    assert g.cost_of_transport_j_per_kg_m is not None
    balance = g.energy_balance
    assert abs(balance["energy_balance_residual_j"]) < 1e-3 * balance["actuator_work_j_per_step"]


def test_walk_report_equals_the_cli_json(cli):
    code, expected, err = cli(
        "walk", "--scene", "compass", "--steps", "4", "--perturb", "stance_leg_dot=0.01", "--json"
    )
    assert code == 0, err
    w = walker.walk("compass", 4, perturb={"stance_leg_dot": 0.01})
    assert w.report == expected
    assert w.steps_completed == 4 and w.failure is None
    steps = w.steps
    assert list(steps["step"]) == [0, 1, 2, 3]
    np.testing.assert_array_equal(steps["duration_s"], [s["duration_s"] for s in expected["steps"]])
    assert len(w.events) == sum(len(s["events"]) for s in expected["steps"])
    # The path: every sample, in time order, over the four steps.
    n = len(w.time_s)
    assert n > 40
    assert w.q.shape == w.qdot.shape == (n, len(w.coordinates))
    assert w.hip_floor_m.shape == (n, 3)
    assert np.all(np.diff(w.time_s) >= 0)
    end_s = expected["steps"][-1]["start_time_s"] + expected["steps"][-1]["duration_s"]
    assert w.time_s[-1] == pytest.approx(end_s, abs=1e-9)
    assert set(w.step) == {0, 1, 2, 3}
    assert w.q_frame().columns.tolist() == w.coordinates


def test_a_fall_is_a_result_as_the_cli_exit_code_3(cli):
    code, expected, _ = cli("walk", "--scene", "wisse3d-uncompensated", "--steps", "10", "--json")
    assert code == 3
    w = walker.walk("wisse3d-uncompensated", 10, path_interval_s=0.01)
    assert w.report == expected
    assert w.failure is not None and w.failure == expected["failure"]
    assert w.steps_completed < 10


def test_floor_and_start_guess_as_the_cli(cli):
    code, expected, err = cli(
        "walk", "--scene", "compass", "--steps", "3", "--start", "guess",
        "--floor", "step:at=2,height_m=-0.001", "--json",
    )
    assert code in (0, 3), err
    w = walker.walk("compass", 3, start="guess", floor="step:at=2,height_m=-0.001")
    assert w.report == expected


def test_scenes_and_parameter_table_as_the_cli(cli):
    code, expected, _ = cli("scenes", "--json")
    assert code == 0
    table = walker.scenes()
    assert list(table.index) == [s["name"] for s in expected["scenes"]]
    assert list(table["degrees_of_freedom"]) == [s["degrees_of_freedom"] for s in expected["scenes"]]
    params = walker.Scene.load("compass").parameters
    slope = next(p for p in expected["scenes"] if p["name"] == "compass")["parameters"]
    by_name = {p["name"]: p for p in slope}
    assert set(params.index) == set(by_name)
    for name, row in params.iterrows():
        assert row["default"] == by_name[name]["default"]
        assert row["unit"] == by_name[name]["unit"]
        assert row["doc"] == by_name[name]["doc"]
        assert row["value"] == row["default"]
    changed = walker.Scene.load("compass").with_params(slope_rad=0.05)
    assert changed.values["slope_rad"] == 0.05
    assert changed.parameters.loc["slope_rad", "value"] == 0.05
    assert walker.Scene.load("compass").values["slope_rad"] != 0.05


def test_gaits_equal_the_cli_json(cli):
    code, expected, err = cli("gaits", "--scene", "simplest", "--set", "slope=0.015", "--json")
    assert code == 0, err
    found = walker.gaits(walker.Scene.load("simplest").with_params(slope=0.015))
    assert found.report == expected
    assert len(found.gaits) == len(expected["gaits"]) >= 2
    assert found.searches == expected["searches"]
    periods = list(found.table()["step_period_s"])
    assert periods == sorted(periods, reverse=True)
    assert all(g.gait_source is None for g in found.gaits)


def test_stability_map_equals_the_cli_json(cli):
    code, expected, err = cli(
        "stability-map", "--scene", "compass", "--x", "slope_rad=0.04:0.06:3",
        "--y", "leg_mass_kg=4:6:2", "--json",
    )
    assert code == 0, err
    m = walker.stability_map(
        "compass",
        x=("slope", expected["x"]["values"]),  # an alias, as the command takes it
        y=("leg_mass_kg", expected["y"]["values"]),
    )
    assert m.report == expected
    assert m.x_name == "slope_rad" and m.max_abs_eigenvalue.shape == (2, 3)
    assert np.all(np.isfinite(m.max_abs_eigenvalue))
    frame = m.to_frame()
    assert len(frame) == 6
    assert frame["max_abs_eigenvalue"].tolist() == [v for row in expected["max_abs_eigenvalue"] for v in row]


def test_stability_map_bad_axes():
    with pytest.raises(walker.InputError, match="both vary"):
        walker.stability_map("compass", x=("slope", [0.05]), y=("slope_rad", [0.05]))
    with pytest.raises(walker.InputError, match="cells"):
        walker.stability_map("compass", x=("slope", []), y=("leg_mass_kg", [5.0]))
    with pytest.raises(walker.SceneError) as e:
        walker.stability_map("compass", x=("slope", [0.05]), y=("no_such", [5.0]))
    assert e.value.kind == "unknown_parameter"


def test_orbit_diagram_equals_the_cli_json(cli):
    code, expected, err = cli(
        "orbit-diagram", "--scene", "simplest", "--param", "slope", "--from", "0.015",
        "--to", "0.0175", "--points", "8", "--json",
    )
    assert code == 0, err
    values = np.linspace(0.015, 0.0175, 8)
    d = walker.orbit_diagram("simplest", "slope", values)
    assert d.report == expected
    assert d.param == expected["param"]
    table = d.attractors()
    assert list(table["attractor"]) == [p["attractor"] for p in expected["points"]]
    # Past the period doubling (0.01509) the attractor has two strides.
    assert table["period_strides"].iloc[0] == 1 and table["period_strides"].iloc[-1] >= 2
    assert len(d.samples("theta")) == sum(len(p["samples"]["theta"]) for p in expected["points"])


def test_sweep_equals_the_cli_json(cli):
    code, expected, err = cli(
        "sweep", "--scene", "simplest", "--param", "slope", "--from", "0.012", "--to", "0.0155",
        "--points", "5", "--max-period", "2", "--json",
    )
    assert code == 0, err
    s = walker.sweep("simplest", "slope", 0.012, 0.0155, 5, max_period=2)
    assert s.report == expected
    assert s.param == expected["param_canonical"]
    table = s.points()
    assert len(table) == len(expected["points"])
    # The period doubling near 0.01509 is located and the doubled branch followed.
    assert 2 in set(table["period_strides"].dropna())
    with pytest.raises(walker.InputError, match="points"):
        walker.sweep("simplest", "slope", 0.012, 0.0155, 1)
    with pytest.raises(walker.InputError, match="different"):
        walker.sweep("simplest", "slope", 0.012, 0.012, 5)


def test_solver_options_are_the_commands(cli):
    scene = walker.Scene.load("compass").with_solver(integrator="dop853", rtol=1e-8, newton_tol=1e-10)
    assert scene.solver["integrator"]["kind"] == "dop853" and scene.solver["newton_tol"] == 1e-10
    code, expected, err = cli(
        "gait", "--scene", "compass", "--integrator", "dop853", "--rtol", "1e-8", "--newton-tol", "1e-10", "--json"
    )
    assert code == 0, err
    g = walker.gait(scene)
    assert g.report == expected
    assert g.report["integrator"] != walker.gait("compass").report["integrator"]
    # the options travel with the scene through with_params, into every study
    code, expected, err = cli(
        "stability-map", "--scene", "compass", "--x", "slope_rad=0.04:0.06:2", "--y", "leg_mass_kg=4:6:2",
        "--jacobian", "variational", "--json",
    )
    assert code == 0, err
    m = walker.stability_map(
        walker.Scene.load("compass").with_solver(jacobian="variational"),
        x=("slope_rad", expected["x"]["values"]),
        y=("leg_mass_kg", expected["y"]["values"]),
        progress=False,
    )
    assert m.report == expected
    code, expected, err = cli("walk", "--scene", "compass", "--steps", "3", "--integrator", "rk4", "--step-s", "0.002", "--json")
    assert code == 0, err
    w = walker.walk(walker.Scene.load("compass").with_solver(integrator="rk4", step_s=0.002), 3)
    assert w.report == expected


@pytest.mark.parametrize(
    "options, match",
    [
        ({"step_s": -1.0}, "step_s must be a positive number"),
        ({"rtol": float("nan")}, "rtol must be a positive number"),
        ({"integrator": "euler"}, "integrator `euler`: expected meijaard, rk4, dopri5 or dop853"),
        ({"integrator": "dop853", "step_s": 0.01}, "step_s sets the fixed step of meijaard and rk4"),
        ({"integrator": "rk4", "rtol": 1e-6}, "rtol sets the tolerance of dopri5 and dop853"),
        ({"jacobian": "forward"}, "jacobian `forward`: expected central or variational"),
        ({"newton_max_iter": 0}, "newton_max_iter must be"),
        ({"max_strides": -5}, "max_strides must be"),
    ],
)
def test_solver_options_bad_input(options, match):
    with pytest.raises(walker.InputError, match=match):
        walker.Scene.load("compass").with_solver(**options)


def test_a_scene_with_solver_options_repr_builds_it_again():
    scene = walker.Scene.load("compass").with_params(slope=0.05).with_solver(integrator="rk4", step_s=0.002, jacobian="variational")
    shown = repr(scene)
    assert ".with_solver(" in shown and 'integrator="rk4"' in shown
    again = eval(shown, {"Scene": walker.Scene})
    assert again.solver == scene.solver and again.values == scene.values


def test_the_scenes_stride_budget_applies_unless_a_call_gives_one(cli):
    tight = walker.Scene.load("compass").with_solver(max_strides=2)
    code, expected, _ = cli("gait", "--scene", "compass", "--max-strides", "2", "--json")
    assert code == 1
    with pytest.raises(walker.GaitNotFound) as e:
        walker.gait(tight)
    assert e.value.report == expected
    assert walker.gait(tight, max_strides=10_000).max_abs_eigenvalue < 1
