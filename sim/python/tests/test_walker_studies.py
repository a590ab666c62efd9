"""``walker.studies``: a study as pure tasks, written to a study file it resumes from, equal bit
for bit to the one-process function; the Ray cluster test (``test_cluster``) runs
``ray_cluster_check.py`` in a network namespace of its own."""

from __future__ import annotations

import os
import pathlib
import pickle
import shutil
import subprocess
import sys

import pandas as pd
import pyarrow.parquet as pq
import pytest
import walker
import walker.studies as studies

HERE = pathlib.Path(__file__).resolve().parent
SCENE = walker.Scene.load("compass")
X = ("slope", [0.01, 0.03, 0.05, 0.07, 0.08])
Y = ("leg_mass_kg", [1.0, 4.0, 7.0, 10.0])


@pytest.fixture(scope="module")
def reference():
    return walker.stability_map(SCENE, X, Y, progress=False)


def test_a_scene_pickles_to_the_same_scene_with_its_values_and_solver(tmp_path):
    s = walker.Scene.load("compass").with_params(slope_rad=0.0612345678901234).with_solver(rtol=1e-10, newton_tol=1e-11)
    t = pickle.loads(pickle.dumps(s))
    assert repr(t) == repr(s) and t.values == s.values and t.solver == s.solver
    assert walker.gait(t).report == walker.gait(s).report
    # a scene file given by path travels with its text: the copy needs no file
    path = tmp_path / "mine.toml"
    shutil.copy(pathlib.Path(walker.__file__).parents[3] / "scenes" / "compass.toml", path)
    u = walker.Scene.load(path).with_params(hip_mass_kg=12.0)
    blob = pickle.dumps(u)
    path.unlink()
    v = pickle.loads(blob)
    assert v.values == u.values and walker.gait(v).report == walker.gait(u).report


def test_the_study_with_a_file_equals_the_one_process_map_bit_for_bit(tmp_path, reference):
    for cells in (1, 3, 20, None):
        m = studies.stability_map(SCENE, X, Y, study_file=tmp_path / f"m{cells}.parquet", progress=False,
                                  cells_per_task=cells)
        assert m.report == reference.report, cells
    table = pd.read_parquet(tmp_path / "m3.parquet")
    assert len(table) == 20 and set(table.columns) >= {"i", "j", "x", "y", "max_abs_eigenvalue", "gait_source"}
    eig = table.set_index(["j", "i"])["max_abs_eigenvalue"]
    assert all(eig[(j, i)] == reference.max_abs_eigenvalue[j, i] for j in range(4) for i in range(5))


def test_an_interrupted_study_resumes_from_its_file_and_computes_only_what_is_missing(tmp_path, reference):
    path = tmp_path / "study.parquet"

    class Stop(Exception):
        pass

    def stop_after_two_tasks(done, total):
        if done >= 6:
            raise Stop

    with pytest.raises(Stop):
        studies.stability_map(SCENE, X, Y, study_file=path, progress=stop_after_two_tasks, cells_per_task=3)
    kept = len(pd.read_parquet(path))
    assert 6 <= kept < 20
    seen = []
    m = studies.stability_map(SCENE, X, Y, study_file=path, progress=lambda d, t: seen.append((d, t)), cells_per_task=3)
    assert seen[0] == (kept, 20) and seen[-1] == (20, 20)
    assert m.report == reference.report
    # a finished study is read back without a task
    seen.clear()
    again = studies.stability_map(SCENE, X, Y, study_file=path, progress=lambda d, t: seen.append(d))
    assert seen == [20] and again.report == reference.report


def test_the_file_carries_the_spec_and_versions_and_another_study_is_refused_naming_the_difference(tmp_path):
    path = tmp_path / "study.parquet"
    studies.stability_map(SCENE, X, Y, study_file=path, progress=False)
    import json

    meta = json.loads(pq.read_schema(path).metadata[studies.METADATA_KEY])
    assert meta["spec"]["x"] == {"name": "slope_rad", "values": X[1]}
    assert meta["spec"]["scene"]["name"] == "compass"
    assert {"walker", "pyarrow", "python"} <= set(meta["versions"])
    before = path.read_bytes()
    with pytest.raises(walker.InputError, match=r"x\.values\[2\]: 0\.05 in the file, 0\.051 now"):
        studies.stability_map(SCENE, (X[0], [0.01, 0.03, 0.051, 0.07, 0.08]), Y, study_file=path, progress=False)
    with pytest.raises(walker.InputError, match=r"scene\.values\.hip_mass_kg: 10\.0 in the file, 11\.0 now"):
        studies.stability_map(SCENE.with_params(hip_mass_kg=11.0), X, Y, study_file=path, progress=False)
    assert path.read_bytes() == before, "a refused study leaves the file as it was"


