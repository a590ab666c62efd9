"""The walker simulator from Python: scenes, gaits, walks and walks with the ankle firmware in
the loop as numpy arrays and pandas tables.

>>> import walker
>>> scene = walker.Scene.load("compass").with_params(slope_rad=0.05)
>>> g = walker.gait(scene)
>>> g.max_abs_eigenvalue < 1.0
True

Every number equals the one the ``walker`` command prints with ``--json`` for the same scene
and parameters (the same library calls and the same report). Long computations release the
GIL and stop on Ctrl-C (``KeyboardInterrupt``). Errors are :class:`WalkerError` subclasses.
"""

from __future__ import annotations

import os
import warnings
from typing import Mapping, Sequence

import pandas as pd

from . import _walker
from ._basin import Basin
from ._errors import GaitNotFound, InputError, SceneError, StrideFailed, WalkerError
from ._gait import Gait, Gaits
from ._optimize import Best, Optimize
from ._orbit_diagram import OrbitDiagram
from ._progress import ProgressArg, callback as _progress_callback
from ._robustness import Robustness
from ._sil import Sil
from ._stability_map import StabilityMap
from ._sweep import Sweep
from ._walk import Walk
from ._walker import (
    DEFAULT_GAIT_STRIDE_BUDGET,
    DEFAULT_INITIAL_STEP,
    DEFAULT_PATH_SAMPLES,
    MAX_BASIN_CELL_STRIDES,
    DEFAULT_SIL_FRAMES,
    MAX_MAP_CELLS,
    MAX_OPTIMIZE_EVALUATIONS,
    MAX_ORBIT_POINTS,
    MAX_PATH_SAMPLES,
    MAX_SIL_FRAMES,
    MAX_WALK_STEPS,
    Scene,
    dbc,
)

__all__ = [
    "Basin",
    "Best",
    "Optimize",
    "optimize",
    "DEFAULT_INITIAL_STEP",
    "MAX_OPTIMIZE_EVALUATIONS",
    "Robustness",
    "basin",
    "robustness",
    "DEFAULT_GAIT_STRIDE_BUDGET",
    "DEFAULT_PATH_SAMPLES",
    "MAX_BASIN_CELL_STRIDES",
    "DEFAULT_SIL_FRAMES",
    "MAX_MAP_CELLS",
    "MAX_ORBIT_POINTS",
    "MAX_PATH_SAMPLES",
    "MAX_SIL_FRAMES",
    "MAX_WALK_STEPS",
    "Gait",
    "Gaits",
    "GaitNotFound",
    "InputError",
    "OrbitDiagram",
    "Scene",
    "SceneError",
    "Sil",
    "StabilityMap",
    "StrideFailed",
    "Sweep",
    "Walk",
    "WalkerError",
    "dbc",
    "gait",
    "gaits",
    "orbit_diagram",
    "scenes",
    "sil",
    "stability_map",
    "sweep",
    "walk",
]


def _scene(scene: Scene | str | os.PathLike[str]) -> Scene:
    return scene if isinstance(scene, Scene) else Scene.load(os.fspath(scene))


def scenes() -> pd.DataFrame:
    """The built-in scenes, indexed by name: ``summary``, ``reference``,
    ``degrees_of_freedom``, ``coordinates`` (as ``walker scenes --json`` lists them; each
    scene's parameters are ``Scene.load(name).parameters``)."""
    catalogue = _walker.scenes()["scenes"]
    rows = [{k: v for k, v in s.items() if k != "parameters"} for s in catalogue]
    return pd.DataFrame(rows).set_index("name")


def gait(scene: Scene | str | os.PathLike[str], *, max_strides: int | None = None) -> Gait:
    """The gait of ``scene`` (a :class:`Scene` or a scene name or path) as ``walker gait``
    finds it: at the scene's defaults Newton from its guess, elsewhere the defaults' gait
    followed to the scene's values (``Gait.gait_source`` says which), with the scene's solver
    options (:meth:`Scene.with_solver`; by default the scene's integrator and the command's
    default Newton settings).

    ``max_strides`` bounds the strides the search may take (``--max-strides``; ``None``: the
    scene's solver options', by default :data:`DEFAULT_GAIT_STRIDE_BUDGET`).

    Raises :class:`GaitNotFound` (or :class:`StrideFailed`, a subclass, when a stride of the
    search failed) if there is none, :class:`SceneError` if the scene cannot be built,
    ``KeyboardInterrupt`` on Ctrl-C.
    """
    return Gait.from_report(_walker.gait(_scene(scene), max_strides=max_strides))


