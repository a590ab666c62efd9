"""Type stubs of the extension module ``walker._walker`` (the Rust side of ``walker``)."""

import os
from typing import Any, Callable, Mapping

import numpy as np
import pandas as pd

DEFAULT_GAIT_STRIDE_BUDGET: int
"""Strides one gait search may take by default (``--max-strides``)."""
MAX_BASIN_CELL_STRIDES: int
"""Most strides a basin cell may take (``basin(strides=)``)."""
MAX_MAP_CELLS: int
"""Most cells of one stability map."""
MAX_OPTIMIZE_EVALUATIONS: int
"""Most candidates one search may evaluate (``optimize(budget=)``)."""
DEFAULT_INITIAL_STEP: float
"""CMA-ES's initial step size by default, normalised (``optimize(initial_step=)``)."""
MAX_ORBIT_POINTS: int
"""Most values of one orbit diagram."""
MAX_WALK_STEPS: int
"""Most steps of one walk."""
DEFAULT_PATH_SAMPLES: int
"""Path samples a walk keeps by default (past them the path stops; the walk goes on)."""
MAX_PATH_SAMPLES: int
"""Most path samples one walk may keep (``max_path_samples``)."""
DEFAULT_SIL_FRAMES: int
"""Bus frames a SIL walk keeps by default (past them the first are kept; the walk goes on)."""
MAX_SIL_FRAMES: int
"""Most bus frames one SIL walk may keep (``max_frames``)."""

class Scene:
    """A scene: a walker described by a scene file (built-in or a path), with parameter
    values. Read-only: :meth:`with_params` returns a new scene."""

    @staticmethod
    def load(name_or_path: str | os.PathLike[str]) -> Scene:
        """Loads a built-in scene by name or a scene file by path; raises ``SceneError``."""
    @property
    def name(self) -> str:
        """The scene's name."""
    @property
    def file_text(self) -> str:
        """The text of the scene file it was parsed from (a built-in scene's own text)."""
    @property
    def values(self) -> dict[str, float]:
        """The parameter values by name (units in :attr:`parameters`)."""
    @property
    def parameters(self) -> pd.DataFrame:
        """The parameter table indexed by name: value, default, unit, min, max, doc, aliases."""
    def describe(self) -> dict[str, Any]:
        """The ``walker scenes NAME --json`` object: summary, reference, degrees of freedom,
        coordinates, parameters."""
    def with_solver(
        self,
        *,
        integrator: str | None = None,
        step_s: float | None = None,
        rtol: float | None = None,
        newton_tol: float | None = None,
        newton_max_iter: int | None = None,
        max_strides: int | None = None,
        perturbation: float | None = None,
        frozen_steps: bool | None = None,
        jacobian: str | None = None,
    ) -> Scene:
        """A new scene whose studies use these numerical options (``None`` keeps this scene's):
        the command's ``--integrator``, ``--step-s``, ``--rtol``, ``--newton-tol``,
        ``--newton-max-iter``, ``--max-strides``, ``--perturbation``, ``--frozen-steps``,
        ``--jacobian``; raises ``InputError``."""
    @property
    def solver(self) -> dict[str, Any]:
        """The numerical options of this scene's studies: ``integrator`` (as the reports give
        it), ``newton_tol``, ``newton_max_iter``, ``max_strides``, ``perturbation``,
        ``frozen_steps``, ``jacobian``."""
    def with_params(self, **params: float) -> Scene:
        """A new scene with these parameters (by name or alias) set; raises ``SceneError``
        (unknown parameter, not a finite number, out of range) or ``InputError``."""

def scenes() -> dict[str, Any]:
    """The ``walker scenes --json`` object."""

def gait(scene: Scene, *, max_strides: int | None = None) -> dict[str, Any]:
    """The ``walker gait --json`` object of the scene's gait; raises ``GaitNotFound``,
    ``StrideFailed`` or ``SceneError``."""

def gaits(scene: Scene, *, progress: Callable[[int, int], None] | None = None) -> dict[str, Any]:
    """The ``walker gaits --json`` object: every period-1 gait, longest step period first."""

def orbit_diagram(scene: Scene, param: str, values: list[float]) -> dict[str, Any]:
    """The ``walker orbit-diagram --json`` object of ``param`` over ``values``."""

def stability_map(
    scene: Scene,
    x: tuple[str, list[float]],
    y: tuple[str, list[float]],
    *,
    quantity: str | None = None,
    sigma_m: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Any]:
    """The ``walker stability-map --json`` object of the grid ``x`` × ``y`` (with
    ``quantity`` mapped too)."""

