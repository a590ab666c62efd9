"""Throughput of ``walker.studies.stability_map`` on a Ray test cluster against one process
(docs/cluster.md): the compass map of the issue on one process (rayon, every core), on one
and on two worker processes (one CPU each), and Ray's cost per task (tiny tasks against row
tasks). Run by ``scripts/bench-cluster`` inside a network namespace of its own; prints a
Markdown table and writes JSON to ``--out``."""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import ray  # noqa: E402
import walker  # noqa: E402
import walker.studies as studies  # noqa: E402
from ray_cluster import Cluster  # noqa: E402


def axis(name: str, lo: float, hi: float, n: int) -> tuple[str, list[float]]:
    return name, [lo + (hi - lo) * k / (n - 1) for k in range(n)]


def timed(f) -> tuple[float, object]:
    t0 = time.perf_counter()
    out = f()
    return time.perf_counter() - t0, out


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--points", type=int, default=100, help="points per axis of the compass map")
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    scene = walker.Scene.load("compass")
    x, y = axis("slope", 0.01, 0.08, args.points), axis("leg_mass_kg", 1.0, 10.0, args.points)
    cells = args.points**2
    small_x, small_y = axis("slope", 0.01, 0.08, 20), axis("leg_mass_kg", 1.0, 10.0, 20)
    search = dict(vary={"slope_rad": (0.02, 0.07), "leg_mass_kg": (2.0, 8.0)}, objective="step_down",
                  budget=120, seed=3, progress=False)
    rows: dict[str, float] = {}
    searches: dict[str, float] = {}
    cluster = Cluster(workers=2)
    try:
        cluster.connect(ray)
        local_s, reference = timed(lambda: walker.stability_map(scene, x, y, progress=False))
        rows["one process, rayon on 2 threads"] = local_s
        # warm the workers (their first task imports walker) before timing
        studies.stability_map(scene, small_x, small_y, executor="ray", progress=False)
        two_s, on_two = timed(lambda: studies.stability_map(scene, x, y, executor="ray", progress=False))
        assert on_two.report == reference.report
        rows["Ray, 2 worker processes, one row a task"] = two_s
        searches["one process, rayon on 2 threads"], best = timed(lambda: walker.optimize(scene, **search))
        searches["Ray, 2 worker processes, one candidate a task"], found = timed(
            lambda: studies.optimize(scene, executor="ray", **search))
        assert found.report == best.report
        rows_s, _ = timed(lambda: studies.stability_map(scene, small_x, small_y, executor="ray", progress=False,
                                                        cells_per_task=20))
        single_s, _ = timed(lambda: studies.stability_map(scene, small_x, small_y, executor="ray", progress=False,
                                                          cells_per_task=1))
        per_task_ms = (single_s - rows_s) / (400 - 20) * 1e3 * 2  # two workers run tasks side by side
        cluster.kill(cluster.workers[0])
        deadline = time.monotonic() + 120
        while sum(1 for n in ray.nodes() if n["Alive"] and n["Resources"].get("CPU")) > 1:
            if time.monotonic() > deadline:
                raise RuntimeError("the killed worker node is still alive")
            time.sleep(1)
        one_s, on_one = timed(lambda: studies.stability_map(scene, x, y, executor="ray", progress=False))
        assert on_one.report == reference.report
        rows["Ray, 1 worker process, one row a task"] = one_s
        searches["Ray, 1 worker process, one candidate a task"], found = timed(
            lambda: studies.optimize(scene, executor="ray", **search))
        assert found.report == best.report
    finally:
        ray.shutdown()
        cluster.stop()
    machine = f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs"
    try:
        with open("/proc/cpuinfo") as f:
            machine = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name")) + \
                f", {os.cpu_count()} CPUs"
    except (OSError, StopIteration):
        pass
    import pickle

    from walker import _walker
    from walker.studies._stability_map import map_block

    row_bytes = len(pickle.dumps(map_block(scene, x[0], x[1], y[0], y[1][:1], None, None)))
    ranges = ["slope_rad=0.02:0.07", "leg_mass_kg=2.0:8.0"]
    evaluation_bytes = len(_walker.optimize_evaluate(scene, ranges, "step_down", [[0.5, 0.5]], budget=120, seed=3)[0])
    result = {"machine": machine, "cells": cells, "seconds": rows, "ray_cost_per_task_ms": per_task_ms,
              "optimize_seconds": searches, "optimize_evaluations": search["budget"] + 1,
              "bytes_returned": {"map_row": row_bytes, "evaluation": evaluation_bytes},
              "versions": {"ray": ray.__version__, "python": platform.python_version()}}
    with open(args.out, "w") as f:
        json.dump(result, f, indent=1)
    print(f"compass stability map, {args.points} × {args.points} = {cells} cells, on {machine}\n")
    print("| run | wall [s] | cells/s |\n| --- | --- | --- |")
    for name, s in rows.items():
        print(f"| {name} | {s:.2f} | {cells / s:.0f} |")
    print(f"\noptimize, step_down, {search['budget']} candidates\n")
    print("| run | wall [s] | candidates/s |\n| --- | --- | --- |")
    for name, sec in searches.items():
        print(f"| {name} | {sec:.2f} | {search['budget'] / sec:.1f} |")
    print(f"\nbytes returned: a map row of {args.points} cells {row_bytes}, an evaluation {evaluation_bytes}")
    print(f"\nRay's cost per task (400 one-cell tasks against 20 one-row tasks, 2 workers): {per_task_ms:.2f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
