"""Benchmark: generate 100,000 samples to disk; print wall seconds and peak memory.

    python benchmarks/bench_generate.py [--samples 100000] [--seed 0] [--out DIR] [--threads T]

Target (issue 3) on the 2-core dev machine: <= 3 s wall and <= 400 MB peak RSS. The wall
time is that of ``generate_dataset`` (sampling, curves, writing, fsync); the import time of
the package (torch, scipy) is printed separately. The peak RSS (ru_maxrss) covers the whole
process, imports included. The process CPU time is printed too: on a shared machine it says
more than the wall time. --threads T sets torch's thread count, which generate_dataset turns
into min(4, T) curve workers of one thread each.
"""

from __future__ import annotations

import argparse
import resource
import sys
import tempfile
import time
from pathlib import Path

t_import = time.perf_counter()
import torch  # noqa: E402

from metainterface.data import generate_dataset  # noqa: E402
from metainterface.physics import CellSettings  # noqa: E402
from metainterface.runtime import tune_allocator  # noqa: E402

t_import = time.perf_counter() - t_import


def _peak_mb() -> float:
    kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return kb / 1024 if sys.platform != "darwin" else kb / 2**20


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--samples 2000"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=100_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", help="folder for the file (default: a temporary one)")
    parser.add_argument("--threads", type=int, help="torch threads (default: torch's own)")
    args = parser.parse_args()
    tune_allocator()  # as the CLI does
    if args.threads:
        torch.set_num_threads(args.threads)
    settings = CellSettings()
    with tempfile.TemporaryDirectory(dir=args.out) as tmp:
        path = Path(tmp) / "bench.npz"
        mb_before = _peak_mb()
        cpu0, t0 = time.process_time(), time.perf_counter()
        generate_dataset(args.samples, args.seed, settings, path, progress=False)
        wall, cpu = time.perf_counter() - t0, time.process_time() - cpu0
        size = path.stat().st_size / 2**20
    print(f"import metainterface: {t_import:.2f} s, peak RSS after import {mb_before:.0f} MB")
    print(
        f"generate {args.samples} samples: {wall:.2f} s wall, {cpu:.2f} s CPU "
        f"({min(4, torch.get_num_threads())} curve workers), {args.samples / wall:,.0f} samples/s, "
        f"file {size:.0f} MiB, peak RSS {_peak_mb():.0f} MB"
    )


if __name__ == "__main__":
    main()
