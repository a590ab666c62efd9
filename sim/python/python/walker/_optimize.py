"""Design optimisation by CMA-ES: :class:`Optimize` and its :class:`Best` design."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from ._gait import Gait


@dataclass(frozen=True)
class Best:
    """The best feasible design of a search."""

    index: int
    """Its row in :attr:`Optimize.evaluations`."""
    parameters: dict[str, float]
    """Its values of the varied parameters (``scene.with_params(**parameters)`` is it)."""
    value: float
    """The objective's value there."""
    gait: Gait = field(repr=False)
    """Its gait, as :func:`walker.gait` finds it at these values."""


def _evaluation_rows(evaluations: list[dict[str, Any]], names: list[str]) -> pd.DataFrame:
    rows = []
    for e in evaluations:
        row: dict[str, Any] = {"index": e.get("index"), "generation": e.get("generation")}
        row.update({n: e["parameters"].get(n) for n in names})
        row.update(
            value=e["value"],
            feasible=e["feasible"],
            reason=e["reason"],
            detail=e.get("detail"),
            fitness=e["fitness"],
            outside_bounds=e["outside_bounds"],
            max_abs_eigenvalue=e["max_abs_eigenvalue"],
            gait_source=e["gait_source"],
        )
        for q, v in e["constrained"].items():
            row.setdefault(q, v)
        rows.append(row)
    frame = pd.DataFrame(rows)
    for column in ["value", "max_abs_eigenvalue", "fitness", "outside_bounds", *names]:
        if column in frame:
            frame[column] = frame[column].astype(float)
    return frame


@dataclass(frozen=True)
class Optimize:
    """A CMA-ES search over a scene's parameters (``walker optimize --json``;
    :func:`walker.optimize`)."""

    report: dict[str, Any] = field(repr=False)
    """The ``walker optimize --json`` object."""
    objective: str
    """The objective's name."""
    sense: str
    """``minimise`` or ``maximise``."""
    best: Best | None
    """The best feasible design (``None``: none was feasible)."""
    default: dict[str, Any] = field(repr=False)
    """The scene's own design's evaluation (outside the budget): ``parameters``, ``value``,
    ``feasible``, ``reason``, ``detail``, ``max_abs_eigenvalue``, ``gait_source``..."""
    history: np.ndarray = field(repr=False)
    """The best feasible value after each generation (NaN before the first feasible one)."""

    @classmethod
    def from_report(cls, report: dict[str, Any]) -> Optimize:
        """The search of a ``walker optimize --json`` object."""
        b = report["best"]
        best = None if b is None else Best(b["index"], dict(b["parameters"]), b["value"], Gait.from_report(b["gait"]))
        history = np.array([np.nan if v is None else v for v in report["history"]], dtype=float)
        return cls(report, report["objective"], report["sense"], best, report["default"], history)

    @property
    def parameters(self) -> pd.DataFrame:
        """The varied parameters indexed by name: ``min``, ``max``."""
        return pd.DataFrame(self.report["parameters"], columns=["name", "min", "max"]).set_index("name")

    @property
    def evaluations(self) -> pd.DataFrame:
        """One row per evaluation, in the search's order (generation by generation, in each
        as CMA-ES ranked them): ``index``, ``generation``, each varied parameter's value,
        ``value`` (the objective; NaN where not computed), ``feasible``, ``reason`` and
        ``detail`` (why not), ``fitness`` (what CMA-ES ranked), ``outside_bounds``,
        ``max_abs_eigenvalue``, ``gait_source``, and each constrained quantity's value."""
        names = [p["name"] for p in self.report["parameters"]]
        return _evaluation_rows(self.report["evaluations"], names)

    @property
    def generations(self) -> pd.DataFrame:
        """One row per generation: ``generation``, ``run``, ``population``, ``best_value``,
        ``best_so_far`` (NaN: none feasible yet), ``feasible``, ``evaluations`` (so far),
        ``sigma`` (the step size it was drawn with)."""
        frame = pd.DataFrame(self.report["generations"])
        for column in ["best_value", "best_so_far"]:
            if column in frame:
                frame[column] = frame[column].astype(float)
        return frame

    @property
    def runs(self) -> int:
        """Runs of CMA-ES (1 + restarts, the last short generation counted as a run)."""
        return int(self.report["runs"])
