"""Suite-wide test order: the longest module first.

The suite runs on two processes (pytest-xdist, ``-n 2 --dist loadscope`` in pyproject.toml):
each test module goes whole to one process, so its module-scoped fixtures are built once.
The longest modules (CPU seconds measured in benchmarks/results/test_suite.md) are moved to
the front so that none starts last and runs alone while the other process idles. The
documentation build (tests/test_docs.py, marked ``docs``: CI's step of its own) leads where
it is selected. In one process (``-n 0``) only the order changes.
"""

from __future__ import annotations

import pytest

#: Modules run first, longest first.
FIRST = (
    "tests/test_docs.py",
    "tests/scaling/test_adhesive_scale.py",
    "tests/verify/test_verify.py",
    "tests/test_reproduce.py",
    "tests/measure/test_predict.py",
    "tests/robustness/test_faults.py",
)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    def rank(item: pytest.Item) -> int:
        path = item.nodeid.split("::", 1)[0]
        return FIRST.index(path) if path in FIRST else len(FIRST)

    items.sort(key=rank)  # stable: every other test keeps its order