def _axes(x: tuple[str, Sequence[float]], y: tuple[str, Sequence[float]]):
    """Two grid axes ``(name, values)`` with the values as floats."""
    return tuple((name, [float(v) for v in values]) for name, values in (x, y))


def _with_progress(progress: ProgressArg, desc: str, unit: str, run):
    f, bar = _progress_callback(progress, desc, unit)
    try:
        return run(f)
    finally:
        if bar is not None:
            bar.close()


def gaits(scene: Scene | str | os.PathLike[str], *, progress: ProgressArg = True) -> Gaits:
    """Every distinct period-1 gait of ``scene``, longest step period first, as
    ``walker gaits`` finds them (Newton from many starts, and the gaits followed from the
    scene's defaults). No gait gives an empty list. ``progress``: ``True`` shows a tqdm bar of
    the Newton searches once the census has lasted a second, ``False`` none, a callable is
    called as ``progress(done, total)``. Raises :class:`SceneError`, ``KeyboardInterrupt``
    on Ctrl-C."""
    s = _scene(scene)
    report = _with_progress(progress, "gaits", "search", lambda f: _walker.gaits(s, progress=f))
    return Gaits.from_report(report)


def walk(
    scene: Scene | str | os.PathLike[str],
    steps: int,
    *,
    start: str | Mapping[str, float] | None = "gait",
    perturb: Mapping[str, float] | None = None,
    floor: str = "plane",
    path_interval_s: float | None = None,
    max_strides: int | None = None,
    max_path_samples: int = DEFAULT_PATH_SAMPLES,
) -> Walk:
    """Walks up to ``steps`` strides of ``scene``, as ``walker walk`` does.

    ``start``: ``"gait"`` (the gait's fixed point, found as :func:`gait` finds it),
    ``"guess"`` (the scene's guess), or a mapping ``{stride-map entry: value}`` that replaces
    entries of the gait's fixed point (``--start-state``). ``perturb``: ``{entry: delta}``
    added to the start (``--perturb``). ``floor``: ``"plane"``, ``"step:at=K,height_m=H"`` or
    ``"rough:sigma_m=S[,seed=N]"`` (``--floor``); ``start=None`` is ``"gait"``.
    ``path_interval_s``: keep one path sample per interval (and every step's first and last)
    instead of every integration sample. ``max_path_samples`` (at most
    :data:`MAX_PATH_SAMPLES`) bounds the path's memory: past it the path stops, the walk goes
    on, :attr:`Walk.path_cut_at_time_s` says where, and a ``RuntimeWarning`` says so.

    A fall is not an error: :attr:`Walk.failure` says how the walk ended early (the command's
    exit code 3). Raises :class:`InputError` for bad input (``steps`` outside 0 to
    :data:`MAX_WALK_STEPS`, an unknown entry, a floor that cannot be read),
    :class:`SceneError`, :class:`GaitNotFound` / :class:`StrideFailed` (no gait to start
    from), ``KeyboardInterrupt`` on Ctrl-C.
    """
    report, path = _walker.walk(
        _scene(scene),
        steps,
        start="gait" if start is None else start if isinstance(start, str) else dict(start),
        perturb=None if perturb is None else dict(perturb),
        floor=floor,
        path_interval_s=path_interval_s,
        max_strides=max_strides,
        max_path_samples=max_path_samples,
    )
    walked = Walk.from_parts(report, path)
    if walked.path_cut_at_time_s is not None:
        warnings.warn(
            f"walker.walk: the path stopped at {walked.path_cut_at_time_s:.6g} s after "
            f"max_path_samples={max_path_samples} samples (the walk went on: see "
            "Walk.steps); a larger path_interval_s or max_path_samples keeps more",
            RuntimeWarning,
            stacklevel=2,
        )
    return walked


