"""``walker.optimize``: the ``walker optimize --json`` object bit for bit, deterministic by its
seed, its best design's value what ``walker.gait`` finds there, bad input refused with the
keyword named, and its progress counted to ``budget + 1``."""

from __future__ import annotations

import math

import numpy as np
import pytest

import walker

RANGE = {"leg_mass_kg": (4.0, 6.0)}


def run(**kwargs):
    args = dict(budget=12, seed=3, progress=False)
    args.update(kwargs)
    return walker.optimize("compass", RANGE, "max_abs_eigenvalue", **args)


@pytest.fixture(scope="module")
def short():
    seen = []
    result = run(progress=lambda d, t: seen.append((d, t)))
    return result, seen


def test_a_short_compass_search_equals_the_cli_json(cli, short):
    code, expected, err = cli(
        "optimize", "--scene", "compass", "--vary", "leg_mass_kg=4:6",
        "--objective", "max_abs_eigenvalue", "--budget", "12", "--seed", "3", "--json",
    )
    assert code == 0, err
    o, _ = short
    assert o.report == expected
    assert len(o.evaluations) == 12 and len(expected["evaluations"]) == 12
    assert list(o.evaluations["value"]) == [e["value"] for e in expected["evaluations"]]
    assert list(o.evaluations["leg_mass_kg"]) == [e["parameters"]["leg_mass_kg"] for e in expected["evaluations"]]
    assert list(o.evaluations["generation"]) == [e["generation"] for e in expected["evaluations"]]
    assert len(o.generations) == len(expected["generations"])
    assert o.best is not None and o.best.index == expected["best"]["index"]
    assert o.best.value == expected["best"]["value"]
    assert o.best.gait.report == expected["best"]["gait"]
    assert o.default == expected["default"]
    assert o.default["parameters"]["leg_mass_kg"] == walker.Scene.load("compass").values["leg_mass_kg"]
    history = [math.nan if v is None else v for v in expected["history"]]
    np.testing.assert_array_equal(o.history, np.array(history))
    assert o.objective == "max_abs_eigenvalue" and o.sense == "minimise"


def test_a_constrained_search_with_solver_options_equals_the_cli_json(cli):
    code, expected, err = cli(
        "optimize", "--scene", "compass", "--vary", "leg_com_from_hip_m=0.3:0.7",
        "--vary", "leg_mass_kg=4:6", "--objective", "max_abs_eigenvalue",
        "--constraint", "step_period_s<=0.77", "--budget", "10", "--seed", "1",
        "--rtol", "1e-9", "--json",
    )
    assert code in (0, 1), err
    scene = walker.Scene.load("compass").with_solver(rtol=1e-9)
    o = walker.optimize(
        scene, ["leg_com_from_hip_m=0.3:0.7", "leg_mass_kg=4:6"], "max_abs_eigenvalue",
        constraints=[("step_period_s", "<=", 0.77)], budget=10, seed=1, progress=False,
    )
    assert o.report == expected
    frame = o.evaluations
    assert set(frame.columns) >= {"leg_com_from_hip_m", "leg_mass_kg", "value", "feasible", "step_period_s"}
    assert (frame.loc[frame["feasible"], "step_period_s"] <= 0.77).all()
    # the solver options reach the search: the default rtol gives another report
    plain = walker.optimize(
        "compass", ["leg_com_from_hip_m=0.3:0.7", "leg_mass_kg=4:6"], "max_abs_eigenvalue",
        constraints=["step_period_s<=0.77"], budget=10, seed=1, progress=False,
    )
    assert plain.report["default"]["value"] != o.report["default"]["value"]


def test_the_same_seed_repeats_the_search_and_another_seed_searches_elsewhere(short):
    o, _ = short
    again = run()
    assert again.report == o.report
    other = run(seed=4)
    assert [e["normalised"] for e in other.report["evaluations"]] != [e["normalised"] for e in o.report["evaluations"]]


def test_the_best_value_is_the_gait_walker_gait_finds_at_the_best_design(short):
    o, _ = short
    scene = walker.Scene.load("compass").with_params(**o.best.parameters)
    g = walker.gait(scene)
    assert g.max_abs_eigenvalue == o.best.value
    assert g.gait_source == o.best.gait.gait_source
    feasible = o.evaluations[o.evaluations["feasible"]]
    assert o.best.value == feasible["value"].min()
    assert o.history[-1] == o.best.value


