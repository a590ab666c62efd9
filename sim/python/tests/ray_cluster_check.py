"""The Ray cluster checks of issue 30, run inside a network namespace of its own
(``test_walker_studies.py::test_cluster`` starts it with ``unshare -n``): a head and two worker nodes as
separate processes on 127.0.0.1; a compass stability map and a short ``optimize`` (the
step-down objective: tens of milliseconds a candidate) on the cluster equal bit for bit to the
one-process runs; the same with a worker node killed in the middle of each; an interrupted
study and an interrupted search resumed from their files equal to uninterrupted ones. Exits 0 when every check holds, 1 with
the failing check on stderr. ``--timings FILE`` also writes the throughput on 1 and 2 worker
processes (docs/cluster.md)."""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from ray_cluster import AUTH_MODE, Cluster  # noqa: E402

os.environ["RAY_AUTH_MODE"] = AUTH_MODE  # before Ray is imported

import ray  # noqa: E402
import walker  # noqa: E402
import walker.studies as studies  # noqa: E402

SCENE = walker.Scene.load("compass")
OPTIMIZE = dict(vary={"slope_rad": (0.02, 0.07), "leg_mass_kg": (2.0, 8.0)}, objective="step_down",
                budget=40, seed=3)
# a search whose candidates take about half a second each: a worker node killed a second in
# is killed while it runs one (the driver's log then says the task was retried)
WISSE3D = walker.Scene.load("wisse3d")
SLOW = dict(vary={"pelvis_yaw_stiffness_n_m_per_rad": (0.8, 1.3)}, objective="max_abs_eigenvalue", budget=8, seed=1)
DEADLINE_S = 600
"""The whole check's budget [s]: past it, the cluster is stopped and the check fails."""


def same(a, b) -> bool:
    """Equal bit for bit: the JSON texts (which tell -0.0 from 0.0, and show NaN)."""
    return json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)
X = ("slope", [0.01 + 0.07 * k / 39 for k in range(40)])
Y = ("leg_mass_kg", [1.0 + 9.0 * k / 39 for k in range(40)])


class Interrupted(Exception):
    pass