def sil(
    scene: Scene | str | os.PathLike[str],
    steps: int,
    *,
    faults: Sequence[str] = (),
    sensor_faults: Sequence[str] = (),
    firmware_params: Mapping[str, float] | Sequence[str] | None = None,
    actuator: str = "servo",
    estop_at_s: float | None = None,
    floor: str = "plane",
    keep_steps: int | None = None,
    max_strides: int | None = None,
    max_frames: int = DEFAULT_SIL_FRAMES,
) -> Sil:
    """Walks up to ``steps`` strides of ``scene`` with the ankle firmware in the loop (two
    nodes on the simulated CAN bus actuating the ankles), as ``walker sil`` does: from the
    ideal-actuator gait (found as :func:`gait` finds it), with the SIL integrator unless the
    scene's solver options (:meth:`Scene.with_solver`) choose one.

    ``faults``: bus faults (``--fault``, e.g. ``"drop:id=0x022,count=5"``); ``sensor_faults``:
    encoder faults (``--sensor-fault``, e.g. ``"stuck:side=left,from_ms=500"``);
    ``firmware_params``: written to both ankles at start-up (``--firmware-param``), a mapping
    ``{"taut_angle_rad": -0.07}`` or strings ``"taut_angle_rad=-0.07"``, in order;
    ``actuator``: ``"servo"`` or ``"motor"``; ``estop_at_s``: the host's emergency stop at
    this walk time (``--estop-at``); ``floor`` as :func:`walk`'s; ``keep_steps``: keep only
    the last N step summaries (``--keep-steps``). ``max_frames`` (at most
    :data:`MAX_SIL_FRAMES`) bounds the bus frames kept: past it the first ``max_frames`` are
    kept, :attr:`Sil.frames_cut_at_time_s` says where, and a ``RuntimeWarning`` says so (0
    keeps none, silently).

    :attr:`Sil.report` is the ``walker sil --json`` object; :attr:`Sil.frames` the bus
    frames (what ``--candump`` logs) decoded with the project's DBC (:func:`dbc`, cantools).
    A fall is not an error (:attr:`Sil.failure`). Raises :class:`InputError` with the
    command's message (an unknown fault, a bad firmware parameter, ``steps`` outside 0 to
    :data:`MAX_WALK_STEPS`, a scene without actuated ankles), :class:`SceneError`,
    :class:`GaitNotFound` / :class:`StrideFailed` (no ideal-actuator gait to start from),
    ``KeyboardInterrupt`` on Ctrl-C (at the next step).
    """
    if firmware_params is None:
        params: list[str] = []
    elif isinstance(firmware_params, Mapping):
        params = [f"{k}={v}" for k, v in firmware_params.items()]
    elif isinstance(firmware_params, str):
        params = [firmware_params]
    else:
        params = [str(p) for p in firmware_params]
    report, frames = _walker.sil(
        _scene(scene),
        steps,
        faults=[faults] if isinstance(faults, str) else list(faults),
        sensor_faults=[sensor_faults] if isinstance(sensor_faults, str) else list(sensor_faults),
        firmware_params=params,
        actuator=actuator,
        estop_at=estop_at_s,
        floor=floor,
        keep_steps=keep_steps,
        max_strides=max_strides,
        max_frames=max_frames,
    )
    ran = Sil.from_parts(report, frames)
    if ran.frames_not_kept and max_frames > 0:
        warnings.warn(
            f"walker.sil: the bus frames stopped at {ran.frames_cut_at_time_s:.6g} s after "
            f"max_frames={max_frames} frames ({ran.frames_not_kept} more not kept; the walk "
            "went on: see Sil.report); a larger max_frames keeps more",
            RuntimeWarning,
            stacklevel=2,
        )
    return ran


