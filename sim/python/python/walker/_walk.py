"""A walk of many strides as numpy arrays and pandas tables: :class:`Walk`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd


def steps_frame(steps: list[dict[str, Any]]) -> pd.DataFrame:
    """The step summaries of a walk's JSON (``walker walk``, ``walker sil``) as a table: one row
    per step, its fields but ``events`` and ``state``, ``hip_floor_m`` as ``hip_x_m``,
    ``hip_y_m``, ``hip_z_m``."""
    rows = [
        {k: v for k, v in s.items() if k not in ("events", "state", "hip_floor_m")}
        | {
            "hip_x_m": s["hip_floor_m"][0],
            "hip_y_m": s["hip_floor_m"][1],
            "hip_z_m": s["hip_floor_m"][2],
        }
        for s in steps
    ]
    return pd.DataFrame(rows)


@dataclass(frozen=True)
class Walk:
    """A walk: the path sampled by the integrator, the per-step table and the failure.

    ``report`` is the ``walker walk --json`` object of the same walk.
    """

    report: dict[str, Any] = field(repr=False)
    """The ``walker walk --json`` object."""
    coordinates: list[str]
    """The model's generalised coordinates: the columns of ``q`` and ``qdot``."""
    time_s: np.ndarray = field(repr=False)
    """Time of each sample from the start of the walk [s], shape (n,)."""
    step: np.ndarray = field(repr=False)
    """The step (0-based) each sample belongs to, shape (n,)."""
    q: np.ndarray = field(repr=False)
    """Coordinates [rad, m] of each sample, in its step's stance labelling, shape
    (n, len(coordinates))."""
    qdot: np.ndarray = field(repr=False)
    """Their rates [rad/s, m/s], shape (n, len(coordinates))."""
    hip_floor_m: np.ndarray = field(repr=False)
    """The hip in the floor frame [m], shape (n, 3): the hip path."""
    path_cut_at_time_s: float | None = None
    """``None``: the path covers the whole walk; else the walk time [s] of its last sample,
    where it reached ``max_path_samples`` (the walk went on: :attr:`steps` has every step)."""

    @classmethod
    def from_parts(cls, report: dict[str, Any], path: dict[str, Any]) -> Walk:
        """The walk of a ``walker walk --json`` object and its path arrays."""
        return cls(
            report,
            list(path["coordinates"]),
            path["time_s"],
            path["step"],
            path["q"],
            path["qdot"],
            path["hip_floor_m"],
            path["cut_at_time_s"],
        )

    @property
    def steps_completed(self) -> int:
        """Steps completed."""
        return int(self.report["steps_completed"])

    @property
    def failure(self) -> dict[str, Any] | None:
        """How the walk ended early (``kind``, ``step``, ``time_s``, ``detail``), or ``None``
        if it completed every step."""
        return self.report["failure"]

    @property
    def steps(self) -> pd.DataFrame:
        """One row per completed step, the JSON's fields: ``step`` (0-based),
        ``start_time_s``, ``duration_s``, ``step_length_m``, ``state_deviation``,
        ``impact_energy_loss_j``, ``actuator_work_j``... (``events`` and ``state`` left to
        :attr:`events` and :attr:`states`)."""
        return steps_frame(self.report["steps"])

    @property
    def events(self) -> pd.DataFrame:
        """Every event of the walk: ``step``, ``name`` and ``time_s`` (from its stride's
        start)."""
        rows = [
            {"step": s["step"], "name": e["name"], "time_s": e["time_s"]}
            for s in self.report["steps"]
            for e in s["events"]
        ]
        return pd.DataFrame(rows, columns=["step", "name", "time_s"])

    @property
    def states(self) -> pd.DataFrame:
        """The state after each step (stride-map entries), one row per step."""
        return pd.DataFrame(
            [dict(s["state"]) for s in self.report["steps"]],
            index=pd.Index([s["step"] for s in self.report["steps"]], name="step"),
        )

    def q_frame(self) -> pd.DataFrame:
        """``q`` as a DataFrame indexed by ``time_s``, one column per coordinate."""
        return pd.DataFrame(self.q, columns=self.coordinates, index=pd.Index(self.time_s, name="time_s"))

    def qdot_frame(self) -> pd.DataFrame:
        """``qdot`` as a DataFrame indexed by ``time_s``, columns ``<coordinate>_dot``."""
        return pd.DataFrame(
            self.qdot,
            columns=[f"{c}_dot" for c in self.coordinates],
            index=pd.Index(self.time_s, name="time_s"),
        )
