"""Studies that outgrow one process: a study split into pure tasks that run in this process or
on a Ray cluster (``executor="ray"``), its results written as they arrive to a study file
(Parquet) from which an interrupted study resumes. The result is the same, bit for bit, as the
one-process function's (:func:`walker.stability_map`, :func:`walker.optimize`), whatever the executor, the number of
workers, the split or the retries (docs/cluster.md).

>>> import walker.studies
>>> m = walker.studies.stability_map("compass", ("slope", [0.03, 0.05]), ("leg_mass_kg", [4.0, 6.0]),
...                                  progress=False)
>>> m.max_abs_eigenvalue.shape
(2, 2)

From a shell: ``python -m walker.studies stability-map --help``.
"""

from __future__ import annotations

from ._executor import EXECUTORS, RAY_TASK_RETRIES
from ._optimize import optimize
from ._stability_map import LOCAL_BLOCK_CELLS, TASKS_PER_CPU, stability_map
from ._study_file import METADATA_KEY

__all__ = [
    "EXECUTORS",
    "LOCAL_BLOCK_CELLS",
    "METADATA_KEY",
    "RAY_TASK_RETRIES",
    "TASKS_PER_CPU",
    "optimize",
    "stability_map",
]