def check(ok: bool, what: str) -> None:
    if not ok:
        raise AssertionError(what)
    print(f"ok: {what}", flush=True)


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--timings")
    args = parser.parse_args()
    def out_of_time(signum, frame):
        raise TimeoutError(f"the cluster check ran past {DEADLINE_S} s")

    signal.signal(signal.SIGALRM, out_of_time)
    signal.alarm(DEADLINE_S)
    cluster = Cluster(workers=2)
    print(f"cluster temp dir: {cluster.temp}", flush=True)
    try:
        cluster.connect(ray)
        nodes = [n for n in ray.nodes() if n["Alive"]]
        check(all(n["NodeManagerAddress"] == "127.0.0.1" for n in nodes),
              f"every node on 127.0.0.1 ({[n['NodeManagerAddress'] for n in nodes]})")
        t0 = time.perf_counter()
        reference = walker.stability_map(SCENE, X, Y, progress=False)
        local_s = time.perf_counter() - t0
        best = walker.optimize(SCENE, progress=False, **OPTIMIZE)
        with tempfile.TemporaryDirectory() as tmp:
            # 1. the cluster's map equals the one-process map, bit for bit
            t0 = time.perf_counter()
            on_ray = studies.stability_map(SCENE, X, Y, executor="ray", progress=False,
                                           study_file=os.path.join(tmp, "ray.parquet"))
            ray2_s = time.perf_counter() - t0
            check(same(on_ray.report, reference.report), "the map on 2 worker nodes equals the one-process map")
            small = studies.stability_map(SCENE, X, Y, executor="ray", progress=False, cells_per_task=7)
            check(same(small.report, reference.report), "the same with 7 cells a task")
            searched = studies.optimize(SCENE, executor="ray", progress=False, **OPTIMIZE)
            check(same(searched.report, best.report), "optimize on 2 worker nodes equals the one-process search")

            # 2. an interrupted study resumed from its file equals an uninterrupted one
            path = os.path.join(tmp, "resumed.parquet")

            def stop_midway(done: int, total: int) -> None:
                if done >= total // 3:
                    raise Interrupted()

            try:
                studies.stability_map(SCENE, X, Y, executor="ray", study_file=path, progress=stop_midway)
                check(False, "the study was interrupted")
            except Interrupted:
                pass
            import pandas as pd

            kept = len(pd.read_parquet(path))
            total = len(X[1]) * len(Y[1])
            check(0 < kept < total, f"the interrupted study's file holds {kept} of {total} cells")
            started: list[int] = []
            resumed = studies.stability_map(SCENE, X, Y, executor="ray", study_file=path,
                                            progress=lambda d, t: started.append(d))
            check(started[0] == kept and started[-1] == total,
                  f"the resumed study starts from the file's {kept} cells and ends at {total} ({started[0]}, {started[-1]})")
            check(same(resumed.report, reference.report), "the resumed study equals the uninterrupted one")

            opt_path = os.path.join(tmp, "optimize.parquet")

            def stop_optimize(done: int, total: int) -> None:
                if done >= 15:
                    raise Interrupted()

            try:
                studies.optimize(SCENE, executor="ray", study_file=opt_path, progress=stop_optimize, **OPTIMIZE)
                check(False, "the search was interrupted")
            except Interrupted:
                pass
            kept = len(pd.read_parquet(opt_path))
            check(0 < kept < OPTIMIZE["budget"], f"the interrupted search's file holds {kept} of "
                  f"{OPTIMIZE['budget']} evaluations")
            resumed_search = studies.optimize(SCENE, executor="ray", study_file=opt_path, progress=False, **OPTIMIZE)
            check(same(resumed_search.report, best.report), "the resumed search equals the uninterrupted one")
            evaluated = pd.read_parquet(opt_path)
            check(len(evaluated) == OPTIMIZE["budget"] and evaluated["n"].tolist() == list(range(OPTIMIZE["budget"])),
                  "the file holds every evaluation once")

            # 3. a worker node killed while it runs a task loses nothing
            killed: list[bool] = []

            def kill_running(worker, task: str) -> threading.Thread:
                t = threading.Thread(target=lambda: killed.append(cluster.kill_when_running(worker, task)))
                t.start()
                return t

            watcher = kill_running(cluster.workers[0], "map_block")
            survived = studies.stability_map(SCENE, X, Y, executor="ray", progress=False,
                                             study_file=os.path.join(tmp, "killed.parquet"))
            watcher.join()
            check(killed == [True], "a worker node was killed while it ran a map task")
            check(same(survived.report, reference.report), "the map with a worker node killed equals the one-process map")
            deadline = time.monotonic() + 120.0  # the head notices a dead node by its missed heartbeats
            while True:
                alive = [n for n in ray.nodes() if n["Alive"] and n["Resources"].get("CPU")]
                if len(alive) == 1 or time.monotonic() > deadline:
                    break
                time.sleep(1.0)
            check(len(alive) == 1, f"the head sees one worker node left ({len(alive)})")
            cluster.add_worker(ray)
            killed.clear()
            slow_best = walker.optimize(WISSE3D, progress=False, **SLOW)
            watcher = kill_running(cluster.workers[1], "optimize_block")
            survived_search = studies.optimize(WISSE3D, executor="ray", progress=False, **SLOW)
            watcher.join()
            check(killed == [True], "a worker node was killed while it ran a search's task")
            check(same(survived_search.report, slow_best.report),
                  "optimize (wisse3d) with a worker node killed equals the one-process search")

            if args.timings:
                t0 = time.perf_counter()
                studies.stability_map(SCENE, X, Y, executor="ray", progress=False)
                ray1_s = time.perf_counter() - t0
                with open(args.timings, "w") as f:
                    json.dump({"cells": total, "one_process_2_threads_s": local_s, "ray_2_workers_s": ray2_s,
                               "ray_1_worker_s": ray1_s}, f, indent=1)
        return 0
    except (AssertionError, TimeoutError) as e:
        print(f"FAILED: {e}\n{cluster.tail()}", file=sys.stderr, flush=True)
        return 1
    finally:
        try:
            ray.shutdown()
        finally:
            cluster.stop()


if __name__ == "__main__":
    sys.exit(main())