def test_bad_input_is_refused_before_anything_runs(tmp_path):
    not_parquet = tmp_path / "notes.parquet"
    not_parquet.write_text("not a table")
    with pytest.raises(walker.InputError, match="not a Parquet file"):
        studies.stability_map(SCENE, X, Y, study_file=not_parquet, progress=False)
    assert not_parquet.read_text() == "not a table"
    with pytest.raises(walker.InputError, match="executor must be one of local, ray"):
        studies.stability_map(SCENE, X, Y, executor="dask", progress=False)
    with pytest.raises(walker.InputError, match="Ray's options"):
        studies.stability_map(SCENE, X, Y, address="127.0.0.1:6379", progress=False)
    with pytest.raises(walker.InputError, match="cells_per_task"):
        studies.stability_map(SCENE, X, Y, study_file=tmp_path / "a.parquet", cells_per_task=0, progress=False)
    with pytest.raises(walker.InputError, match="both vary"):
        studies.stability_map(SCENE, X, ("slope_rad", [0.02]), study_file=tmp_path / "b.parquet", progress=False)
    with pytest.raises(walker.SceneError):
        studies.stability_map(SCENE, X, ("leg_mass_kg", [-1.0]), study_file=tmp_path / "c.parquet", progress=False)
    assert not (tmp_path / "a.parquet").exists() and not (tmp_path / "c.parquet").exists()


