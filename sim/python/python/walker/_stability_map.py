"""The stability of a scene's gait over a grid of two parameters: :class:`StabilityMap`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd


def _grid(rows: list[list[Any]]) -> np.ndarray:
    return np.array([[np.nan if v is None else v for v in row] for row in rows], dtype=float)


@dataclass(frozen=True)
class StabilityMap:
    """The gait at every cell of a grid (``walker stability-map --json``). Grids are indexed
    ``[j, i]``: row ``j`` at ``y[j]``, column ``i`` at ``x[i]``; NaN where there is no gait."""

    report: dict[str, Any] = field(repr=False)
    """The ``walker stability-map --json`` object."""
    x_name: str
    """The parameter along the columns."""
    x: np.ndarray = field(repr=False)
    """Its values."""
    y_name: str
    """The parameter along the rows."""
    y: np.ndarray = field(repr=False)
    """Its values."""
    max_abs_eigenvalue: np.ndarray = field(repr=False)
    """Largest |eigenvalue| of each cell's gait (NaN: no gait)."""
    step_period_s: np.ndarray = field(repr=False)
    """Step period of each cell's gait [s] (NaN: no gait)."""

    @classmethod
    def from_report(cls, report: dict[str, Any]) -> StabilityMap:
        """The map of a ``walker stability-map --json`` object."""
        return cls(
            report,
            report["x"]["name"],
            np.array(report["x"]["values"], dtype=float),
            report["y"]["name"],
            np.array(report["y"]["values"], dtype=float),
            _grid(report["max_abs_eigenvalue"]),
            _grid(report["step_period_s"]),
        )

    @property
    def quantity_name(self) -> str | None:
        """The other quantity mapped (``quantity=``), or ``None``."""
        q = self.report.get("quantity")
        return None if q is None else q["name"]

    @property
    def quantity(self) -> np.ndarray | None:
        """The other quantity of each cell's gait (``quantity=``; NaN: no gait, or it could not
        be had: ``quantity_errors`` says why), or ``None``."""
        q = self.report.get("quantity")
        return None if q is None else _grid(q["values"])

    @property
    def quantity_errors(self) -> np.ndarray | None:
        """Why the quantity could not be had at a cell with a gait (``None`` elsewhere)."""
        q = self.report.get("quantity")
        return None if q is None else np.array(q["errors"], dtype=object)

    @property
    def stable(self) -> np.ndarray:
        """Whether each cell's gait is stable (``False`` also where there is no gait)."""
        return np.array([[v is True for v in row] for row in self.report["stable"]])

    def to_frame(self) -> pd.DataFrame:
        """One row per cell: the two parameters, ``max_abs_eigenvalue``, ``stable``,
        ``step_period_s``, ``gait_source``, ``no_gait_reason`` and the other quantity, if
        mapped, under its name."""
        r = self.report
        rows = [
            {
                self.x_name: x,
                self.y_name: y,
                "max_abs_eigenvalue": r["max_abs_eigenvalue"][j][i],
                "stable": r["stable"][j][i],
                "step_period_s": r["step_period_s"][j][i],
                "gait_source": r["gait_source"][j][i],
                "no_gait_reason": r["no_gait_reason"][j][i],
            }
            for j, y in enumerate(self.y)
            for i, x in enumerate(self.x)
        ]
        q = r.get("quantity")
        if q is not None:
            for row, value in zip(rows, (v for line in q["values"] for v in line)):
                row[q["name"]] = value
        return pd.DataFrame(rows)
