"""The stability map as a study: blocks of cells as tasks, results in a study file."""

from __future__ import annotations

import contextlib
import hashlib
import math
import os
import platform
from typing import Any, Sequence

from .. import _walker
from .._errors import InputError
from .._progress import ProgressArg, callback as _progress_callback
from .._stability_map import StabilityMap
from . import _executor
from ._study_file import FORMAT, StudyFile, saved_on_exit

GRIDS = ("max_abs_eigenvalue", "stable", "step_period_s", "gait_source", "no_gait_reason")
"""The report's grids, one entry per cell (``walker stability-map --json``)."""

TASKS_PER_CPU = 4
"""Tasks a study is split into per worker CPU (at least), so that every worker stays busy to
the end although cells differ in cost (a cell without a gait costs several with one)."""

LOCAL_BLOCK_CELLS = 64
"""Cells of one task of the local executor with a study file (whole rows, at least this many):
the results reach the file every few seconds."""


def map_block(scene: Any, x_name: str, xs: list[float], y_name: str, ys: list[float],
              quantity: str | None, sigma_m: float | None) -> dict[str, Any]:
    """One task: the map of ``xs`` × ``ys`` (the extension's, as ``walker stability-map
    --json`` reports it, on every thread the process allows)."""
    return _walker.stability_map(scene, (x_name, xs), (y_name, ys), quantity=quantity, sigma_m=sigma_m)


def _blocks(missing: list[tuple[int, int]], nx: int, cells_per_task: int) -> list[tuple[list[int], list[int]]]:
    """The missing cells ``(i, j)`` as rectangular blocks ``(columns, rows)``: runs of at most
    ``cells_per_task`` consecutive columns of one row, or (``cells_per_task`` ≥ ``nx``) whole
    missing rows grouped up to ``cells_per_task`` cells."""
    by_row: dict[int, list[int]] = {}
    for i, j in missing:
        by_row.setdefault(j, []).append(i)
    blocks: list[tuple[list[int], list[int]]] = []
    full_rows: list[int] = []
    for j in sorted(by_row):
        cols = sorted(by_row[j])
        if len(cols) == nx and cells_per_task >= nx:
            full_rows.append(j)
            if len(full_rows) * nx >= cells_per_task:
                blocks.append((list(range(nx)), full_rows))
                full_rows = []
            continue
        run: list[int] = []
        for i in cols:
            if run and (i != run[-1] + 1 or len(run) >= cells_per_task):
                blocks.append((run, [j]))
                run = []
            run.append(i)
        if run:
            blocks.append((run, [j]))
    if full_rows:
        blocks.append((list(range(nx)), full_rows))
    return blocks


def _resolve(scene: Any, name: str) -> str:
    """The parameter's own name for ``name`` (itself or an alias); unknown names are left to
    the extension's error."""
    params = scene.parameters
    if name in params.index:
        return name
    for own, aliases in params["aliases"].items():
        if name in aliases:
            return own
    return name


def _check_axes(scene: Any, x_name: str, xs: list[float], y_name: str, ys: list[float]) -> None:
    """:func:`walker.stability_map`'s refusals, before a cluster is contacted or a file
    written: the same parameter twice, no cells or too many, a value the scene refuses."""
    if x_name == y_name:
        raise InputError(f"x and y both vary `{x_name}`: give two different parameters")
    cells = len(xs) * len(ys)
    if not 1 <= cells <= _walker.MAX_MAP_CELLS:
        raise InputError(f"the map must have between 1 and {_walker.MAX_MAP_CELLS} cells, got {cells}")
    for name, values in ((x_name, xs), (y_name, ys)):
        for v in values:
            scene.with_params(**{name: v})


def scene_spec(scene: Any) -> dict[str, Any]:
    """What a study file records of its scene: the name, the expression that builds it (with
    its solver options), every parameter value and the scene file's text by its SHA-256 (a
    changed file is another study)."""
    return {"name": scene.name, "repr": repr(scene), "values": dict(scene.values),
            "file_sha256": hashlib.sha256(scene.file_text.encode()).hexdigest()}