def robustness(
    scene: Scene,
    *,
    measures: list[str] | None = None,
    sigma_m: list[float] | None = None,
    mfpt_runs: int | None = None,
    mfpt_strides: int | None = None,
    mfpt_seed: int | None = None,
    rate_scan_step: float = 1e-2,
    return_strides: int | None = None,
    max_strides: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Any]:
    """The ``walker robustness --json`` object of the scene's gait; raises ``InputError``,
    ``SceneError``, ``GaitNotFound`` or ``StrideFailed``."""

def basin(
    scene: Scene,
    x: tuple[str, list[float]],
    y: tuple[str, list[float]],
    *,
    strides: int | None = None,
    max_strides: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Any]:
    """The ``walker basin --json`` object of the slice ``x`` × ``y`` through the scene's
    gait; raises ``InputError``, ``SceneError``, ``GaitNotFound`` or ``StrideFailed``."""

def sweep(
    scene: Scene,
    param: str,
    start: float,
    end: float,
    points: int,
    *,
    max_period: int | None = None,
    quantity: str | None = None,
    sigma_m: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Any]:
    """The ``walker sweep --json`` object."""

def walk(
    scene: Scene,
    steps: int,
    *,
    start: str | Mapping[str, float] | None = None,
    perturb: Mapping[str, float] | None = None,
    floor: str = "plane",
    path_interval_s: float | None = None,
    max_strides: int | None = None,
    max_path_samples: int | None = None,
) -> tuple[dict[str, Any], dict[str, Any]]:
    """``(report, path)``: the ``walker walk --json`` object and the path's numpy arrays
    (``time_s``, ``step``, ``q``, ``qdot``, ``hip_floor_m``) with ``coordinates`` and
    ``cut_at_time_s`` (``None``, or where the path stopped at ``max_path_samples``)."""

def sil(
    scene: Scene,
    steps: int,
    *,
    faults: list[str] = ...,
    sensor_faults: list[str] = ...,
    firmware_params: list[str] = ...,
    actuator: str = "servo",
    estop_at: float | None = None,
    floor: str = "plane",
    keep_steps: int | None = None,
    max_strides: int | None = None,
    max_frames: int | None = None,
) -> tuple[dict[str, Any], dict[str, Any]]:
    """``(report, frames)``: the ``walker sil --json`` object and the run's bus events as
    ``--candump`` logs them, numpy arrays ``time_ns`` (bus clock), ``id``, ``dlc``, ``data``
    (n × 8 bytes), ``error``, with ``not_kept`` (events past ``max_frames``) and
    ``max_frames``; raises ``InputError`` (the command's message), ``SceneError``,
    ``GaitNotFound`` or ``StrideFailed``."""

def check_quantity(quantity: str | None = None, sigma_m: float | None = None) -> None:
    """Checks ``quantity=``/``sigma_m=`` as :func:`stability_map` does; raises ``InputError``."""

def dbc() -> str:
    """The project's DBC file (the bus's messages and signals, as ``protocol/walker.dbc``),
    for ``cantools.database.load_string``."""

def optimize(
    scene: Scene,
    vary: list[str],
    objective: str,
    *,
    constraints: list[str] = ...,
    budget: int | None = None,
    seed: int | None = None,
    initial_step: float = ...,
    sigma_m: float | None = None,
    progress: Callable[[int, int], None] | None = None,
    evaluate: Callable[[list[list[float]], Callable[[], bool]], list[bytes]] | None = None,
) -> dict[str, Any]:
    """The ``walker optimize --json`` object of CMA-ES over the ranges ``vary``
    (``NAME=MIN:MAX``) for ``objective`` under ``constraints`` (``NAME<=V``); raises
    ``InputError`` or ``SceneError``. ``evaluate``: each generation's new candidates
    (normalised designs) to their evaluations as :func:`optimize_evaluate` makes them (a
    cluster's workers); its exception is raised here."""

def optimize_evaluate(
    scene: Scene,
    vary: list[str],
    objective: str,
    drawn: list[list[float]],
    *,
    constraints: list[str] = ...,
    budget: int | None = None,
    seed: int | None = None,
    initial_step: float = ...,
    sigma_m: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[bytes]:
    """The evaluations (CBOR, bit for bit) of the designs ``drawn`` (normalised) for the
    search :func:`optimize` runs with the same arguments: a cluster worker's task."""
