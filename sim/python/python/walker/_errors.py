"""The exceptions of the ``walker`` package.

Each carries the message the ``walker`` command prints after ``error:`` and, as attributes,
the values the error names.
"""

from __future__ import annotations

from typing import Any


class WalkerError(Exception):
    """Base class of every error the ``walker`` package raises."""


class InputError(WalkerError, ValueError):
    """Bad input other than a scene's: a count out of its bounds (``steps``), an unknown
    stride-map entry, a floor or start that cannot be read. Also a ``ValueError``."""


class SceneError(WalkerError, ValueError):
    """A scene that cannot be loaded or built, or a parameter that cannot be set.

    Attributes: ``kind`` (``unknown_scene``, ``file``, ``unknown_parameter``,
    ``not_a_number``, ``out_of_range`` or ``invalid``) and the values it names: ``name``,
    ``available``, ``scene``, ``path``, ``detail``, ``value``, ``unit``, ``min``, ``max``
    (those that apply). Also a ``ValueError``."""

    kind: str = "invalid"


class GaitNotFound(WalkerError):
    """No gait was found (``walker gait`` exits with code 1).

    Attributes: ``report`` (the ``walker gait --json`` object, ``converged: false``),
    ``newton_iterations`` and ``failure`` (``None`` here; see :class:`StrideFailed`)."""

    report: dict[str, Any]
    newton_iterations: int
    failure: dict[str, Any] | None = None


class StrideFailed(GaitNotFound):
    """No gait was found because a stride of the search failed (the walker fell, or the
    stride ran out of its budget); ``failure`` says how (``kind``, ``time_s``, ``detail``...)."""
