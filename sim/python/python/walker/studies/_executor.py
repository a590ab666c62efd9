"""Where a study's tasks run: in this process (``"local"``: one task at a time, each on every
core through the extension's own threads) or on a Ray cluster (``"ray"``: one task per worker
CPU, each on one thread).

A task is a pure function of its arguments (a pickled :class:`walker.Scene` and plain
numbers): its result depends on nothing else, so a study's result is the same, bit for bit,
whatever runs it, in whatever order, split or retried.
"""

from __future__ import annotations

import os
import time
from typing import Any, Callable, Iterator, Sequence

from .._errors import InputError, WalkerError

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
        _reachable(address)
        try:
            ray.init(address=address, runtime_env=runtime_env, log_to_driver=False,
                     include_dashboard=False, configure_logging=False)
        except ConnectionError as e:
            # something answers at the address, but no Ray cluster (Ray gave up on it)
            raise InputError(f"no Ray cluster at {address} ({e})") from None
    return max(1, int(ray.cluster_resources().get("CPU", 1)))


CONNECT_BUDGET_S = 10.0
"""How long a cluster's address may take to answer before the study refuses it [s] (Ray's
own connection waits minutes, deaf to Ctrl-C)."""


def _reachable(address: str | None) -> None:
    """Refuses a ``HOST:PORT`` address nothing listens on (other forms are Ray's to read)."""
    host, sep, port = (address or "").rpartition(":")
    if not sep or not port.isdigit() or "://" in address:
        return
    import socket

    try:
        socket.create_connection((host, int(port)), timeout=CONNECT_BUDGET_S).close()
    except OSError as e:
        raise InputError(f"no Ray cluster answers at {address} ({e})") from None


def _ray():
    try:
        import ray
    except ImportError as e:
        raise InputError("executor='ray' needs Ray: pip install 'ray>=2.9'") from e
    return ray


NO_CPU_BUDGET_S = 120.0
"""How long a study waits for a cluster that has lost every worker CPU [s]."""


def run(executor: str, task: Callable[..., Any], shared: Any, args: Sequence[tuple[Any, ...]],
        cancelled: Callable[[], bool] | None = None) -> Iterator[tuple[int, Any]]:
    """Runs ``task(shared, *a)`` for every ``a`` of ``args``; yields ``(index, result)`` as
    results arrive (in order for ``local``, as they finish for ``ray``). A task's error is
    raised here. On Ctrl-C, when ``cancelled()`` turns true (``KeyboardInterrupt``), or when
    the caller stops iterating, Ray's pending tasks are cancelled."""
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
    without_cpu_since: float | None = None
    try:
        while pending:
            if cancelled is not None and cancelled():
                raise KeyboardInterrupt
            done, _ = ray.wait(list(pending), num_returns=1, timeout=RAY_WAIT_S)
            for ref in done:
                k = pending.pop(ref)
                yield k, ray.get(ref)
            if done:
                without_cpu_since = None
            elif ray.cluster_resources().get("CPU", 0) > 0:
                without_cpu_since = None
            elif without_cpu_since is None:
                without_cpu_since = time.monotonic()
            elif time.monotonic() - without_cpu_since > NO_CPU_BUDGET_S:
                raise WalkerError(f"the Ray cluster has had no worker CPU for {NO_CPU_BUDGET_S:.0f} s: "
                                  f"{len(pending)} tasks cannot run")
    finally:
        for ref in pending:
            ray.cancel(ref, force=True)
