"""``python -m walker.studies``: a study from a shell, on this machine or a Ray cluster, written
to a study file it resumes from.

    python -m walker.studies stability-map --scene compass \\
        --x slope=0.01:0.08:100 --y leg_mass_kg=1:10:100 \\
        --executor ray --address 10.0.0.1:6379 --study-file compass-map.parquet

    python -m walker.studies optimize --scene compass --vary slope_rad=0.02:0.07 \\
        --objective step_down --budget 200 --executor ray --study-file search.parquet

Axes as ``walker stability-map`` takes them (``NAME=FROM:TO:POINTS``) or as a list
(``NAME=V1,V2,...``); ``--vary`` and ``--constraint`` as ``walker optimize`` takes them. Exit
codes: 0 done, 1 an error while computing (or, for ``optimize``, no feasible design), 2 bad
input, 130 interrupted (the file keeps every cell or evaluation finished).
"""

from __future__ import annotations

import argparse
import json
import sys

import walker

from ._optimize import optimize
from ._stability_map import stability_map

MAX_AXIS_POINTS = 40_000
"""Most values one axis may have (the map's own limit is on cells)."""


def axis(text: str) -> tuple[str, list[float]]:
    """``NAME=FROM:TO:POINTS`` (evenly spaced, both ends included) or ``NAME=V1,V2,...``."""
    name, sep, values = text.partition("=")
    if not sep or not name:
        raise argparse.ArgumentTypeError(f"`{text}`: give NAME=FROM:TO:POINTS or NAME=V1,V2,...")
    try:
        if ":" in values:
            a, b, n = values.split(":")
            lo, hi, points = float(a), float(b), int(n)
            if not 1 <= points <= MAX_AXIS_POINTS:
                raise ValueError(f"POINTS must be 1 to {MAX_AXIS_POINTS}")
            if points == 1:
                return name, [lo]
            return name, [lo + (hi - lo) * k / (points - 1) for k in range(points)]
        return name, [float(v) for v in values.split(",")]
    except ValueError as e:
        raise argparse.ArgumentTypeError(f"`{text}`: {e}") from None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m walker.studies", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="study", required=True)
    m = sub.add_parser("stability-map", help="the gait's largest |eigenvalue| over a grid of two parameters")
    m.add_argument("--scene", required=True, help="a built-in scene's name or a scene file")
    m.add_argument("--x", required=True, type=axis, help="NAME=FROM:TO:POINTS or NAME=V1,V2,...")
    m.add_argument("--y", required=True, type=axis, help="NAME=FROM:TO:POINTS or NAME=V1,V2,...")
    m.add_argument("--quantity", help="also map this number of each cell's gait (as walker stability-map)")
    m.add_argument("--sigma-m", type=float, help="the rough floor's standard deviation for --quantity mfpt [m]")
    m.add_argument("--executor", choices=("local", "ray"), default="local")
    m.add_argument("--address", help="the Ray cluster's address (default: RAY_ADDRESS, or a new local one)")
    m.add_argument("--study-file", required=True, help="the Parquet file the cells are written to and resumed from")
    m.add_argument("--cells-per-task", type=int, help="cells of one task (default: see walker.studies)")
    m.add_argument("--no-progress", action="store_true", help="no progress bar")
    m.add_argument("--json", action="store_true", help="print the map as walker stability-map --json does")
    o = sub.add_parser("optimize", help="CMA-ES over a scene's parameters for an objective of its gait")
    o.add_argument("--scene", required=True, help="a built-in scene's name or a scene file")
    o.add_argument("--vary", required=True, action="append", metavar="NAME=MIN:MAX",
                   help="a parameter and its range (repeat for several)")
    o.add_argument("--objective", required=True, help="gsn, max_abs_eigenvalue, cost_of_transport, step_down or mfpt")
    o.add_argument("--constraint", action="append", default=[], metavar="NAME<=V",
                   help="a constraint on a quantity of the gait (repeatable)")
    o.add_argument("--budget", type=int, default=200, help="candidates evaluated")
    o.add_argument("--seed", type=int, default=0, help="seed of CMA-ES's draws")
    o.add_argument("--initial-step", type=float, default=walker.DEFAULT_INITIAL_STEP,
                   help="CMA-ES's first step size, normalised")
    o.add_argument("--sigma-m", type=float, help="the rough floor's standard deviation for mfpt [m]")
    o.add_argument("--executor", choices=("local", "ray"), default="local")
    o.add_argument("--address", help="the Ray cluster's address (default: RAY_ADDRESS, or a new local one)")
    o.add_argument("--study-file", required=True, help="the Parquet file the evaluations are written to and resumed from")
    o.add_argument("--no-progress", action="store_true", help="no progress bar")
    o.add_argument("--json", action="store_true", help="print the result as walker optimize --json does")
    args = parser.parse_args(argv)
    try:
        if args.study == "optimize":
            found = optimize(
                walker.Scene.load(args.scene), args.vary, args.objective, constraints=args.constraint,
                budget=args.budget, seed=args.seed, initial_step=args.initial_step, sigma_m=args.sigma_m,
                executor=args.executor, address=args.address, study_file=args.study_file,
                progress=not args.no_progress,
            )
            if args.json:
                print(json.dumps(found.report, indent=2, sort_keys=True))
            else:
                best = found.report.get("best")
                where = "no feasible design" if best is None else f"best {args.objective} {best['value']} at {best['parameters']}"
                print(f"{found.report['scene']} optimize, {len(found.report['evaluations'])} candidates: {where}; "
                      f"in {args.study_file}")
            return 0 if found.report.get("best") is not None else 1
        result = stability_map(
            walker.Scene.load(args.scene), args.x, args.y, quantity=args.quantity, sigma_m=args.sigma_m,
            executor=args.executor, address=args.address, study_file=args.study_file,
            cells_per_task=args.cells_per_task, progress=not args.no_progress,
        )
    except (walker.InputError, walker.SceneError) as e:
        print(f"python -m walker.studies: {e}", file=sys.stderr)
        return 2
    except walker.WalkerError as e:
        print(f"python -m walker.studies: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        what = "evaluation" if args.study == "optimize" else "cell"
        print(f"python -m walker.studies: interrupted; {args.study_file} keeps every {what} written to it: run "
              "the same command again to go on", file=sys.stderr)
        return 130
    if args.json:
        print(json.dumps(result.report, indent=2, sort_keys=True))
    else:
        eig = result.max_abs_eigenvalue
        cells = eig.size
        found = int((eig == eig).sum())
        stable = int(result.stable.sum())
        print(f"{result.report['scene']} stability map, {args.x[0]} × {args.y[0]}: {cells} of {cells} cells, "
              f"{found} with a gait, {stable} stable; in {args.study_file}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
