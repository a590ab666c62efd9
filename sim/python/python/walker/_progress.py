"""Progress bars for long studies: a tqdm bar (a widget in a notebook, text on a terminal)
that the extension updates while it works without the GIL."""

from __future__ import annotations

from typing import Callable, Union

ProgressArg = Union[bool, Callable[[int, int], None], None]
"""``True``: a tqdm bar (shown once the study has lasted a second); ``False``/``None``: none;
a callable: called as ``progress(done, total)`` about every 50 ms and at the end."""


class _Bar:
    """``progress(done, total)`` onto a tqdm bar, created at the first call."""

    def __init__(self, desc: str, unit: str) -> None:
        self._desc, self._unit = desc, unit
        self._bar = None

    def __call__(self, done: int, total: int) -> None:
        if self._bar is None:
            from tqdm.auto import tqdm

            self._bar = tqdm(total=total, desc=self._desc, unit=self._unit, delay=1.0)
        if total != self._bar.total or done < self._bar.n:
            # the next stage of the study (a sweep's measuring after its continuation)
            self._bar.reset(total=total)
        self._bar.update(done - self._bar.n)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()


def callback(progress: ProgressArg, desc: str, unit: str) -> tuple[Callable[[int, int], None] | None, _Bar | None]:
    """The callable the extension calls, and the bar to close after it returns (or raised)."""
    if progress is True:
        bar = _Bar(desc, unit)
        return bar, bar
    if progress is None or progress is False:
        return None, None
    if callable(progress):
        return progress, None
    from ._errors import InputError

    raise InputError(f"progress must be True, False, None or a callable (done, total), got {progress!r}")
