"""docs/python.md's examples run as written: every ```python block, in order, in one namespace
(a later block may use what an earlier one made), so the documented API cannot drift from the
package."""

from __future__ import annotations

import pathlib
import re
import warnings

import walker

DOC = pathlib.Path(__file__).resolve().parents[3] / "docs" / "python.md"


def blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)


def test_docs_python_md_has_an_example_of_every_public_function():
    text = "\n".join(blocks())
    public = [n for n in walker.__all__ if callable(getattr(walker, n)) and n[0].islower()]
    missing = [n for n in public if f"walker.{n}(" not in text]
    assert not missing, f"docs/python.md has no example of {missing}"


def test_docs_python_md_examples_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for i, code in enumerate(blocks()):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # e.g. an unstable gait's robustness
            try:
                exec(compile(code, f"docs/python.md block {i + 1}", "exec"), namespace)
            except Exception as e:  # pragma: no cover - the message names the block
                raise AssertionError(f"docs/python.md block {i + 1} fails: {e!r}\n{code}") from e
