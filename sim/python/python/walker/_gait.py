"""The gait of a scene as numpy arrays: :class:`Gait`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd


@dataclass(frozen=True)
class Gait:
    """A periodic gait (a fixed point of the stride map) and its stability.

    Every number is the one ``walker gait --json`` prints for the same scene; ``report`` is
    that JSON object itself.
    """

    report: dict[str, Any] = field(repr=False)
    """The ``walker gait --json`` object."""
    names: list[str]
    """The stride-map entries sorted by name (each rate ``_dot`` right after its coordinate),
    as ``fixed_point`` lists them: the order of ``fixed_point``, the Jacobian's rows and columns and the
    eigenvectors' entries."""
    fixed_point: np.ndarray = field(repr=False)
    """The state just after heel strike, in ``names``' order [rad, m, rad/s, m/s]."""
    jacobian: np.ndarray = field(repr=False)
    """The stride Jacobian ∂S/∂v at the fixed point (rows and columns in ``names``' order)."""
    eigenvalues: np.ndarray = field(repr=False)
    """Eigenvalues of the Jacobian (complex), in the report's order."""
    eigenvectors: np.ndarray = field(repr=False)
    """Column ``k`` is the eigenvector of ``eigenvalues[k]`` (complex, unit 2-norm, its
    largest entry real and positive; NaN where none was found), as ``numpy.linalg.eig``
    returns them."""

    @classmethod
    def from_report(cls, report: dict[str, Any]) -> Gait:
        """The gait of a ``walker gait --json`` object that converged."""
        names = list(report["jacobian"]["names"])
        n = len(names)
        fixed_point = np.array([report["fixed_point"][k] for k in names], dtype=float)
        jacobian = np.array(report["jacobian"]["rows"], dtype=float).reshape(n, n)
        eigenvalues = np.array([complex(re, im) for re, im in report["eigenvalues"]])
        vectors = np.full((n, len(eigenvalues)), np.nan + 0j)
        for k, v in enumerate(report["eigenvectors"]):
            if v is not None:
                vectors[:, k] = np.array(v["re"]) + 1j * np.array(v["im"])
        return cls(report, names, fixed_point, jacobian, eigenvalues, vectors)

    @property
    def fixed_point_named(self) -> dict[str, float]:
        """The fixed point by name, with the scene's convention outputs (e.g. Garcia's
        ``theta``, ``phi``) beside the stride-map entries."""
        return dict(self.report["fixed_point"])

    @property
    def max_abs_eigenvalue(self) -> float:
        """Largest eigenvalue modulus; below 1 the gait is stable."""
        return float(self.report["max_abs_eigenvalue"])

    @property
    def stable(self) -> bool:
        """Every eigenvalue strictly inside the unit circle."""
        return bool(self.report["stable"])

    @property
    def speed_m_s(self) -> float:
        """Forward speed [m/s]: forward progress per step over the period."""
        return float(self.report["speed_m_s"])

    @property
    def step_length_m(self) -> float:
        """Distance between the feet at heel strike [m]."""
        return float(self.report["step_length_m"])

    @property
    def progress_m_per_step(self) -> float:
        """Forward progress of one step [m]."""
        return float(self.report["progress_m_per_step"])

    @property
    def step_period_s(self) -> float:
        """Step period [s]."""
        return float(self.report["step_period_s"])

    @property
    def cost_of_transport_j_per_kg_m(self) -> float | None:
        """Actuator work per unit mass and forward distance [J/(kg·m)] (``None`` for a
        walker without actuated ankles)."""
        value = self.report.get("cost_of_transport_j_per_kg_m")
        return None if value is None else float(value)

    @property
    def specific_cost_of_transport(self) -> float | None:
        """Impact loss over weight times step length [-]."""
        value = self.report.get("specific_cost_of_transport")
        return None if value is None else float(value)

    @property
    def energy_balance(self) -> dict[str, float | None]:
        """Energy per step [J]: ``impact_energy_loss_j``, and for an actuated walker
        ``actuator_work_j_per_step``, ``damping_dissipation_j_per_step``,
        ``slope_work_j_per_step`` and ``energy_balance_residual_j`` (``None`` where absent)."""
        keys = [
            "impact_energy_loss_j",
            "actuator_work_j_per_step",
            "damping_dissipation_j_per_step",
            "slope_work_j_per_step",
            "energy_balance_residual_j",
        ]
        return {k: self.report.get(k) for k in keys}

    @property
    def events(self) -> pd.DataFrame:
        """The stride's events in order: ``name`` and ``time_s`` (from the stride's start)."""
        return pd.DataFrame(self.report["events"], columns=["name", "time_s"])

    @property
    def gait_source(self) -> str | None:
        """Where the gait comes from: ``defaults``, ``guess`` or ``continued_from_defaults``
        (``None`` for a gait of :func:`walker.gaits`, which lists every gait found)."""
        return self.report.get("gait_source")

    @property
    def newton_iterations(self) -> int:
        """Newton iterations of the search that found it."""
        return int(self.report["newton_iterations"])


@dataclass(frozen=True)
class Gaits:
    """Every distinct period-1 gait of a scene, longest step period first
    (``walker gaits --json``)."""

    report: dict[str, Any] = field(repr=False)
    """The ``walker gaits --json`` object."""
    gaits: list[Gait]
    """The gaits, longest step period first."""
    searches: int
    """Newton searches the census ran."""

    @classmethod
    def from_report(cls, report: dict[str, Any]) -> Gaits:
        """The gaits of a ``walker gaits --json`` object."""
        return cls(report, [Gait.from_report(g) for g in report["gaits"]], int(report["searches"]))

    def table(self) -> pd.DataFrame:
        """One row per gait: ``step_period_s``, ``progress_m_per_step``, ``step_length_m``,
        ``speed_m_s``, ``max_abs_eigenvalue``, ``stable``."""
        keys = [
            "step_period_s",
            "progress_m_per_step",
            "step_length_m",
            "speed_m_s",
            "max_abs_eigenvalue",
            "stable",
        ]
        return pd.DataFrame([{k: g.report[k] for k in keys} for g in self.gaits], columns=keys)