def test_the_module_runs_from_a_shell_and_writes_the_same_map(tmp_path, reference):
    path = tmp_path / "shell.parquet"
    out = subprocess.run(
        [sys.executable, "-m", "walker.studies", "stability-map", "--scene", "compass",
         "--x", "slope=" + ",".join(map(str, X[1])), "--y", "leg_mass_kg=" + ",".join(map(str, Y[1])),
         "--study-file", str(path), "--no-progress"],
        capture_output=True, text=True, timeout=300,
    )
    assert out.returncode == 0, out.stderr
    assert "20 of 20 cells" in out.stdout
    m = studies.stability_map(SCENE, X, Y, study_file=path, progress=False)
    assert m.report == reference.report
    bad = subprocess.run([sys.executable, "-m", "walker.studies", "stability-map", "--scene", "compass",
                          "--x", "slope=abc", "--y", "leg_mass_kg=1,2", "--study-file", str(tmp_path / "x.parquet")],
                         capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and "slope=abc" in bad.stderr and "Traceback" not in bad.stderr


def _namespace_available() -> str | None:
    """Why a network namespace cannot be made here, or ``None``."""
    if shutil.which("unshare") is None or shutil.which("ip") is None:
        return "unshare or ip is not installed"
    probe = subprocess.run(["unshare", "-n", "true"], capture_output=True, text=True)
    if probe.returncode != 0:
        return f"unshare -n is not permitted here ({probe.stderr.strip()}): run as root"
    return None


def test_cluster():
    """A head and two worker nodes in a network namespace of their own: the map on the
    cluster, with a worker node killed in the middle, and resumed after an interruption, each
    equal bit for bit to the one-process map (``ray_cluster_check.py``)."""
    why = _namespace_available()
    if why is not None:
        if os.environ.get("WALKER_REQUIRE_RAY"):
            pytest.fail(f"WALKER_REQUIRE_RAY is set and the Ray cluster cannot run: {why}")
        pytest.skip(why)
    script = f"ip link set lo up && exec {sys.executable} {HERE / 'ray_cluster_check.py'}"
    try:
        out = subprocess.run(["unshare", "-n", "sh", "-c", script], capture_output=True, text=True, timeout=900)
    except subprocess.TimeoutExpired as e:
        # the check stops its cluster at its own deadline (600 s); past this one, its nodes
        # (each in a session of its own) are found by their temp dir and killed
        text = e.stdout.decode() if isinstance(e.stdout, bytes) else (e.stdout or "")
        temp = next((line.split(": ", 1)[1] for line in text.splitlines() if line.startswith("cluster temp dir: ")), None)
        if temp:
            subprocess.run(["pkill", "-9", "-f", temp])
        raise
    checks = [line for line in out.stdout.splitlines() if line.startswith("ok: ")]
    assert out.returncode == 0, out.stdout + out.stderr[-6000:]
    assert len(checks) == 15, checks
    # the killed nodes were running tasks, which Ray ran again (its driver log says so)
    assert "Task map_block failed" in out.stdout + out.stderr, out.stdout[-3000:]
    assert "Task optimize_block failed" in out.stdout + out.stderr, out.stdout[-3000:]


# step_down: about 15 ms a candidate, so that the search is still running when it is stopped
OPTIMIZE = dict(vary={"slope_rad": (0.02, 0.07), "leg_mass_kg": (2.0, 8.0)}, objective="step_down",
                budget=30, seed=3)


def test_optimize_as_a_study_equals_the_one_process_search_and_resumes_from_its_file(tmp_path):
    best = walker.optimize(SCENE, progress=False, **OPTIMIZE)
    path = tmp_path / "search.parquet"

    class Stop(Exception):
        pass

    def stop(done, total):
        if done >= 10:
            raise Stop

    with pytest.raises(Stop):
        studies.optimize(SCENE, study_file=path, progress=stop, **OPTIMIZE)
    kept = len(pd.read_parquet(path))
    assert 0 < kept < 30
    again = studies.optimize(SCENE, study_file=path, progress=False, **OPTIMIZE)
    assert again.report == best.report
    table = pd.read_parquet(path)
    assert len(table) == 30 and list(table["n"]) == list(range(30))
    with pytest.raises(walker.InputError, match=r"seed: 3 in the file, 4 now"):
        studies.optimize(SCENE, study_file=path, progress=False, **{**OPTIMIZE, "seed": 4})
    with pytest.raises(walker.InputError, match=r"study: 'optimize' in the file, 'stability_map' now"):
        studies.stability_map(SCENE, X, Y, study_file=path, progress=False)


def test_an_evaluator_that_answers_for_other_designs_is_refused():
    from walker import _walker

    s = SCENE
    ranges = ["slope_rad=0.02:0.07"]

    def liar(scene, ranges_, texts):
        def batch(drawn, cancelled):
            other = [[u[0] + 1e-3] for u in drawn]
            return _walker.optimize_evaluate(scene, ranges_, "max_abs_eigenvalue", other, budget=8)
        return batch

    with pytest.raises(walker.InputError, match="another design"):
        walker._optimize(s, ranges, "max_abs_eigenvalue", (), 8, 0, 0.25, None, False, liar)

    def raises(scene, ranges_, texts):
        def batch(drawn, cancelled):
            raise ZeroDivisionError("the cluster is gone")
        return batch

    with pytest.raises(ZeroDivisionError, match="the cluster is gone"):
        walker._optimize(s, ranges, "max_abs_eigenvalue", (), 8, 0, 0.25, None, False, raises)


def test_a_changed_scene_file_or_a_refused_option_never_mixes_or_leaves_a_file(tmp_path):
    scene_file = tmp_path / "mine.toml"
    shutil.copy(pathlib.Path(walker.__file__).parents[3] / "scenes" / "compass.toml", scene_file)
    path = tmp_path / "study.parquet"
    studies.stability_map(walker.Scene.load(scene_file), X, Y, study_file=path, progress=False)
    scene_file.write_text(scene_file.read_text().replace('com_m = [0, "-leg_com_from_hip_m", 0]',
                                                         'com_m = [0, "-0.9 * leg_com_from_hip_m", 0]'))
    with pytest.raises(walker.InputError, match=r"scene\.file_sha256"):
        studies.stability_map(walker.Scene.load(scene_file), X, Y, study_file=path, progress=False)
    for bad in (dict(quantity="nosuch"), dict(quantity="mfpt"), dict(quantity="mfpt", sigma_m=-1.0),
                dict(sigma_m=0.001), dict(quantity="mfpt", sigma_m=float("nan"))):
        fresh = tmp_path / "refused.parquet"
        with pytest.raises(walker.InputError):
            studies.stability_map(SCENE, X, Y, study_file=fresh, progress=False, **bad)
        assert not fresh.exists(), bad
    with pytest.raises(walker.InputError, match="is a directory"):
        studies.stability_map(SCENE, X, Y, study_file=tmp_path, progress=False)
    with pytest.raises(walker.InputError, match="does not exist"):
        studies.stability_map(SCENE, X, Y, study_file=tmp_path / "no" / "such.parquet", progress=False)


def test_the_spec_tells_minus_zero_from_zero():
    from walker.studies._study_file import differences

    assert differences({"v": [0.0]}, {"v": [-0.0]}) == ["v[0]: 0.0 in the file, -0.0 now"]
    assert differences({"v": [1.5]}, {"v": [1.5]}) == []


def test_the_module_runs_a_search_from_a_shell_and_resumes_it(tmp_path):
    best = walker.optimize(SCENE, progress=False, **OPTIMIZE)
    path = tmp_path / "search.parquet"
    command = [sys.executable, "-m", "walker.studies", "optimize", "--scene", "compass",
               "--vary", "slope_rad=0.02:0.07", "--vary", "leg_mass_kg=2.0:8.0", "--objective", "step_down",
               "--budget", "30", "--seed", "3", "--study-file", str(path), "--no-progress", "--json"]
    out = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    import json

    assert json.dumps(json.loads(out.stdout), sort_keys=True) == json.dumps(best.report, sort_keys=True)
    again = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert again.returncode == 0 and again.stdout == out.stdout
    bad = subprocess.run(command[:-4] + ["--budget", "0", "--study-file", str(tmp_path / "b.parquet")],
                         capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and "budget" in bad.stderr and "Traceback" not in bad.stderr
    assert not (tmp_path / "b.parquet").exists()
