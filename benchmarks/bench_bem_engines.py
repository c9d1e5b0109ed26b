"""BEM engines side by side: Tamaas against our torch engine on the same load paths.

The packaged 9-asperity example design, K ascending loads up to P*_max, on M x M grids
(default 384 and 768, 20 loads): Tamaas (one thread), torch on 1 and 2 CPU threads, and torch
on a CUDA device when torch sees one (else that column says "unmeasured"). Every engine
solves the same height map; the table gives the wall time of the path, the speed-up over
Tamaas and the largest |alpha_torch / alpha_tamaas - 1| over the loads.

Run with OMP_NUM_THREADS=1 (Tamaas on one thread; torch's threads are set here), and on a
machine shared with other busy processes OMP_WAIT_POLICY=PASSIVE (else torch's threads spin
waiting for a descheduled one):

    OMP_NUM_THREADS=1 OMP_WAIT_POLICY=PASSIVE python benchmarks/bench_bem_engines.py
        [--grids 384 768] [--loads 20] [--threads 1 2] [--profile] [--quick]

Writes benchmarks/results/bem_engines.md (not with --quick). Timings depend on what else
runs on the cores: the load average is printed and recorded with them.
"""

from __future__ import annotations

import argparse
import datetime
import os
import time
from importlib.resources import files
from pathlib import Path

import numpy as np

from metainterface.physics import Design
from metainterface.physics.registry import get_model
from metainterface.validation import solve_path, torch_threads
from metainterface.validation.heightmap import height_map

RESULTS = Path(__file__).parent / "results" / "bem_engines.md"
#: Environment variables recorded with the command (they change what the threads do).
ENV = ("OMP_NUM_THREADS", "OMP_WAIT_POLICY")
EXAMPLE = files("metainterface") / "examples" / "example_design.json"


def _path(hm, loads, n, engine, device="cpu", threads=None):
    t0 = time.perf_counter()
    path = solve_path(
        hm.heights, hm.cell_side, loads, hm.owner, n, engine=engine, device=device, threads=threads
    )
    return path, time.perf_counter() - t0


