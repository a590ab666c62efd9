"""A gait followed over one parameter: :class:`Sweep`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import pandas as pd


@dataclass(frozen=True)
class Sweep:
    """The gait followed by continuation over one parameter (``walker sweep --json``);
    the branches, bifurcations (``stability_boundaries``) and branch ends are in ``report``."""

    report: dict[str, Any] = field(repr=False)
    """The ``walker sweep --json`` object."""
    param: str
    """The parameter followed (its canonical name)."""

    @classmethod
    def from_report(cls, report: dict[str, Any]) -> Sweep:
        """The sweep of a ``walker sweep --json`` object."""
        return cls(report, report["param_canonical"])

    def points(self) -> pd.DataFrame:
        """One row per point along the branches: ``value``, ``converged``, ``branch``,
        ``period_strides``, ``max_abs_eigenvalue``, ``stable``, ``step_period_s``,
        ``step_length_m`` (NaN where no gait was found), and with ``quantity=`` its value
        under its name (NaN where it has none: :meth:`quantity_errors` says why)."""
        keys = [
            "value",
            "converged",
            "branch",
            "period_strides",
            "max_abs_eigenvalue",
            "stable",
            "step_period_s",
            "step_length_m",
        ]
        rows = [{k: p.get(k) for k in keys} for p in self.report["points"]]
        names = {p["quantity"]["name"] for p in self.report["points"] if p.get("quantity")}
        for name in names:
            keys.append(name)
            for row, p in zip(rows, self.report["points"]):
                q = p.get("quantity")
                row[name] = q["value"] if q and q["value"] is not None else float("nan")
        return pd.DataFrame(rows, columns=keys)

    def quantity_errors(self) -> pd.DataFrame:
        """Why a point's ``quantity`` has no value: ``value``, ``branch``, ``error``."""
        rows = [
            {"value": p["value"], "branch": p.get("branch"), "error": p["quantity"]["error"]}
            for p in self.report["points"]
            if p.get("quantity") and p["quantity"].get("error")
        ]
        return pd.DataFrame(rows, columns=["value", "branch", "error"])

    def stability_boundaries(self) -> pd.DataFrame:
        """The located bifurcations (folds, period doublings, Neimark–Sacker), one row each,
        as the JSON lists them."""
        return pd.DataFrame(self.report["stability_boundaries"])
