"""The package's torch work on each device (issue 29): one table, one column per device.

Rows: a 100k-sample dataset; one training epoch on it (batch 1024, the shipped model's
pair with lr 2e-3); a 500-epoch training; one design (``mi.design("saturating")``, CLI
defaults); designs per second for K targets designed in one call (K realisable targets:
exact curves of random cells, as in bench_design.py; CLI defaults: surrogate, 8 hedge
starts, 50-start fallback); a 4096-sample tolerance study of that design.

The 500-epoch row is measured only with --full-training; otherwise it is 500 times the
mean epoch time of --epochs measured epochs (each with its validation pass and checkpoint),
and the table says so. K above --max-k is not run: its figure is the rate of the largest K
run, marked as extrapolated. A device that torch does not see gets "unmeasured" and the
reason. Each timed step is run once after a warm-up (the surrogate loaded, caches built).

Run: python benchmarks/bench_devices.py [--quick | --smoke] [--max-k 1000]
     [--out results/devices.md]
"""

from __future__ import annotations

import argparse
import platform
import sys
import tempfile
import time
from pathlib import Path

import torch

import metainterface as mi
from metainterface.runtime import tune_allocator

sys.path.insert(0, str(Path(__file__).parent))
from bench_design import realisable_targets

ROWS = (
    "dataset 100k",
    "one training epoch",
    "500-epoch training",
    "one design",
    "designs/s, K = 1",
    "designs/s, K = 10",
    "designs/s, K = 100",
    "designs/s, K = 1000",
    "tolerance, 4096 samples",
)


def _sync(device: str) -> None:
    if device.startswith("cuda"):
        torch.cuda.synchronize()


def timed(fn, *args, **kwargs) -> tuple[float, object]:
    """Wall seconds of ``fn(*args, **kwargs)`` (on a GPU, until its work is done)."""
    _sync(kwargs["device"])
    t0 = time.perf_counter()
    out = fn(*args, **kwargs)
    _sync(kwargs["device"])
    return time.perf_counter() - t0, out


def measure(device: str, args: argparse.Namespace, work: Path) -> dict[str, str]:
    """Every row's figure on ``device`` (text for the table)."""
    cells: dict[str, str] = {}
    samples = args.samples
    data = work / f"{device.replace(':', '_')}.npz"
    mi.generate_dataset(2000, work / "warm.npz", seed=1, progress=False, device=device)
    t, _ = timed(mi.generate_dataset, samples, data, seed=0, progress=False, device=device)
    cells["dataset 100k"] = f"{t:.2f} s" + ("" if samples == 100_000 else f" ({samples} samples)")
    print(f"{device}: dataset {samples}: {t:.2f} s", flush=True)

    epochs = 500 if args.full_training else args.epochs
    cfg = mi.TrainConfig(epochs=epochs, batch_size=1024, lr=2e-3)
    t, run = timed(
        mi.train_surrogate,
        data,
        work / f"run-{device.replace(':', '_')}",
        cfg,
        progress=False,
        device=device,
    )
    from metainterface.surrogate.run_state import read_metrics

    per_epoch = read_metrics(run.run_dir)["seconds"]
    epoch = float(per_epoch.mean())
    cells["one training epoch"] = f"{epoch:.2f} s (mean of {len(per_epoch)})"
    if args.full_training:
        cells["500-epoch training"] = f"{t:.0f} s ({run.epochs_run} epochs run)"
    else:
        cells["500-epoch training"] = f"{500 * epoch:.0f} s (extrapolated: 500 x epoch)"
    print(f"{device}: epoch {epoch:.2f} s", flush=True)

    check = {"verify": False} if args.smoke else {}
    mi.design("saturating", device=device, **check)  # warm-up: the surrogate, the envelope cache
    t, one = timed(mi.design, "saturating", device=device, **check)
    cells["one design"] = f"{t:.2f} s"
    print(f"{device}: one design {t:.2f} s", flush=True)

    rate = None
    for k in (1, 10, 100, 1000):
        row = f"designs/s, K = {k}"
        if k > args.max_k:
            cells[row] = f"{rate:.2f} (extrapolated: rate at K = {args.max_k})"
            continue
        targets = realisable_targets(k, seed=11)
        t, _ = timed(mi.design, targets, device=device, **check)
        rate = k / t
        cells[row] = f"{rate:.2f} ({t:.1f} s)"
        print(f"{device}: K = {k}: {t:.1f} s, {rate:.2f} designs/s", flush=True)

    mi.tolerance(one, sigma_h=0.002, sigma_gamma=0.05, samples=64, device=device)
    n = 256 if args.smoke else 4096
    t, _ = timed(mi.tolerance, one, sigma_h=0.002, sigma_gamma=0.05, samples=n, device=device)
    cells["tolerance, 4096 samples"] = f"{t:.2f} s" + ("" if n == 4096 else f" ({n} samples)")
    print(f"{device}: tolerance {n}: {t:.2f} s", flush=True)
    return cells


def machine(device: str) -> str:
    if device.startswith("cuda"):
        return torch.cuda.get_device_name(torch.device(device))
    name = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                name = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{name}, {torch.get_num_threads()} torch thread(s)"


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--smoke"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="5k samples, 2 epochs, K <= 10")
    ap.add_argument(
        "--smoke",
        action="store_true",
        help="2k samples, 1 epoch, K = 1, no BEM check, 256 tolerance samples: a check that "
        "the script runs (benchmarks/run.py's quick mode), its figures mean nothing",
    )
    ap.add_argument("--samples", type=int, default=100_000, help="dataset size (100000)")
    ap.add_argument("--epochs", type=int, default=3, help="epochs measured (3)")
    ap.add_argument("--full-training", action="store_true", help="run all 500 epochs")
    ap.add_argument("--max-k", type=int, default=1000, help="largest K run (1000)")
    ap.add_argument("--devices", default="cpu,cuda", help="columns (cpu,cuda)")
    ap.add_argument("--out", help="write the markdown table here")
    args = ap.parse_args()
    if args.quick:
        args.samples, args.epochs, args.max_k = 5000, 2, 10
    if args.smoke:
        args.samples, args.epochs, args.max_k = 2000, 1, 1
    tune_allocator()
    columns: dict[str, dict[str, str]] = {}
    where: dict[str, str] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for device in args.devices.split(","):
            if device.startswith("cuda") and not torch.cuda.is_available():
                columns[device] = {r: "unmeasured" for r in ROWS}
                where[device] = "unmeasured: no GPU lent to this task (torch sees no CUDA device)"
                continue
            columns[device] = measure(device, args, Path(tmp))
            where[device] = machine(device)
    head = "| | " + " | ".join(columns) + " |"
    lines = [head, "|---" * (len(columns) + 1) + "|"]
    lines += [f"| {r} | " + " | ".join(c[r] for c in columns.values()) + " |" for r in ROWS]
    table = "\n".join(lines)
    print(table)
    if args.out:
        cmd = "python benchmarks/bench_devices.py " + " ".join(sys.argv[1:])
        machines = "\n".join(f"- {d}: {w}" for d, w in where.items())
        Path(args.out).write_text(
            f"# Devices (issue 29)\n\n`{cmd}`; torch {torch.__version__}.\n\n"
            f"Columns:\n\n{machines}\n\n{table}\n\n"
            "One run of each step after a warm-up; OMP_NUM_THREADS as set by the caller. On a "
            "machine shared with other jobs the times are noisy: compare rows as ratios "
            "within one column, not across runs.\n"
        )


if __name__ == "__main__":
    main()
