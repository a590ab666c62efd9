"""A slice of a gait's basin of attraction: :class:`Basin`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from ._gait import Gait


@dataclass(frozen=True)
class Basin:
    """The basin slice (``walker basin --json``): each cell a start state, the gait's fixed
    point with two stride-map coordinates set to ``x[i]``, ``y[j]``. Grids are indexed
    ``[j, i]``."""

    report: dict[str, Any] = field(repr=False)
    """The ``walker basin --json`` object."""
    x_name: str
    """The stride-map coordinate along the columns."""
    x: np.ndarray = field(repr=False)
    """Its values."""
    y_name: str
    """The stride-map coordinate along the rows."""
    y: np.ndarray = field(repr=False)
    """Its values."""
    outcome: np.ndarray = field(repr=False)
    """Each cell's outcome (str): ``gait``, ``periodic``, ``fell_forward``, ``fell_backward``,
    another failure's kind, ``not_settled``, ``off_section`` (the swing foot cannot reach the
    floor)."""
    strides: np.ndarray = field(repr=False)
    """Strides each cell took (to return, settle or fail)."""
    period: np.ndarray = field(repr=False)
    """The period of a ``periodic`` cell (NaN elsewhere)."""
    fraction_returning: float
    """Cells back on the gait over all cells."""
    gait: Gait = field(repr=False)
    """The gait (as :func:`walker.gait` finds it)."""

    @classmethod
    def from_report(cls, report: dict[str, Any]) -> Basin:
        """The slice of a ``walker basin --json`` object."""
        return cls(
            report,
            report["x"]["name"],
            np.array(report["x"]["values"], dtype=float),
            report["y"]["name"],
            np.array(report["y"]["values"], dtype=float),
            np.array(report["outcome"], dtype=object),
            np.array(report["strides"], dtype=np.int64),
            np.array([[np.nan if p is None else p for p in row] for row in report["period"]], dtype=float),
            float(report["fraction_returning"]),
            Gait.from_report(report["gait"]),
        )

    @property
    def returns(self) -> np.ndarray:
        """Whether each cell came back to the gait."""
        return self.outcome == "gait"

    @property
    def solved_coordinate(self) -> str | None:
        """The position coordinate solved to keep the swing foot on the floor."""
        return self.report["solved_coordinate"]

    def to_frame(self) -> pd.DataFrame:
        """One row per cell: the two coordinates, ``outcome``, ``strides``, ``period``."""
        rows = [
            {
                self.x_name: x,
                self.y_name: y,
                "outcome": self.outcome[j, i],
                "strides": int(self.strides[j, i]),
                "period": self.period[j, i],
            }
            for j, y in enumerate(self.y)
            for i, x in enumerate(self.x)
        ]
        return pd.DataFrame(rows)
