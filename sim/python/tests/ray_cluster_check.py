"""The Ray cluster checks of issue 30, run inside a network namespace of its own
(``test_walker_studies_ray.py`` starts it with ``unshare -n``): a head and two worker nodes as
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
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import ray  # noqa: E402
import walker  # noqa: E402
import walker.studies as studies  # noqa: E402
from ray_cluster import Cluster  # noqa: E402

SCENE = walker.Scene.load("compass")
OPTIMIZE = dict(vary={"slope_rad": (0.02, 0.07), "leg_mass_kg": (2.0, 8.0)}, objective="step_down",
                budget=40, seed=3)
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
    cluster = Cluster(workers=2)
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
            check(on_ray.report == reference.report, "the map on 2 worker nodes equals the one-process map")
            small = studies.stability_map(SCENE, X, Y, executor="ray", progress=False, cells_per_task=7)
            check(small.report == reference.report, "the same with 7 cells a task")
            searched = studies.optimize(SCENE, executor="ray", progress=False, **OPTIMIZE)
            check(searched.report == best.report, "optimize on 2 worker nodes equals the one-process search")

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
            check(started[0] == kept, f"the resumed study starts from the file's {kept} cells ({started[0]})")
            check(resumed.report == reference.report, "the resumed study equals the uninterrupted one")

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
            check(resumed_search.report == best.report, "the resumed search equals the uninterrupted one")
            check(len(pd.read_parquet(opt_path)) == OPTIMIZE["budget"],
                  "the resumed search evaluated only the designs its file lacked")

            # 3. a worker node killed in the middle loses nothing
            killed: list[bool] = []

            def kill_midway(done: int, total: int) -> None:
                if not killed and done >= total // 4:
                    cluster.kill(cluster.workers[0])
                    killed.append(True)

            survived = studies.stability_map(SCENE, X, Y, executor="ray", progress=kill_midway,
                                             study_file=os.path.join(tmp, "killed.parquet"))
            check(bool(killed), "a worker node was killed during the study")
            check(survived.report == reference.report, "the map with a worker node killed equals the one-process map")
            deadline = time.monotonic() + 120.0  # the head notices a dead node by its missed heartbeats
            while True:
                alive = [n for n in ray.nodes() if n["Alive"] and n["Resources"].get("CPU")]
                if len(alive) == 1 or time.monotonic() > deadline:
                    break
                time.sleep(1.0)
            check(len(alive) == 1, f"the head sees one worker node left ({len(alive)})")
            cluster.add_worker(ray)
            killed.clear()

            def kill_in_search(done: int, total: int) -> None:
                if not killed and done >= total // 4:
                    cluster.kill(cluster.workers[1])
                    killed.append(True)

            survived_search = studies.optimize(SCENE, executor="ray", progress=kill_in_search, **OPTIMIZE)
            check(bool(killed), "a worker node was killed during the search")
            check(survived_search.report == best.report, "optimize with a worker node killed equals the one-process search")

            if args.timings:
                t0 = time.perf_counter()
                studies.stability_map(SCENE, X, Y, executor="ray", progress=False)
                ray1_s = time.perf_counter() - t0
                with open(args.timings, "w") as f:
                    json.dump({"cells": total, "one_process_2_threads_s": local_s, "ray_2_workers_s": ray2_s,
                               "ray_1_worker_s": ray1_s}, f, indent=1)
        return 0
    except AssertionError as e:
        print(f"FAILED: {e}\n{cluster.tail()}", file=sys.stderr, flush=True)
        return 1
    finally:
        try:
            ray.shutdown()
        finally:
            cluster.stop()


if __name__ == "__main__":
    sys.exit(main())
