"""Where a study's tasks run: in this process (``"local"``: one task at a time, each on every
core through the extension's own threads) or on a Ray cluster (``"ray"``: one task per worker
CPU, each on one thread).

A task is a pure function of its arguments (a pickled :class:`walker.Scene` and plain
numbers): its result depends on nothing else, so a study's result is the same, bit for bit,
whatever runs it, in whatever order, split or retried.
"""

from __future__ import annotations

import os
from typing import Any, Callable, Iterator, Sequence

from .._errors import InputError

EXECUTORS = ("local", "ray")
"""The executors a study accepts."""

RAY_TASK_RETRIES = 5
"""How often Ray runs a task again whose worker died (a node lost, a process killed)."""

RAY_WAIT_S = 0.5
"""How long the driver waits for a result before it looks at Ctrl-C again [s]."""


def check(executor: str, address: str | None, runtime_env: dict[str, Any] | None) -> None:
    """Refuses an unknown executor, or Ray's options without Ray."""
    if executor not in EXECUTORS:
        raise InputError(f"executor must be one of {', '.join(EXECUTORS)}, got {executor!r}")
    if executor != "ray" and (address is not None or runtime_env is not None):
        raise InputError("address and runtime_env are Ray's options: give executor='ray'")


def worker_cpus(executor: str, address: str | None, runtime_env: dict[str, Any] | None) -> int:
    """The CPUs that run tasks: this machine's for ``local``, the cluster's for ``ray``
    (connecting to it, or starting a local one, as :func:`ray.init` does)."""
    if executor == "local":
        return max(1, os.cpu_count() or 1)
    ray = _ray()
    if not ray.is_initialized():
        ray.init(address=address, runtime_env=runtime_env, log_to_driver=False,
                 include_dashboard=False, configure_logging=False)
    return max(1, int(ray.cluster_resources().get("CPU", 1)))


def _ray():
    try:
        import ray
    except ImportError as e:
        raise InputError("executor='ray' needs Ray: pip install 'ray>=2.9'") from e
    return ray


def run(executor: str, task: Callable[..., Any], shared: Any, args: Sequence[tuple[Any, ...]]
        ) -> Iterator[tuple[int, Any]]:
    """Runs ``task(shared, *a)`` for every ``a`` of ``args``; yields ``(index, result)`` as
    results arrive (in order for ``local``, as they finish for ``ray``). A task's error is
    raised here. On Ctrl-C (or when the caller stops iterating) Ray's pending tasks are
    cancelled."""
    if executor == "local":
        for k, a in enumerate(args):
            yield k, task(shared, *a)
        return
    ray = _ray()
    remote = ray.remote(num_cpus=1, max_retries=RAY_TASK_RETRIES)(task).options(
        # one thread a task: Ray gives each task one CPU
        runtime_env={"env_vars": {"RAYON_NUM_THREADS": "1"}}
    )
    shared_ref = ray.put(shared)
    pending = {remote.remote(shared_ref, *a): k for k, a in enumerate(args)}
    try:
        while pending:
            done, _ = ray.wait(list(pending), num_returns=1, timeout=RAY_WAIT_S)
            for ref in done:
                k = pending.pop(ref)
                yield k, ray.get(ref)
    finally:
        for ref in pending:
            ray.cancel(ref, force=True)
