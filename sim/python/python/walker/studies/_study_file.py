"""A study's results on disk: a Parquet file of the cells done so far, with the study's full
specification and the versions that computed it in the file's metadata.

The file is rewritten whole, atomically (a temporary file in the same folder, then
``os.replace``), as results arrive: whatever kills the driver, the file on disk is a complete
Parquet file of the cells finished before its last write. A study started again with the same
file reads it, checks that its specification is the one asked for (refusing another, naming
the differences) and computes only the cells it lacks.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import time
from typing import Any, Iterable, Iterator

from .._errors import InputError

METADATA_KEY = b"walker.study"
"""The key of the file's metadata that holds ``{"spec": ..., "versions": ..., "extra": ...}``."""

FORMAT = 1
"""The layout of the file (its ``spec["format"]``)."""

MAX_DIFFERENCES = 5
"""Differences named when a file's specification is refused."""


def canonical(spec: Any) -> Any:
    """``spec`` as JSON reads it back (tuples as lists, floats exact: JSON writes ``repr``).
    Raises :class:`InputError` for a number that is not finite."""
    try:
        return json.loads(json.dumps(spec, allow_nan=False, sort_keys=True))
    except ValueError as e:
        raise InputError(f"a study's specification must hold finite numbers only ({e})") from None


def differences(file: Any, now: Any, where: str = "") -> list[str]:
    """Where two specifications differ, as ``where: <in the file> in the file, <now> now``."""
    if isinstance(file, dict) and isinstance(now, dict):
        out: list[str] = []
        for k in sorted(set(file) | set(now)):
            at = f"{where}.{k}" if where else str(k)
            if k not in file:
                out.append(f"{at}: absent in the file, {now[k]!r} now")
            elif k not in now:
                out.append(f"{at}: {file[k]!r} in the file, absent now")
            else:
                out.extend(differences(file[k], now[k], at))
        return out
    if isinstance(file, list) and isinstance(now, list):
        if len(file) != len(now):
            return [f"{where}: {len(file)} entries in the file, {len(now)} now"]
        out = []
        for n, (a, b) in enumerate(zip(file, now)):
            out.extend(differences(a, b, f"{where}[{n}]"))
        return out
    if type(file) is not type(now) or file != now or (
            isinstance(file, float) and math.copysign(1.0, file) != math.copysign(1.0, now)):
        return [f"{where}: {file!r} in the file, {now!r} now"]
    return []