def test_progress_counts_every_evaluation_and_the_scenes_design(short):
    _, seen = short
    assert seen[-1] == (13, 13)
    assert all(t == 13 and 0 <= d <= 13 for d, t in seen)


@pytest.mark.parametrize(
    "vary, objective, kwargs, error, match",
    [
        (RANGE, "max_abs_eigenvalue", {"budget": 0}, walker.InputError, "^budget must be between 1 and 10000, got 0$"),
        (RANGE, "max_abs_eigenvalue", {"budget": -2}, walker.InputError, "^budget must be between 1 and 10000, got -2$"),
        (RANGE, "max_abs_eigenvalue", {"budget": 10**30}, walker.InputError, "budget must be between 1 and 10000"),
        (RANGE, "max_abs_eigenvalue", {"budget": 1.5}, walker.InputError, "budget must be an integer"),
        (RANGE, "max_abs_eigenvalue", {"seed": -1}, walker.InputError, "seed must be an integer"),
        (RANGE, "max_abs_eigenvalue", {"initial_step": 0.0}, walker.InputError, "^initial_step must be above 0"),
        (RANGE, "max_abs_eigenvalue", {"initial_step": float("nan")}, walker.InputError, "initial_step must be"),
        (RANGE, "fastest", {}, walker.InputError, "^objective `fastest`: expected one of"),
        (RANGE, "mfpt", {}, walker.InputError, r"objective mfpt: mfpt needs the rough floor's standard deviation \(sigma_m\)"),
        (RANGE, "mfpt", {"sigma_m": -1.0}, walker.InputError, "sigma_m -1"),
        (RANGE, "gsn", {"sigma_m": 0.001}, walker.InputError, "^sigma_m is the rough floor of mfpt"),
        (RANGE, "gsn", {"constraints": ["speed=1"]}, walker.InputError, "^constraints `speed=1`: expected NAME<=V"),
        (RANGE, "gsn", {"constraints": ["legs<=1"]}, walker.InputError, "unknown quantity `legs`"),
        (RANGE, "gsn", {"constraints": [("speed_m_s", "==", 1.0)]}, walker.InputError, "relation"),
        (RANGE, "cost_of_transport", {}, walker.InputError, "no actuated ankle"),
        ({"leg_mass_kg": (6.0, 4.0)}, "gsn", {}, walker.InputError, "^vary `leg_mass_kg=6.0:4.0`: MIN 6 must be below MAX 4"),
        ({"leg_mass_kg": (float("nan"), 4.0)}, "gsn", {}, walker.InputError, "not a finite number"),
        ({"leg_mass_kg": 4.0}, "gsn", {}, walker.InputError, "pair"),
        (["leg_mass_kg=4"], "gsn", {}, walker.InputError, "NAME=MIN:MAX"),
        ([], "gsn", {}, walker.InputError, "nothing to vary"),
        (["leg_mass_kg=4:6", "leg_mass_kg=4.5:5"], "gsn", {}, walker.InputError, "twice"),
        ({"nope": (0.0, 1.0)}, "gsn", {}, walker.SceneError, "nope"),
        ({"leg_com_from_hip_m": (-1.0, 0.5)}, "gsn", {}, walker.SceneError, "outside its allowed range"),
        (RANGE, "gsn", {"progress": "yes"}, walker.InputError, "progress must be"),
    ],
)
def test_bad_input_is_refused_naming_the_keyword(vary, objective, kwargs, error, match):
    with pytest.raises(error, match=match):
        walker.optimize("compass", vary, objective, **kwargs)


def test_a_range_outside_the_parameters_is_a_scene_error_with_its_fields():
    with pytest.raises(walker.SceneError) as raised:
        walker.optimize("compass", {"leg_com_from_hip_m": (-1.0, 0.5)}, "gsn", progress=False)
    assert raised.value.kind == "out_of_range"
    assert raised.value.name == "leg_com_from_hip_m"
    assert str(raised.value).startswith("vary `leg_com_from_hip_m=-1.0:0.5`: ")


def test_a_progress_callable_that_raises_stops_the_search():
    class Stop(Exception):
        pass

    def stop(done, total):
        raise Stop()

    with pytest.raises(Stop):
        walker.optimize("compass", {"leg_mass_kg": (4.0, 6.0), "leg_com_from_hip_m": (0.3, 0.7)}, "gsn", budget=10_000, progress=stop)
