"""A Ray test cluster on this machine: a head and worker nodes, each a separate ``ray start
--block`` process (its own process group, killed as a whole), all on 127.0.0.1.

Run inside a network namespace of its own with only the loopback interface up (``unshare -n``,
``ip link set lo up``): outside one, Ray advertises and connects to the machine's other
address even when told 127.0.0.1. ``test_walker_studies.py::test_cluster`` runs
``ray_cluster_check.py`` so.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HOST = "127.0.0.1"
START_BUDGET_S = 120.0
"""How long the nodes may take to join [s]."""

AUTH_MODE = "disabled"
"""Ray's token authentication, off for the test cluster (loopback only, in a namespace of its
own): left unset, a token in ``~/.ray/auth_token`` (any local ``ray.init()`` writes one)
switches it on for the nodes and not for the driver. The driver sets ``RAY_AUTH_MODE`` too."""


class Cluster:
    """A head without CPUs (it schedules, runs no task) and ``workers`` nodes of one CPU each."""

    def __init__(self, workers: int, port: int = 6390) -> None:
        self.port = port
        self.address = f"{HOST}:{port}"
        self.temp = tempfile.mkdtemp(prefix="rw")  # short: Ray's socket paths are limited
        self.ray = os.path.join(os.path.dirname(sys.executable), "ray")
        self.procs: list[subprocess.Popen] = []
        self.logs: list[str] = []
        self.head = self._start(["--head", f"--port={port}", "--num-cpus=0", "--include-dashboard=false",
                                 f"--temp-dir={self.temp}"], "head")
        self.workers: list[subprocess.Popen] = []
        self.wanted_workers = workers

    def connect(self, ray) -> None:
        """Connects this process to the head, then starts the worker nodes one by one (two
        starting at once on a small machine can miss the raylet's start-up deadline)."""
        ray.init(address=self.address, log_to_driver=False, configure_logging=False)
        for _ in range(self.wanted_workers):
            self.add_worker(ray)

    def add_worker(self, ray) -> None:
        """Starts one more worker node (one CPU) and waits until it has joined."""
        alive = sum(1 for p in self.workers if p.poll() is None)
        self.workers.append(self._start([f"--address={self.address}", "--num-cpus=1"], f"worker{len(self.workers)}"))
        self.wait_for_cpus(ray, alive + 1)

    def _start(self, args: list[str], name: str) -> subprocess.Popen:
        log = os.path.join(self.temp, f"{name}.log")
        self.logs.append(log)
        env = dict(os.environ, RAY_USAGE_STATS_ENABLED="0", RAY_AUTH_MODE=AUTH_MODE)
        p = subprocess.Popen(
            [self.ray, "start", "--block", f"--node-ip-address={HOST}", "--disable-usage-stats", *args],
            stdout=open(log, "w"), stderr=subprocess.STDOUT, start_new_session=True, env=env,
        )
        self.procs.append(p)
        if name == "head":
            time.sleep(3.0)  # the GCS listens before a worker node may join
        return p

    def wait_for_cpus(self, ray, cpus: int) -> None:
        """Waits until the cluster has exactly ``cpus`` CPUs (nodes joined, or a killed node
        noticed: the head notices by missed heartbeats)."""
        deadline = time.monotonic() + START_BUDGET_S
        while time.monotonic() < deadline:
            if int(ray.cluster_resources().get("CPU", 0)) == cpus:
                return
            time.sleep(0.5)
        raise RuntimeError(f"the cluster has {ray.cluster_resources()} after {START_BUDGET_S} s, not {cpus} CPUs: "
                           + self.tail())

    @staticmethod
    def _session(p: subprocess.Popen) -> list[int]:
        """The processes of node ``p``'s session: its ``ray start``, raylet, agents and
        workers (a task's worker has a process group of its own, not a session)."""
        out = []
        for pid in os.listdir("/proc"):
            if pid.isdigit():
                try:
                    if os.getsid(int(pid)) == p.pid:
                        out.append(int(pid))
                except (OSError, ProcessLookupError):
                    pass
        return out

    def kill(self, p: subprocess.Popen) -> None:
        """Kills a node: every process of its session (``ray start``, raylet, workers)."""
        for pid in self._session(p):
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        p.wait(timeout=30)

    def kill_when_running(self, p: subprocess.Popen, task: str, budget_s: float = 120.0) -> bool:
        """Kills node ``p`` as soon as one of its workers runs ``task`` (Ray titles a worker
        process ``ray::<task>`` while it runs one), so that the kill lands on a running task;
        ``False`` if none ran within ``budget_s``."""
        title = f"ray::{task}".encode()
        deadline = time.monotonic() + budget_s
        while time.monotonic() < deadline:
            for pid in self._session(p):
                try:
                    with open(f"/proc/{pid}/cmdline", "rb") as f:
                        running = f.read().startswith(title)
                except OSError:
                    continue
                if running:
                    self.kill(p)
                    return True
            time.sleep(0.01)
        return False

    def tail(self) -> str:
        out = []
        for log in self.logs:
            try:
                with open(log) as f:
                    out.append(f"--- {log}\n" + f.read()[-2000:])
            except OSError:
                pass
        return "\n".join(out)

    def stop(self) -> None:
        for p in reversed(self.procs):
            self.kill(p)
        shutil.rmtree(self.temp, ignore_errors=True)