class StudyFile:
    """The cells of one study on disk (``path``), keyed by a tuple of integer columns
    (``key_columns``); see the module docs."""

    def __init__(self, path: str | os.PathLike[str], spec: dict[str, Any], versions: dict[str, str],
                 key_columns: tuple[str, ...], save_every_s: float = 1.0) -> None:
        self.path = os.fspath(path)
        self.spec = canonical(spec)
        self.versions = dict(versions)
        self.key_columns = key_columns
        self.save_every_s = save_every_s
        self.rows: dict[tuple[int, ...], dict[str, Any]] = {}
        self.extra: dict[str, Any] = {}
        self._last_save = -math.inf
        self._dirty = False

    def check_path(self) -> None:
        """Refuses, before anything is computed, a path the study could not write its file
        to: a directory, a missing or read-only folder, a file it cannot read."""
        folder = os.path.dirname(os.path.abspath(self.path))
        if os.path.isdir(self.path):
            raise InputError(f"study file {self.path} is a directory: give a file's path")
        if not os.path.isdir(folder):
            raise InputError(f"study file {self.path}: its folder {folder} does not exist")
        if not os.access(folder, os.W_OK | os.X_OK):
            raise InputError(f"study file {self.path}: its folder {folder} is not writable")
        if os.path.exists(self.path) and not os.access(self.path, os.R_OK):
            raise InputError(f"study file {self.path} cannot be read (permission denied)")

    def load(self) -> None:
        """Reads the cells of an existing file (none when there is no file). Raises
        :class:`InputError` when the path cannot hold the study's file
        (:meth:`check_path`), the file is not a study file or is another study's."""
        self.check_path()
        if not os.path.exists(self.path):
            return
        import pyarrow.parquet as pq

        try:
            table = pq.read_table(self.path)
        except OSError as e:
            raise InputError(f"study file {self.path} cannot be read ({e})") from e
        except Exception as e:  # pyarrow's errors have no common base but ArrowException
            raise InputError(f"study file {self.path}: not a Parquet file ({e})") from e
        meta = (table.schema.metadata or {}).get(METADATA_KEY)
        if meta is None:
            raise InputError(f"study file {self.path}: a Parquet file without a walker study in its metadata")
        try:
            stored = json.loads(meta)
            spec = stored["spec"]
        except (ValueError, KeyError, TypeError) as e:
            raise InputError(f"study file {self.path}: its study metadata cannot be read ({e})") from e
        if isinstance(spec, dict) and spec.get("study") != self.spec.get("study"):
            raise InputError(
                f"study file {self.path} holds another study: study: {spec.get('study')!r} in the file, "
                f"{self.spec.get('study')!r} now. Give another file, or delete this one to start afresh"
            )
        diff = differences(spec, self.spec)
        if diff:
            shown = "; ".join(diff[:MAX_DIFFERENCES])
            more = f" (and {len(diff) - MAX_DIFFERENCES} more)" if len(diff) > MAX_DIFFERENCES else ""
            raise InputError(
                f"study file {self.path} holds another study: {shown}{more}. "
                "Give another file, or delete this one to start afresh"
            )
        missing = [c for c in self.key_columns if c not in table.column_names]
        if missing:
            raise InputError(f"study file {self.path}: no column {missing[0]!r}")
        self.extra = dict(stored.get("extra") or {})
        # The versions that started the study stay; those that went on with it are added.
        started = stored.get("versions")
        if isinstance(started, dict) and started != self.versions:
            later = [v for v in self.extra.get("resumed_with", []) if v != self.versions]
            self.extra["resumed_with"] = later + [canonical(self.versions)]
            self.versions = started
        for row in table.to_pylist():
            self.rows[tuple(int(row[c]) for c in self.key_columns)] = row

    def add(self, rows: Iterable[dict[str, Any]]) -> None:
        """Adds finished cells and saves when the last save is older than ``save_every_s``."""
        for row in rows:
            self.rows[tuple(int(row[c]) for c in self.key_columns)] = row
        self._dirty = True
        if time.monotonic() - self._last_save >= self.save_every_s:
            self.save()

    def save(self) -> None:
        """Writes every cell held (atomically; nothing when nothing changed: a study that
        computed nothing leaves no file)."""
        if not self._dirty:
            return
        import pyarrow as pa
        import pyarrow.parquet as pq

        rows = [self.rows[k] for k in sorted(self.rows)]
        table = pa.Table.from_pylist(rows, schema=self.schema) if rows else self.schema.empty_table()
        folder = os.path.dirname(os.path.abspath(self.path))
        tmp = os.path.join(folder, f".{os.path.basename(self.path)}.{os.getpid()}.tmp")
        try:
            pq.write_table(table, tmp)
            os.replace(tmp, self.path)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
        self._last_save = time.monotonic()
        self._dirty = False

    schema: Any = None
    """The pyarrow schema of the cells, with the study in its metadata (set by the study)."""

    def with_schema(self, fields: list[tuple[str, Any]]) -> None:
        """Sets :attr:`schema` from ``(name, pyarrow type)`` pairs and the study's metadata."""
        import pyarrow as pa

        meta = json.dumps({"spec": self.spec, "versions": self.versions, "extra": self.extra},
                          sort_keys=True).encode()
        self.schema = pa.schema(fields, metadata={METADATA_KEY: meta})

    def set_extra(self, key: str, value: Any) -> None:
        """Keeps ``value`` in the metadata (what a study learns from its first result)."""
        if self.extra.get(key) != value:
            self.extra[key] = canonical(value)
            self._dirty = True
            if self.schema is not None:
                self.with_schema(list(zip(self.schema.names, self.schema.types)))


@contextlib.contextmanager
def saved_on_exit(file: StudyFile | None) -> Iterator[None]:
    """Saves ``file`` (if any) when the block ends: on success as :meth:`StudyFile.save`
    does (its error raised), on an error keeping what was computed without hiding why the
    study stopped (a failing save is then ignored)."""
    try:
        yield
    except BaseException:
        if file is not None:
            with contextlib.suppress(Exception):
                file.save()
        raise
    if file is not None:
        file.save()
