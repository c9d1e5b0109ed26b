"""The README main job's phases in CPU seconds: imports, the reach test's envelope, the design,
the BEM check (its worker processes included), the files and the figure.

CPU seconds (user + system of the process and of its waited-for children, ``os.times``) move
less than wall time on a shared machine: compare two source trees by running this on each in
turn, several times, and take the minimum. Runs the command line in this process, as
``python -m metainterface design ...`` does.

Run: PYTHONPATH=src python benchmarks/bench_main_job_phases.py design --target saturating
     --out /tmp/main-job
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from collections.abc import Callable
from typing import Any


def cpu() -> float:
    """CPU seconds of this process and its finished children."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def timed(module: Any, name: str, label: str, marks: list[tuple[str, float]]) -> None:
    """Replace ``module.name`` by a wrapper that adds its CPU seconds to ``marks``."""
    fn: Callable[..., Any] = getattr(module, name)

    def run(*args: Any, **kwargs: Any) -> Any:
        start = cpu()
        try:
            return fn(*args, **kwargs)
        finally:
            marks.append((label, cpu() - start))

    setattr(module, name, run)


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "design --target saturating --no-verify --out {tmp}"


def main() -> None:
    start, wall = cpu(), time.perf_counter()
    marks: list[tuple[str, float]] = []
    import metainterface.cli as cli
    import metainterface.designer.finish as finish
    import metainterface.inverse.envelope as envelope
    import metainterface.inverse.pipeline as pipeline

    timed(finish, "verify_all", "BEM check", marks)
    timed(finish, "save_all", "files and figure", marks)
    timed(pipeline, "design", "design", marks)
    timed(envelope, "_envelope", "envelope", marks)
    marks.append(("imports", cpu() - start))
    sys.argv = ["metainterface", *sys.argv[1:]]
    with contextlib.suppress(SystemExit):  # the exit status is not measured
        cli.main()
    total = {"total": cpu() - start}
    for label, seconds in marks:
        total[label] = total.get(label, 0.0) + seconds
    total["wall"] = time.perf_counter() - wall
    print(" | ".join(f"{k} {v:.2f}" for k, v in total.items()), file=sys.stderr)


if __name__ == "__main__":
    main()
