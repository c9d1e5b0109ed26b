"""BEM sweep of many designs: wall time on 1 vs 2 workers, and the engines' per-task overhead.

Target (issue 19): 8 designs at 384 x 384 on 2 workers at least 1.8x faster than the serial
sweep on an idle 2-core machine. Wall times depend on what else runs on the cores: the load
average is printed beside them. Prints a markdown table (benchmarks/results/sweep.md).

Run: python benchmarks/bench_sweep.py [--designs 8] [--grid 384] [--loads 4] [--tasks 200]
"""

import argparse
import os
import tempfile
import time
from concurrent.futures import Executor
from importlib.resources import files
from pathlib import Path

import metainterface as mi
from metainterface.validation.executors import local_pool, stream


def family(folder: Path, n: int) -> list[Path]:
    """n 9-asperity designs: the packaged example with its heights scaled."""
    base = mi.Design.load(files("metainterface") / "examples" / "example_design.json")
    return [
        mi.Design(gamma=base.gamma, h=base.h * (1 + 0.05 * i), settings=base.settings).save(
            folder / f"cell{i}.json"
        )
        for i in range(n)
    ]


def sweep(paths: list[Path], out: Path, grid: int, loads: int, **kw) -> float:
    t0 = time.perf_counter()
    res = mi.validate_many(paths, out, grid=grid, loads=loads, progress=False, **kw)
    wall = time.perf_counter() - t0
    assert all("error" not in s for s in res.values())
    return wall


def overhead(executor: Executor, n: int) -> float:
    """Seconds per task for n no-op tasks through the sweep engine (``stream``)."""

    def ignore(i: int, result: object) -> None:
        pass

    stream(abs, [0] * 4, executor=executor, on_done=ignore, on_error=ignore)  # warm
    t0 = time.perf_counter()
    stream(abs, [0] * n, executor=executor, on_done=ignore, on_error=ignore)
    return (time.perf_counter() - t0) / n


def _warm() -> None:
    """Import the package's task code in a worker (returning None: a module object does not
    serialise back to the client)."""
    import metainterface.validation.executors  # noqa: F401


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--designs 2 --grid 48 --loads 2 --tasks 10"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--designs", type=int, default=8)
    ap.add_argument("--grid", type=int, default=384)
    ap.add_argument("--loads", type=int, default=4)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--tasks", type=int, default=200, help="no-op tasks for the overhead")
    args = ap.parse_args()
    import dask.distributed as dd

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        paths = family(root / "designs", args.designs)
        g, k = args.grid, args.loads
        load0 = os.getloadavg()[0]
        serial = sweep(paths, root / "serial", g, k, jobs=1)
        rows.append(("serial (this process)", serial, os.getloadavg()[0]))
        pool = sweep(paths, root / "pool", g, k, jobs=args.workers)
        rows.append((f"local processes, {args.workers} workers", pool, os.getloadavg()[0]))
        local = sweep(paths, root / "dask", g, k, jobs=args.workers, scheduler="local")
        rows.append(
            (
                f"Dask LocalCluster, {args.workers} workers (with its start)",
                local,
                os.getloadavg()[0],
            )
        )
        with (
            dd.LocalCluster(
                n_workers=args.workers, threads_per_worker=1, dashboard_address=None
            ) as cluster,
            dd.Client(cluster) as client,
        ):
            ex = client.get_executor(pure=False)
            # workers import the package once before the clock starts
            client.run(_warm)
            warm = sweep(paths, root / "dask2", g, k, executor=ex)
            rows.append(
                (f"Dask, {args.workers} running workers (executor=)", warm, os.getloadavg()[0])
            )
            dask_task = overhead(ex, args.tasks)
        with local_pool(args.workers) as p:
            pool_task = overhead(p, args.tasks)

    print(
        f"{args.designs} designs (N = 9) at {args.grid} x {args.grid}, {args.loads} loads each, "
        f"{os.cpu_count()} cores; load average before {load0:.1f}\n"
    )
    print("| run | wall [s] | speed-up vs serial | load average after |")
    print("| --- | ---: | ---: | ---: |")
    for name, wall, load in rows:
        print(f"| {name} | {wall:.1f} | {serial / wall:.2f}x | {load:.1f} |")
    print(f"\nper-task overhead ({args.tasks} no-op tasks through the sweep engine):\n")
    print("| engine | ms per task |")
    print("| --- | ---: |")
    print(f"| local process pool ({args.workers}) | {1e3 * pool_task:.2f} |")
    print(f"| Dask LocalCluster ({args.workers}) | {1e3 * dask_task:.2f} |")


if __name__ == "__main__":
    main()
