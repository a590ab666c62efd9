"""How much disturbance a gait survives: :class:`Robustness`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import pandas as pd

from ._gait import Gait


@dataclass(frozen=True)
class Robustness:
    """The robustness measures of a gait (``walker robustness --json``; docs/robustness.md).
    A measure not asked for, or that failed (``errors`` says why), is ``None``."""

    report: dict[str, Any] = field(repr=False)
    """The ``walker robustness --json`` object."""
    gait: Gait = field(repr=False)
    """The gait measured (as :func:`walker.gait` finds it)."""
    step_down_max_m: float | None
    """Largest step down survived [m]."""
    step_up_max_m: float | None
    """Largest step up survived [m]."""
    errors: dict[str, str]
    """A measure that could not be computed, and why (``gait``: the gait is unstable)."""

    @classmethod
    def from_report(cls, report: dict[str, Any]) -> Robustness:
        """The measures of a ``walker robustness --json`` object."""
        return cls(
            report,
            Gait.from_report(report["gait"]),
            report["step_down_max_m"],
            report["step_up_max_m"],
            dict(report["errors"]),
        )

    @property
    def gait_source(self) -> str | None:
        """Where the gait came from (``defaults``, ``guess``, ``continued_from_defaults``)."""
        return self.gait.gait_source

    @property
    def gait_sensitivity_norm(self) -> dict[str, Any] | None:
        """The gait sensitivity norm: ``step_time`` [s/m], ``step_length`` [m/m], ``both``, and
        ``strides_summed``."""
        return self.report["gait_sensitivity_norm"]

    @property
    def velocity_perturbation_max(self) -> pd.DataFrame | None:
        """Largest change of each rate survived, by coordinate: ``positive``, ``negative``
        [rad/s, or m/s for a slide]."""
        v = self.report["velocity_perturbation_max"]
        if v is None:
            return None
        return pd.DataFrame.from_dict(v, orient="index", columns=["positive", "negative"])

    @property
    def mfpt(self) -> pd.DataFrame:
        """The mean first-passage time on rough floors, one row per roughness: ``sigma_m``,
        ``steps`` (NaN: no walk fell), ``ci_low``, ``ci_high``, ``runs``, ``failed``,
        ``censored``, ``strides_per_run``, ``strides_simulated``..."""
        return pd.DataFrame(self.report["mfpt"])

    @property
    def return_rule(self) -> dict[str, Any]:
        """The rule a disturbed walker's return to the gait is judged by."""
        return dict(self.report["return_rule"])