def _versions(executor: str) -> dict[str, str]:
    from importlib import metadata

    versions = {"python": platform.python_version()}
    for package in ("walker", "pyarrow") + (("ray",) if executor == "ray" else ()):
        try:
            versions[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            versions[package] = "unknown"
    return versions


def stability_map(
    scene: Any,
    x: tuple[str, Sequence[float]],
    y: tuple[str, Sequence[float]],
    *,
    quantity: str | None = None,
    sigma_m: float | None = None,
    executor: str = "local",
    address: str | None = None,
    runtime_env: dict[str, Any] | None = None,
    study_file: str | os.PathLike[str] | None = None,
    cells_per_task: int | None = None,
    progress: ProgressArg = True,
) -> StabilityMap:
    """:func:`walker.stability_map` as a study: the same map, bit for bit, computed as tasks of
    blocks of cells on ``executor`` (``"local"``: this process; ``"ray"``: the Ray cluster at
    ``address``, ``None`` for the one ``RAY_ADDRESS`` names or a new local one, with
    ``runtime_env`` as :func:`ray.init` takes it), written to ``study_file`` (Parquet) as they
    arrive. Started again with the same file, only the cells it lacks are computed; a file of
    another study is refused, naming the differences. ``cells_per_task``: the cells of one task
    (default: at least :data:`TASKS_PER_CPU` tasks per worker CPU on Ray, whole rows of at
    least :data:`LOCAL_BLOCK_CELLS` cells locally). ``progress``: a bar of the cells done
    (``True``), none (``False``) or ``progress(done, total)``.

    Raises what :func:`walker.stability_map` raises, and :class:`InputError` for an unknown
    executor, a study file of another study or one that cannot be read."""
    from .. import _axes, _scene

    _executor.check(executor, address, runtime_env)
    s = _scene(scene)
    (x_name, xs), (y_name, ys) = _axes(x, y)
    x_name, y_name = _resolve(s, x_name), _resolve(s, y_name)
    nx, ny = len(xs), len(ys)
    if cells_per_task is not None and (isinstance(cells_per_task, bool) or not isinstance(cells_per_task, int)
                                       or cells_per_task < 1):
        raise InputError(f"cells_per_task must be a positive integer, got {cells_per_task!r}")
    if study_file is None and executor == "local":
        # no file to write to and no cluster: the whole map is one task
        from .. import stability_map as whole

        return whole(s, (x_name, xs), (y_name, ys), quantity=quantity, sigma_m=sigma_m, progress=progress)
    _check_axes(s, x_name, xs, y_name, ys)
    _walker.check_quantity(quantity, sigma_m)
    spec = {
        "format": FORMAT,
        "study": "stability_map",
        "walker": _versions(executor)["walker"],
        "scene": scene_spec(s),
        "x": {"name": x_name, "values": xs},
        "y": {"name": y_name, "values": ys},
        "quantity": quantity,
        "sigma_m": sigma_m,
    }
    file = StudyFile(study_file, spec, _versions(executor), ("i", "j")) if study_file is not None else None
    if file is not None:
        file.load()
    done = set(file.rows) if file is not None else set()
    missing = [(i, j) for j in range(ny) for i in range(nx) if (i, j) not in done]
    cpus = _executor.worker_cpus(executor, address, runtime_env) if missing else 1
    if cells_per_task is None:
        if executor == "ray":
            cells_per_task = max(1, min(nx, math.ceil(len(missing) / (TASKS_PER_CPU * cpus))))
        else:
            cells_per_task = max(nx, LOCAL_BLOCK_CELLS)
    blocks = _blocks(missing, nx, cells_per_task)
    rows: dict[tuple[int, int], dict[str, Any]] = dict(file.rows) if file is not None else {}
    extra: dict[str, Any] = dict(file.extra) if file is not None else {}
    if file is not None:
        file.with_schema(_schema(quantity is not None))
    f, bar = _progress_callback(progress, "stability map", "cell")
    total, count = nx * ny, len(done)
    try:
        with saved_on_exit(file):
            if f is not None:
                f(count, total)
            args = [(x_name, [xs[i] for i in cols], y_name, [ys[j] for j in js], quantity, sigma_m)
                    for cols, js in blocks]
            with contextlib.closing(_executor.run(executor, map_block, s, args)) as results:
                for k, report in results:
                    cols, js = blocks[k]
                    new = _cells(report, cols, js, xs, ys)
                    rows.update({(r["i"], r["j"]): r for r in new})
                    if quantity is not None and "quantity" not in extra:
                        q = report["quantity"]
                        extra["quantity"] = {k2: v for k2, v in q.items() if k2 not in ("values", "errors")}
                    if "scene" not in extra:
                        extra["scene"] = report["scene"]
                    if file is not None:
                        for key, value in extra.items():
                            file.set_extra(key, value)
                        file.add(new)
                    count += len(new)
                    if f is not None:
                        f(count, total)
    finally:
        if bar is not None:
            bar.close()
    return StabilityMap.from_report(_report(rows, extra, x_name, xs, y_name, ys, quantity))


def _schema(with_quantity: bool) -> list[tuple[str, Any]]:
    import pyarrow as pa

    fields = [
        ("i", pa.int32()), ("j", pa.int32()), ("x", pa.float64()), ("y", pa.float64()),
        ("max_abs_eigenvalue", pa.float64()), ("stable", pa.bool_()), ("step_period_s", pa.float64()),
        ("gait_source", pa.string()), ("no_gait_reason", pa.string()),
    ]
    if with_quantity:
        fields += [("quantity", pa.float64()), ("quantity_error", pa.string())]
    return fields


def _cells(report: dict[str, Any], cols: list[int], js: list[int], xs: list[float], ys: list[float]
           ) -> list[dict[str, Any]]:
    """The cells of one block's report, as rows of the study file."""
    out = []
    q = report.get("quantity")
    for b, j in enumerate(js):
        for a, i in enumerate(cols):
            row: dict[str, Any] = {"i": i, "j": j, "x": xs[i], "y": ys[j]}
            for g in GRIDS:
                row[g] = report[g][b][a]
            if q is not None:
                row["quantity"] = q["values"][b][a]
                row["quantity_error"] = q["errors"][b][a]
            out.append(row)
    return out


def _report(rows: dict[tuple[int, int], dict[str, Any]], extra: dict[str, Any], x_name: str,
            xs: list[float], y_name: str, ys: list[float], quantity: str | None) -> dict[str, Any]:
    """The ``walker stability-map --json`` object of the whole map from its cells."""
    nx, ny = len(xs), len(ys)
    report: dict[str, Any] = {g: [[rows[(i, j)][g] for i in range(nx)] for j in range(ny)] for g in GRIDS}
    report["scene"] = extra["scene"]
    report["x"] = {"name": x_name, "values": list(xs)}
    report["y"] = {"name": y_name, "values": list(ys)}
    if quantity is not None:
        q = dict(extra["quantity"])
        q["values"] = [[rows[(i, j)]["quantity"] for i in range(nx)] for j in range(ny)]
        q["errors"] = [[rows[(i, j)]["quantity_error"] for i in range(nx)] for j in range(ny)]
        report["quantity"] = q
    return report
