"""What a long target costs: `metainterface design` on a CSV target of many rows.

Measures the command as a user runs it (a fresh process): wall time, the design step's own
seconds (from the summary table), and the size of every file written. The target is stored
once, decimated, in design.json, so the files should not grow with the target's rows.
Run: python benchmarks/bench_outputs.py [--rows 100000] [--html]
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--rows 1000"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, default=100_000)
    ap.add_argument("--html", action="store_true", help="also write the HTML view")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        csv = Path(tmp) / "long.csv"
        p = np.linspace(0.0, 0.002, args.rows)
        a = 0.04 * (1 - np.exp(-p / 6e-4))
        np.savetxt(csv, np.c_[p, a], delimiter=",", header="p_star,alpha", comments="")
        out = Path(tmp) / "out"
        cmd = [sys.executable, "-m", "metainterface", "design", "--target-csv", str(csv)]
        cmd += ["--out", str(out), *(["--html"] if args.html else [])]
        load = os.getloadavg()[0]
        t0 = time.perf_counter()
        done = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if done.returncode not in (0, 3):  # 3: BEM error above --max-bem-error, files written
            raise SystemExit(f"design failed (exit {done.returncode}):\n{done.stderr}")
        row = next(line for line in done.stdout.splitlines() if line.startswith("long"))
        print(f"target CSV: {args.rows} rows, {csv.stat().st_size / 1e6:.2f} MB")
        step = row.split()[-1]
        print(
            f"wall {wall:.1f} s (load average before {load:.1f}); design step {step} s; "
            f"exit {done.returncode}"
        )
        for f in sorted(out.iterdir()):
            print(f"  {f.name}: {f.stat().st_size / 1e3:.1f} kB")


if __name__ == "__main__":
    main()