def profile(grid: int) -> str:
    """torch.profiler's table for 20 iterations of one solve (one thread)."""
    import torch
    from torch.profiler import ProfilerActivity
    from torch.profiler import profile as prof

    from metainterface.validation import torch_bem as tb

    design = Design.load(EXAMPLE)
    hm = height_map(design, grid)
    load = get_model().model_curve(design).p_star_max / 2
    z = torch.as_tensor(hm.heights)[None]
    kernel = (tb.unit_kernel(grid, torch.device("cpu")) * hm.cell_side)[None]
    with torch_threads(1):
        args = (z, kernel, torch.tensor([load]), None)
        tb.solve_batch(*args, tolerance=1e-11, max_iter=5)
        with prof(activities=[ProfilerActivity.CPU]) as p:
            tb.solve_batch(*args, tolerance=1e-11, max_iter=20)
    return p.key_averages().table(sort_by="self_cpu_time_total", row_limit=12)


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--quick"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--grids", type=int, nargs="+", default=[384, 768])
    ap.add_argument("--loads", type=int, default=20)
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--profile", action="store_true", help="print torch.profiler's table first")
    ap.add_argument("--quick", action="store_true", help="one 96 x 96 path of 3 loads, no file")
    ap.add_argument(
        "--engines",
        nargs="+",
        choices=["tamaas", "cpu", "gpu"],
        default=["tamaas", "cpu", "gpu"],
        help="columns to run (the others read 'unmeasured'); a GPU timing alone, with no other "
        "engine's work on the machine: --engines gpu",
    )
    args = ap.parse_args()
    import torch

    from metainterface.validation.bem import require_tamaas

    if args.quick:
        args.grids, args.loads, args.threads = [96], 3, [1]
    if args.profile:
        print(profile(args.grids[0]))
    try:
        require_tamaas()
        have_tamaas = "tamaas" in args.engines
    except Exception:
        have_tamaas = False
    gpu = torch.cuda.is_available() and "gpu" in args.engines
    if "cpu" not in args.engines:
        args.threads = []
    design = Design.load(EXAMPLE)
    loads = get_model().model_curve(design).p_star_max * np.arange(1, args.loads + 1) / args.loads
    cols = ["Tamaas (1 thread)"] + [f"torch CPU, {t} thread{'s' * (t > 1)}" for t in args.threads]
    cols.append("torch GPU")
    rows = []
    for grid in args.grids:
        hm = height_map(design, grid)
        load_before = os.getloadavg()[0]
        times: dict[str, float | None] = {}
        alphas: dict[str, np.ndarray] = {}
        if have_tamaas:
            path, times[cols[0]] = _path(hm, loads, design.n_asperities, "tamaas")
            alphas[cols[0]] = path.alpha
        for t, col in zip(args.threads, cols[1:-1], strict=True):
            path, times[col] = _path(hm, loads, design.n_asperities, "torch", "cpu", t)
            alphas[col] = path.alpha
        if gpu:
            _path(hm, loads[:1], design.n_asperities, "torch", "cuda")  # warm-up (CUDA, FFT plans)
            path, times[cols[-1]] = _path(hm, loads, design.n_asperities, "torch", "cuda")
            alphas[cols[-1]] = path.alpha
        ref = alphas.get(cols[0])
        row = {"grid": grid, "load_before": load_before, "load_after": os.getloadavg()[0]}
        for col in cols:
            sec = times.get(col)
            dev = None
            if ref is not None and col in alphas and col != cols[0]:
                dev = float(np.abs(alphas[col] / ref - 1).max())
            row[col] = (sec, dev)
        rows.append(row)
        print(f"{grid} x {grid}, {args.loads} loads (load average {load_before:.1f} before):")
        base = times.get(cols[0])
        for col in cols:
            sec, dev = row[col]
            if sec is None:
                print(f"  {col:24s} unmeasured")
                continue
            speed = f"{base / sec:5.2f}x" if base else "  -  "
            devs = "" if dev is None else f", max |alpha / alpha_tamaas - 1| = {dev:.1e}"
            print(f"  {col:24s} {sec:8.1f} s  {speed}{devs}")
    if args.quick:
        return
    lines = [
        "# BEM engines: Tamaas and the torch engine on the same load paths",
        "",
        f"Command ({datetime.date.today()}, {os.cpu_count()} cores, torch {torch.__version__}):",
        "",
        "```bash",
        " ".join(f"{v}={os.environ[v]}" for v in ENV if v in os.environ)
        + " python benchmarks/bench_bem_engines.py "
        f"--grids {' '.join(map(str, args.grids))} --loads {args.loads} "
        f"--threads {' '.join(map(str, args.threads))}",
        "```",
        "",
        f"The packaged 9-asperity example, {args.loads} loads uniform up to P*_max, tolerance "
        "1e-11 (both engines measure convergence alike). Wall time of the whole path [s], "
        "speed-up over Tamaas, and the largest |alpha_torch / alpha_tamaas - 1| over the loads.",
        "",
        "| grid | " + " | ".join(cols) + " | load average before / after |",
        "| --- | " + " | ".join("---:" for _ in cols) + " | ---: |",
    ]
    for row in rows:
        base = row[cols[0]][0]
        cells = []
        for col in cols:
            sec, dev = row[col]
            if sec is None:
                cells.append("unmeasured (no GPU here)" if col == cols[-1] else "n/a")
                continue
            text = f"{sec:.1f} s"
            if base and col != cols[0]:
                text += f" ({base / sec:.1f}x; dev {dev:.0e})"
            cells.append(text)
        lines.append(
            f"| {row['grid']}^2 | "
            + " | ".join(cells)
            + f" | {row['load_before']:.1f} / {row['load_after']:.1f} |"
        )
    RESULTS.parent.mkdir(exist_ok=True)
    text = "\n".join(lines) + "\n"
    if RESULTS.exists():  # keep the notes written by hand below the table
        old = RESULTS.read_text()
        marker = "\n## Notes"
        if marker in old:
            text += old[old.index(marker) :]
    RESULTS.write_text(text)
    print(f"wrote {RESULTS}")


if __name__ == "__main__":
    main()
