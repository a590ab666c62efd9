"""Executes the notebooks in docs/notebooks/ (issue 27) and checks a few of their outputs.

Each notebook asserts its own results against the paper's and the docs' numbers, so a wrong
result is a cell error here. The kernel is this interpreter (``sys.executable``, the venv's
python with the ``walker`` package): a kernelspec written to a temporary folder, so the test
depends on no kernelspec installed anywhere. Notebooks are committed without outputs; the
executed copies are not written back.
"""

from __future__ import annotations

import json
import pathlib
import re
import sys
import time

import nbclient  # python/requirements.txt: never skipped, a missing package fails the run
import nbformat
import pytest
from jupyter_client.kernelspec import KernelSpecManager
from jupyter_client.manager import KernelManager

ROOT = pathlib.Path(__file__).resolve().parents[3]
NOTEBOOKS = ROOT / "docs" / "notebooks"
CELL_TIMEOUT_S = 300
KERNEL = "walker-venv"


@pytest.fixture(scope="module")
def kernel_dir(tmp_path_factory) -> pathlib.Path:
    root = tmp_path_factory.mktemp("kernels")
    spec = root / KERNEL
    spec.mkdir()
    (spec / "kernel.json").write_text(
        json.dumps(
            {
                "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
                "display_name": "walker venv",
                "language": "python",
                "env": {"MPLBACKEND": "module://matplotlib_inline.backend_inline"},
            }
        )
    )
    return root


def execute(name: str, kernel_dir: pathlib.Path):
    path = NOTEBOOKS / name
    nb = nbformat.read(path, as_version=4)
    # committed without outputs: keeps the repository small and the diff readable
    for cell in nb.cells:
        if cell.cell_type == "code":
            assert not cell.outputs and cell.execution_count is None, f"{name}: commit it with outputs cleared"
    km = KernelManager(kernel_name=KERNEL, kernel_spec_manager=KernelSpecManager(kernel_dirs=[str(kernel_dir)]))
    client = nbclient.NotebookClient(
        nb, km=km, timeout=CELL_TIMEOUT_S, resources={"metadata": {"path": str(NOTEBOOKS)}}
    )
    start = time.perf_counter()
    client.execute()  # raises CellExecutionError on the first failing cell (an assert, too)
    print(f"{name}: {time.perf_counter() - start:.1f} s")
    return nb


def text_of(nb) -> str:
    parts = []
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            if out.output_type == "stream":
                parts.append(out.text)
            elif "data" in out and "text/plain" in out.data:
                parts.append(out.data["text/plain"])
    return "\n".join(parts)


def images_of(nb) -> int:
    return sum(
        1
        for cell in nb.cells
        for out in cell.get("outputs", [])
        if out.output_type == "display_data" and "image/png" in out.get("data", {})
    )


def errors_of(nb) -> list:
    return [out for cell in nb.cells for out in cell.get("outputs", []) if out.output_type == "error"]


def test_notebooks_are_listed():
    assert sorted(p.name for p in NOTEBOOKS.glob("*.ipynb")) == [
        "paper_claims.ipynb",
        "pelvic_design.ipynb",
        "simplest_bifurcations.ipynb",
    ]


def test_paper_claims(kernel_dir):
    nb = execute("paper_claims.ipynb", kernel_dir)
    out = text_of(nb)
    assert not errors_of(nb)
    # the README's value, to the central-difference Jacobian's noise (a few 1e-9)
    m = re.search(r"max \|eigenvalue\| = ([0-9.]+)", out)
    assert m and abs(float(m.group(1)) - 0.98773638) < 2e-8, out
    assert "fell_forward" in out
    assert images_of(nb) == 2


def test_pelvic_design(kernel_dir):
    nb = execute("pelvic_design.ipynb", kernel_dir)
    assert not errors_of(nb)
    assert "walker.gait" in text_of(nb)
    assert images_of(nb) == 1


def test_simplest_bifurcations(kernel_dir):
    nb = execute("simplest_bifurcations.ipynb", kernel_dir)
    out = text_of(nb)
    assert not errors_of(nb)
    assert "period doubling of the period-1 gait at slope 0.01508843" in out
    assert images_of(nb) == 1
