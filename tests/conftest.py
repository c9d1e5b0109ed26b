"""Suite-wide test order: the longest module first.

The suite runs on two processes (pytest-xdist, ``-n 2 --dist loadscope`` in pyproject.toml):
each test module goes whole to one process, so its module-scoped fixtures are built once.
The longest modules (CPU seconds measured in benchmarks/results/test_suite.md) are moved to
the front so that none starts last and runs alone while the other process idles. The
documentation build (tests/test_docs.py, marked ``docs``: CI's step of its own) leads where
it is selected. In one process (``-n 0``) only the order changes.

Where the environment says not to write bytecode (PYTHONDONTWRITEBYTECODE), every Python
process of the suite (the two workers, the ~30 commands the tests start, the docs' kernels)
compiled the package afresh, ~1 CPU s each. The session compiles it once instead (the
bytecode Python would have written, read by every process) and removes what it wrote at
its end.
"""

from __future__ import annotations

import compileall
import importlib.util
import shutil
import sys
from pathlib import Path

import pytest

_WRITTEN: list[Path] = []


def pytest_configure(config: pytest.Config) -> None:
    if hasattr(config, "workerinput") or not sys.flags.dont_write_bytecode:
        return  # workers share the controller's; elsewhere Python writes its own
    spec = importlib.util.find_spec("metainterface")  # found, not imported (no torch here)
    if spec is None or not spec.submodule_search_locations:
        return
    root = Path(next(iter(spec.submodule_search_locations)))
    before = set(root.rglob("__pycache__"))
    compileall.compile_dir(root, quiet=2)
    _WRITTEN.extend(set(root.rglob("__pycache__")) - before)


def pytest_unconfigure(config: pytest.Config) -> None:
    while _WRITTEN:
        shutil.rmtree(_WRITTEN.pop(), ignore_errors=True)


#: Modules run first, longest first (in the long step, -m long, most of all).
FIRST = (
    "tests/test_docs.py",
    "tests/scaling/test_adhesive_scale.py",
    "tests/measure/test_printed.py",
    "tests/units/test_friction_adhesion.py",
    "tests/measure/test_predict.py",
    "tests/verify/test_verify.py",
    "tests/test_reproduce.py",
    "tests/robustness/test_faults.py",
)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    def rank(item: pytest.Item) -> int:
        path = item.nodeid.split("::", 1)[0]
        return FIRST.index(path) if path in FIRST else len(FIRST)

    items.sort(key=rank)  # stable: every other test keeps its order