def stability_map(
    scene: Scene | str | os.PathLike[str],
    x: tuple[str, Sequence[float]],
    y: tuple[str, Sequence[float]],
    *,
    quantity: str | None = None,
    sigma_m: float | None = None,
    progress: ProgressArg = True,
) -> StabilityMap:
    """The gait of ``scene`` (as :func:`gait` finds it) at every cell of the grid of two
    parameters ``x`` and ``y``, each ``(name or alias, values)``, e.g.
    ``x=("slope_rad", np.linspace(0.01, 0.08, 29))``, as ``walker stability-map`` computes it
    (every core). ``quantity`` also maps a number of each cell's gait (``gsn``,
    ``step_down``, ``step_up``, ``mfpt`` with ``sigma_m``, ``max_abs_eigenvalue``,
    ``cost_of_transport``, ``speed_m_s``, ``step_period_s``, ``step_length_m``:
    ``--quantity``): :attr:`StabilityMap.quantity`. ``progress``: a tqdm bar of the cells
    (``True``, shown after a second), none (``False``) or ``progress(done, total)``. Raises
    :class:`SceneError` (unknown parameter, value out of range), :class:`InputError` (one
    parameter twice, no cells, more than :data:`MAX_MAP_CELLS`, an unknown quantity),
    ``KeyboardInterrupt`` on Ctrl-C (at the next gait search)."""
    s, axes = _scene(scene), _axes(x, y)
    report = _with_progress(
        progress,
        "stability map",
        "cell",
        lambda f: _walker.stability_map(s, *axes, quantity=quantity, sigma_m=sigma_m, progress=f),
    )
    return StabilityMap.from_report(report)


def robustness(
    scene: Scene | str | os.PathLike[str],
    *,
    measures: Sequence[str] = ("gsn", "steps", "rates", "mfpt"),
    sigma_m: Sequence[float] | None = None,
    mfpt_runs: int = 100,
    mfpt_strides: int = 200,
    mfpt_seed: int = 0,
    rate_scan_step: float = 1e-2,
    return_strides: int = 100,
    max_strides: int | None = None,
    progress: ProgressArg = True,
) -> Robustness:
    """How much disturbance the gait of ``scene`` (as :func:`gait` finds it) survives, as
    ``walker robustness`` measures it (docs/robustness.md): the gait sensitivity norm
    (``gsn``), the largest step down and up (``steps``), the largest change of each rate
    (``rates``), the mean first-passage time on rough floors of standard deviation
    ``sigma_m`` (``mfpt``; default 0.001, 0.003 and 0.01 leg lengths; ``mfpt_runs`` walks of
    at most ``mfpt_strides`` strides, floor seeds from ``mfpt_seed``). A disturbed walker must
    come back within 1e-6 of the gait in ``return_strides`` strides. ``progress``: a tqdm bar
    of the measures (``True``), none (``False``) or ``progress(done, total)``.

    An unstable gait has no measure: the result's ``errors["gait"]`` says so (and a
    ``RuntimeWarning``), as does any measure that failed. Raises :class:`InputError` (an
    option out of its range), :class:`SceneError`, :class:`GaitNotFound` /
    :class:`StrideFailed` (no gait), ``KeyboardInterrupt`` on Ctrl-C.
    """
    s = _scene(scene)
    report = _with_progress(
        progress,
        "robustness",
        "measure",
        lambda f: _walker.robustness(
            s,
            measures=[measures] if isinstance(measures, str) else list(measures),
            sigma_m=None if sigma_m is None else [float(v) for v in sigma_m],
            mfpt_runs=mfpt_runs,
            mfpt_strides=mfpt_strides,
            mfpt_seed=mfpt_seed,
            rate_scan_step=float(rate_scan_step),
            return_strides=return_strides,
            max_strides=max_strides,
            progress=f,
        ),
    )
    result = Robustness.from_report(report)
    if result.errors:
        shown = "; ".join(f"{k}: {v}" for k, v in result.errors.items())
        warnings.warn(f"walker.robustness: {shown}", RuntimeWarning, stacklevel=2)
    return result


