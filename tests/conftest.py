"""Suite-wide test order: the longest module first.

The suite runs on two processes (pytest-xdist, ``-n 2 --dist loadscope`` in pyproject.toml):
each test module goes whole to one process, so its module-scoped fixtures are built once.
The documentation build (tests/test_docs.py, about a third of the suite's time on one
process) is moved to the front so that it starts at once beside the rest of the suite rather
than last and alone. In one process (``-n 0``) only the order changes.
"""

from __future__ import annotations

import pytest

#: Modules run first, longest first.
FIRST = ("tests/test_docs.py",)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    def rank(item: pytest.Item) -> int:
        path = item.nodeid.split("::", 1)[0]
        return FIRST.index(path) if path in FIRST else len(FIRST)

    items.sort(key=rank)  # stable: every other test keeps its order
