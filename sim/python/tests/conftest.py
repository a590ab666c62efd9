"""Shared fixtures of the ``walker`` package's tests: the ``walker`` command they compare with.

The command is ``$WALKER_BIN`` if set, else ``walker`` in the cargo target folder
(``$CARGO_TARGET_DIR`` or ``target/``), release build. Without it the comparisons fail (they
are never skipped): build it first with ``cargo build --release -p walker-cli``.
"""

from __future__ import annotations

import json
import os
import pathlib
import subprocess
from typing import Any

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]


def walker_bin() -> pathlib.Path:
    if "WALKER_BIN" in os.environ:
        return pathlib.Path(os.environ["WALKER_BIN"])
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return target / "release" / "walker"


@pytest.fixture(scope="session")
def cli():
    """Runs ``walker ARGS --json`` and returns ``(exit code, parsed JSON or None, stderr)``."""
    path = walker_bin()
    assert path.is_file(), f"{path} not built: cargo build --release -p walker-cli (or set WALKER_BIN)"

    def run(*args: str) -> tuple[int, Any, str]:
        out = subprocess.run([str(path), *args], capture_output=True, text=True, timeout=600)
        parsed = json.loads(out.stdout) if out.stdout.strip() else None
        return out.returncode, parsed, out.stderr

    return run