def basin(
    scene: Scene | str | os.PathLike[str],
    x: tuple[str, Sequence[float]],
    y: tuple[str, Sequence[float]],
    *,
    strides: int = 100,
    max_strides: int | None = None,
    progress: ProgressArg = True,
) -> Basin:
    """A slice of the basin of attraction of the gait of ``scene`` (as :func:`gait` finds it)
    through its fixed point, over two stride-map coordinates ``x`` and ``y`` (each ``(name,
    values)``; :attr:`Gait.names` lists them), as ``walker basin`` computes it (every core):
    each cell starts from the fixed point with the two coordinates set, a third position
    solved to keep the swing foot on the floor, and walks until it is back within 1e-6 of the
    gait in at most ``strides`` strides (at most :data:`MAX_BASIN_CELL_STRIDES`), falls, or
    settles elsewhere. ``progress``: a tqdm bar of the cells (``True``), none (``False``) or
    ``progress(done, total)``. Raises :class:`InputError` (an unknown or repeated coordinate,
    an empty axis, too many cells), :class:`SceneError`, :class:`GaitNotFound` /
    :class:`StrideFailed` (no gait), ``KeyboardInterrupt`` on Ctrl-C."""
    s, axes = _scene(scene), _axes(x, y)
    report = _with_progress(
        progress,
        "basin",
        "cell",
        lambda f: _walker.basin(s, *axes, strides=strides, max_strides=max_strides, progress=f),
    )
    return Basin.from_report(report)


def orbit_diagram(scene: Scene | str | os.PathLike[str], param: str, values: Sequence[float]) -> OrbitDiagram:
    """The attractor of the stride map at each of ``values`` of parameter ``param``, each
    value starting from the last one's attractor, as ``walker orbit-diagram`` computes it
    (``values`` as its ``--from``/``--to``/``--points`` give them: ``np.linspace``). Raises
    :class:`SceneError`, :class:`InputError` (fewer than 2 or more than
    :data:`MAX_ORBIT_POINTS` values), ``KeyboardInterrupt`` on Ctrl-C."""
    report = _walker.orbit_diagram(_scene(scene), param, [float(v) for v in values])
    return OrbitDiagram.from_report(report)


def sweep(
    scene: Scene | str | os.PathLike[str],
    param: str,
    start: float,
    end: float,
    points: int,
    *,
    max_period: int = 1,
    quantity: str | None = None,
    sigma_m: float | None = None,
    progress: ProgressArg = True,
) -> Sweep:
    """The gait of ``scene`` followed as ``param`` goes from ``start`` to ``end`` at
    ``points`` points, as ``walker sweep --param P --from START --to END --points N
    --max-period K`` follows it (pseudo-arclength continuation through folds, bifurcations
    located, period-doubled branches up to ``max_period`` strides per cycle). ``quantity``
    also measures a number of every period-1 gait (as :func:`stability_map`'s; ``mfpt`` with
    ``sigma_m``): the ``quantity`` column of :meth:`Sweep.points`. ``progress``: a tqdm bar
    (``True``, after a second), none (``False``) or ``progress(done, total)``. Raises
    :class:`SceneError`, :class:`InputError`, ``KeyboardInterrupt`` on Ctrl-C (at the next
    stride)."""
    s = _scene(scene)
    report = _with_progress(
        progress,
        "sweep",
        "step",
        lambda f: _walker.sweep(
            s, param, start, end, points, max_period=max_period, quantity=quantity, sigma_m=sigma_m, progress=f
        ),
    )
    return Sweep.from_report(report)


def _ranges(vary: Mapping[str, tuple[float, float]] | Sequence[str] | str) -> list[str]:
    """``vary`` as ``NAME=MIN:MAX`` texts (floats written as Python writes them, which the
    library reads back to the same numbers)."""
    if isinstance(vary, str):
        return [vary]
    if isinstance(vary, Mapping):
        ranges = []
        for name, bounds in vary.items():
            try:
                lo, hi = bounds
                lo, hi = float(lo), float(hi)
            except (TypeError, ValueError):
                raise InputError(f"vary `{name}`: expected a pair (min, max) of numbers, got {bounds!r}") from None
            ranges.append(f"{name}={lo!r}:{hi!r}")
        return ranges
    return [str(v) for v in vary]


