"""How fast the command line answers before any work: `--help`, a subcommand's help, an
argument error, and `import metainterface`, each in a fresh process as a user runs them.

The goal (issue 30) is <= 0.5 s for `--help` and a bad option on the 2-core machine; the
table also shows `python -c pass` (the interpreter's own start) and `import torch` for scale.
Run: python benchmarks/bench_cli_startup.py [--repeat 7] [--out benchmarks/results/cli_startup.md]
"""

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

CASES = {
    "python -c pass": ["-c", "pass"],
    "import metainterface": ["-c", "import metainterface"],
    "metainterface --help": ["-m", "metainterface", "--help"],
    "metainterface design --help": ["-m", "metainterface", "design", "--help"],
    "metainterface design --bogus (error)": ["-m", "metainterface", "design", "--bogus"],
    "metainterface validate --grid -5 (error)": [
        "-m",
        "metainterface",
        "validate",
        "x.json",
        "--grid",
        "-5",
    ],
    "import torch (for scale)": ["-c", "import torch"],
}


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--repeat 1"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--out", type=Path, default=None, help="also write the table here (.md)")
    args = ap.parse_args()
    load = os.getloadavg()[0]
    rows = []
    for label, argv in CASES.items():
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            subprocess.run([sys.executable, *argv], capture_output=True, check=False)
            times.append(time.perf_counter() - t0)
        rows.append((label, statistics.median(times), min(times)))
    lines = [
        f"`python benchmarks/bench_cli_startup.py {' '.join(sys.argv[1:])}`",
        "",
        f"Fresh-process wall time, median and best of {args.repeat} "
        f"(load average before: {load:.1f}, {os.cpu_count()} cores)",
        "",
        "| command | median [s] | best [s] |",
        "| --- | ---: | ---: |",
        *(f"| `{label}` | {med:.3f} | {best:.3f} |" for label, med, best in rows),
    ]
    text = "\n".join(lines)
    print(text)
    if args.out is not None:
        args.out.write_text(text + "\n")


if __name__ == "__main__":
    main()
