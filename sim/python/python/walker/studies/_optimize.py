"""Design optimisation as a study: each generation's candidates as tasks, every evaluation in
a study file the search resumes from."""

from __future__ import annotations

import contextlib
import os
import struct
from typing import Any, Mapping, Sequence

from .. import _walker
from .._optimize import Optimize
from .._progress import ProgressArg
from . import _executor
from ._stability_map import _versions, scene_spec
from ._study_file import FORMAT, StudyFile, saved_on_exit


def optimize_block(scene: Any, ranges: list[str], objective: str, texts: list[str], budget: int, seed: int,
                   initial_step: float, sigma_m: float | None, drawn: list[list[float]],
                   cancelled: Any = None) -> list[bytes]:
    """One task: the evaluations of ``drawn`` (the extension's ``optimize_evaluate``);
    ``cancelled()``, in this process only, stops it."""

    def stop_when_cancelled(done: int, total: int) -> None:
        if cancelled is not None and cancelled():
            raise KeyboardInterrupt

    return _walker.optimize_evaluate(scene, ranges, objective, drawn, constraints=texts, budget=budget, seed=seed,
                                     initial_step=initial_step, sigma_m=sigma_m, progress=stop_when_cancelled)


def _key(design: Sequence[float]) -> bytes:
    """A design's coordinates bit for bit (``-0.0`` is not ``0.0`` here, unlike ``==``)."""
    return struct.pack(f"<{len(design)}d", *design)


def optimize(
    scene: Any,
    vary: Mapping[str, tuple[float, float]] | Sequence[str],
    objective: str,
    *,
    constraints: Sequence[str | tuple[str, str, float]] = (),
    budget: int = 200,
    seed: int = 0,
    initial_step: float = _walker.DEFAULT_INITIAL_STEP,
    sigma_m: float | None = None,
    executor: str = "local",
    address: str | None = None,
    runtime_env: dict[str, Any] | None = None,
    study_file: str | os.PathLike[str] | None = None,
    progress: ProgressArg = True,
) -> Optimize:
    """:func:`walker.optimize` as a study: the same search, bit for bit (CMA-ES's draws depend
    only on the seed and the ranks of the earlier generations, and an evaluation only on its
    design), each generation's candidates evaluated as tasks on ``executor`` (``"local"``:
    this process's threads; ``"ray"``: one task per candidate on the Ray cluster at
    ``address``, with ``runtime_env``), every evaluation written to ``study_file`` (Parquet)
    as it arrives. Started again with the same file, the search evaluates only the designs the
    file lacks; a file of another study is refused, naming the differences. Arguments and
    errors as :func:`walker.optimize`, and :class:`walker.InputError` for an unknown executor
    or another study's file."""
    from .. import _optimize, _scene

    _executor.check(executor, address, runtime_env)
    if executor == "local" and study_file is None:
        return _optimize(scene, vary, objective, constraints, budget, seed, initial_step, sigma_m, progress, None)
    s = _scene(scene)

    def evaluate(s: Any, ranges: list[str], texts: list[str]):
        spec = {
            "format": FORMAT,
            "study": "optimize",
            "walker": _versions(executor)["walker"],
            "scene": scene_spec(s),
            "vary": ranges,
            "objective": objective,
            "constraints": texts,
            "budget": budget,
            "seed": seed,
            "initial_step": float(initial_step),
            "sigma_m": None if sigma_m is None else float(sigma_m),
        }
        file = StudyFile(study_file, spec, _versions(executor), ("n",)) if study_file is not None else None
        known: dict[bytes, bytes] = {}
        if file is not None:
            file.load()
            import pyarrow as pa

            file.with_schema([("n", pa.int64()), ("design", pa.list_(pa.float64())),
                              ("evaluation", pa.binary())])
            known = {_key(r["design"]): r["evaluation"] for r in file.rows.values()}
        args = (ranges, objective, texts, budget, seed, float(initial_step),
                None if sigma_m is None else float(sigma_m))

        def batch(drawn: list[list[float]], cancelled) -> list[bytes]:
            missing = [u for u in drawn if _key(u) not in known]
            if missing:
                if executor == "ray":
                    _executor.worker_cpus(executor, address, runtime_env)
                    chunks = [[u] for u in missing]
                    tasks = [(*args, chunk) for chunk in chunks]
                else:
                    chunks = [missing]
                    tasks = [(*args, missing, cancelled)]
                results = _executor.run(executor, optimize_block, s, tasks, cancelled=cancelled)
                with saved_on_exit(file), contextlib.closing(results):
                    for k, found in results:
                        designs = chunks[k]
                        for u, b in zip(designs, found):
                            known[_key(u)] = b
                        if file is not None:
                            first = len(file.rows)
                            file.add({"n": first + m, "design": u, "evaluation": b}
                                     for m, (u, b) in enumerate(zip(designs, found)))
            return [known[_key(u)] for u in drawn]

        return batch

    return _optimize(s, vary, objective, constraints, budget, seed, initial_step, sigma_m, progress, evaluate)
