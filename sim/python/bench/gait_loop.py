"""Benchmark (not a test): a loop of N gaits from Python against the same work in Rust.

Runs ``walker.gait(scene)`` N times, then the Rust example ``gait_loop`` (the same library
calls, report and JSON form, in one process), and prints both times and their ratio. The
issue's aim: Python under twice Rust's time.

    .venv/bin/python sim/python/bench/gait_loop.py [SCENE] [N]
"""

from __future__ import annotations

import json
import pathlib
import subprocess
import sys
import time

import walker

ROOT = pathlib.Path(__file__).resolve().parents[3]


def main() -> None:
    scene_name = sys.argv[1] if len(sys.argv) > 1 else "compass"
    loops = int(sys.argv[2]) if len(sys.argv) > 2 else 100
    scene = walker.Scene.load(scene_name)
    walker.gait(scene)  # warm up
    started = time.perf_counter()
    for _ in range(loops):
        g = walker.gait(scene)
    python_s = time.perf_counter() - started
    out = subprocess.run(
        ["cargo", "run", "--release", "-q", "-p", "sim", "--example", "gait_loop", "--", scene_name, str(loops)],
        cwd=ROOT, capture_output=True, text=True, check=True,
    )
    rust = json.loads(out.stdout)
    assert rust["max_abs_eigenvalue"] == g.max_abs_eigenvalue
    print(
        json.dumps(
            {
                "scene": scene_name,
                "loops": loops,
                "python_s": python_s,
                "rust_s": rust["total_s"],
                "python_over_rust": python_s / rust["total_s"],
            }
        )
    )


if __name__ == "__main__":
    main()