def _constraints(constraints: Sequence[str | tuple[str, str, float]] | str) -> list[str]:
    """``constraints`` as ``NAME<=V`` / ``NAME>=V`` texts."""
    if isinstance(constraints, str):
        return [constraints]
    texts = []
    for c in constraints:
        if isinstance(c, str):
            texts.append(c)
            continue
        try:
            name, relation, bound = c
            bound = float(bound)
        except (TypeError, ValueError):
            raise InputError(f"constraints: expected \"NAME<=V\" or (name, \"<=\", value), got {c!r}") from None
        if relation not in ("<=", ">="):
            raise InputError(f"constraints: relation {relation!r} of {c!r}: expected \"<=\" or \">=\"")
        texts.append(f"{name}{relation}{bound!r}")
    return texts


def optimize(
    scene: Scene | str | os.PathLike[str],
    vary: Mapping[str, tuple[float, float]] | Sequence[str],
    objective: str,
    *,
    constraints: Sequence[str | tuple[str, str, float]] = (),
    budget: int = 200,
    seed: int = 0,
    initial_step: float = DEFAULT_INITIAL_STEP,
    sigma_m: float | None = None,
    progress: ProgressArg = True,
) -> Optimize:
    """Searches ``scene``'s parameters for the design whose gait (as :func:`gait` finds it)
    is best by ``objective``, by CMA-ES, as ``walker optimize`` does (docs/robustness.md): the
    same arguments give the same search, bit for bit, and :attr:`Optimize.report` equals the
    command's ``--json`` object.

    ``vary``: the parameters and their ranges, ``{"leg_mass_kg": (4.0, 6.0)}`` (or texts
    ``"leg_mass_kg=4:6"``, ``--vary``), each inside the parameter's own range.
    ``objective``: ``gsn``, ``max_abs_eigenvalue``, ``cost_of_transport`` (actuated walkers;
    these three minimised), ``step_down`` or ``mfpt`` (on the rough floor of ``sigma_m``
    metres; maximised). ``constraints``: each ``"NAME<=V"`` / ``"NAME>=V"`` or a tuple
    ``(name, "<=", value)`` on ``gsn``, ``step_down``, ``step_up``, ``max_abs_eigenvalue``,
    ``mfpt``, ``cost_of_transport``, ``speed_m_s``, ``step_period_s``, ``step_length_m``.
    ``budget``: candidates evaluated, exactly (1 to :data:`MAX_OPTIMIZE_EVALUATIONS`; the
    scene's own design is evaluated once more, :attr:`Optimize.default`). ``seed``: of
    CMA-ES's draws. ``initial_step``: CMA-ES's first step size in normalised coordinates
    (each range 0 to 1; above 0, at most 1). The scene's solver options
    (:meth:`Scene.with_solver`) apply as the command's ``--integrator``, ``--rtol``, ...
    ``progress``: a tqdm bar of the ``budget + 1`` evaluations (``True``), none (``False``)
    or ``progress(done, total)``.

    No feasible design is not an error (the command's exit code 1): :attr:`Optimize.best` is
    ``None`` and a ``RuntimeWarning`` says so. Raises :class:`InputError` (an option out of
    its range, an unknown objective, a range or constraint that cannot be read),
    :class:`SceneError` (an unknown parameter, a range outside the parameter's),
    ``KeyboardInterrupt`` on Ctrl-C (at the next gait search).
    """
    return _optimize(scene, vary, objective, constraints, budget, seed, initial_step, sigma_m, progress, None)


def _optimize(scene, vary, objective, constraints, budget, seed, initial_step, sigma_m, progress, evaluate):
    """:func:`optimize`, each generation's new candidates evaluated by ``evaluate`` (a
    callable of the extension's ``optimize``; ``walker.studies.optimize``) if given."""
    s = _scene(scene)
    ranges, texts = _ranges(vary), _constraints(constraints)
    report = _with_progress(
        progress,
        "optimize",
        "gait search",
        lambda f: _walker.optimize(
            s,
            ranges,
            objective,
            constraints=texts,
            budget=budget,
            seed=seed,
            initial_step=float(initial_step),
            sigma_m=None if sigma_m is None else float(sigma_m),
            progress=f,
            evaluate=None if evaluate is None else evaluate(s, ranges, texts),
        ),
    )
    result = Optimize.from_report(report)
    if result.best is None:
        warnings.warn(
            f"walker.optimize: no feasible design among {len(report['evaluations'])} evaluations",
            RuntimeWarning,
            stacklevel=3,
        )
    return result
