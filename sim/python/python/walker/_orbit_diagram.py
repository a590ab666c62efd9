"""The attractors of the stride map over one parameter: :class:`OrbitDiagram`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd


@dataclass(frozen=True)
class OrbitDiagram:
    """The attractor at each value of one parameter (``walker orbit-diagram --json``)."""

    report: dict[str, Any] = field(repr=False)
    """The ``walker orbit-diagram --json`` object."""
    param: str
    """The parameter varied (its canonical name)."""
    values: np.ndarray = field(repr=False)
    """Its values."""

    @classmethod
    def from_report(cls, report: dict[str, Any]) -> OrbitDiagram:
        """The diagram of a ``walker orbit-diagram --json`` object."""
        return cls(report, report["param"], np.array([p["value"] for p in report["points"]]))

    def attractors(self) -> pd.DataFrame:
        """One row per value: ``value``, ``attractor`` (periodic, chaotic or fell),
        ``period_strides``, ``strides``, ``seeded``."""
        keys = ["value", "attractor", "period_strides", "strides", "seeded"]
        return pd.DataFrame([{k: p[k] for k in keys} for p in self.report["points"]], columns=keys)

    def samples(self, entry: str) -> pd.DataFrame:
        """The heel-strike values of stride-map entry (or convention output) ``entry`` on
        each value's attractor, one row per sample: ``value`` and ``entry`` (the classic
        orbit diagram's points)."""
        rows = [
            {"value": p["value"], entry: x}
            for p in self.report["points"]
            for x in p["samples"].get(entry, [])
        ]
        return pd.DataFrame(rows, columns=["value", entry])
