"""Adhesive networks (issue 38, item 2): w as an input, or a second network that reads the
curve alone? Both are the shipped friction-law network fine-tuned the same way on the same
adhesive targets (``metainterface.surrogate.adhesive``), in the same time budget; then
their zero-shot errors on adhesive targets made from the test cells, beside the shipped
networks' and the floor of the true cells (the targets' own resolution). The variants: w
as an input or not, and the training loss's snap-in window (``TrainConfig.snap_window``),
held or falling to 0 over the run.

    python benchmarks/bench_adhesive_surrogate.py --out RUNS [--dataset ds100k.npz]
        [--samples 100000] [--device cuda] [--budget 240] [--batch-size 1024] [--lr 7e-4]
        [--variants input curve window2 window5 anneal5] [--max-epochs 60]
        [--physics-steps 256] [--evaluate-only] [--eval-cells 2000]

Training: each variant in its own process, all at once (on a GPU they share it: the steps
are launch-bound); one probe epoch sets how many epochs fit ``--budget`` seconds (at most
--max-epochs), then the run starts again from the friction-law network with the cosine
schedule over those epochs. RUNS/<variant>/model.pt are the networks.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import torch

import metainterface as mi
from metainterface.data import load_dataset
from metainterface.surrogate.adhesive import AdhesiveTargets, adhesive_error, adhesive_split
from metainterface.surrogate.build import train_surrogate
from metainterface.surrogate.checkpoint import (
    default_adhesive_model_path,
    default_laws_model_path,
    default_model_path,
    load_model,
)
from metainterface.surrogate.config import TrainConfig
from metainterface.surrogate.data import split_of

#: name -> (w as an input, the loss's snap-in window, whether it falls to 0 over the run)
VARIANTS = {
    "input": (True, 0.0, False),
    "curve": (False, 0.0, False),
    "window2": (True, 0.02, False),
    "window5": (True, 0.05, False),
    "anneal5": (True, 0.05, True),
}
FIELDS = ("alpha_hat", "stiffness_hat", "p_star_max", "alpha_max")
#: Seed of the evaluation targets (apart from training's 0 and 1).
EVAL_SEED = 2002


def config(args, name: str, epochs: int) -> TrainConfig:
    adhesion_input, window, falls = VARIANTS[name]
    return TrainConfig.adhesive(
        epochs=epochs,
        batch_size=args.batch_size,
        lr=args.lr,
        adhesion_input=adhesion_input,
        snap_window=window,
        snap_window_epochs=epochs if falls else 0,
        lambda_start=args.lambda_start,
        curriculum_epochs=min(args.curriculum_epochs, epochs),
        physics_steps=args.physics_steps,
    )


def train_one(args, name: str) -> None:
    """One variant: a probe epoch, then the run sized to the budget."""
    out = Path(args.out)
    t0 = time.perf_counter()
    probe = train_surrogate(
        args.dataset,
        out / f"probe-{name}",
        config(args, name, 1),
        progress=False,
        device=args.device,
    )
    spent = time.perf_counter() - t0
    setup = spent - probe.seconds
    epochs = int(max(1, min(args.max_epochs, (args.budget - spent - setup) / probe.seconds)))
    print(
        f"[{name}] probe: epoch {probe.seconds:.1f} s, setup {setup:.1f} s -> {epochs} epochs",
        flush=True,
    )
    r = train_surrogate(
        args.dataset,
        out / name,
        config(args, name, epochs),
        progress=False,
        device=args.device,
    )
    print(
        f"[{name}] {r.epochs_run} epochs in {r.seconds:.0f} s, best {r.best_val_loss:.3f} "
        f"at epoch {r.best_epoch}",
        flush=True,
    )


def evaluate(args) -> None:
    ds = load_dataset(args.dataset)
    s = ds.settings
    test = split_of(ds, "test")
    keep = torch.arange(min(args.eval_cells, len(test)))
    test = type(test)(
        test.features[keep],
        type(test.targets)(*(getattr(test.targets, f)[keep] for f in FIELDS)),
        test.gamma[keep],
        test.h[keep],
        test.category[keep.numpy()],
    )
    dev = torch.device(
        "cuda" if args.device in ("auto", "cuda") and torch.cuda.is_available() else "cpu"
    )
    split = adhesive_split(
        test, s, EVAL_SEED, adhesion_input=True, spec=AdhesiveTargets(copies=1), device=dev
    )
    idx = torch.arange(len(split))
    feats, targets, g, h = split.rows(idx)
    feats, g, h, w = feats.to(dev), g.to(dev), h.to(dev), split.adhesion.to(dev)
    targets = type(targets)(*(getattr(targets, f).to(dev) for f in FIELDS))
    cats = split.category
    rows = {}

    def record(name: str, err: torch.Tensor) -> None:
        e = err.cpu().numpy()
        rows[name] = {
            str(c): (float(np.median(e[cats == c])), float(np.percentile(e[cats == c], 90)))
            for c in sorted(set(cats))
        }
        rows[name]["all"] = (float(np.median(e)), float(np.percentile(e, 90)))
        print(
            name,
            {k: f"{100 * v[0]:.2f} / {100 * v[1]:.2f} %" for k, v in rows[name].items()},
            flush=True,
        )

    with torch.no_grad():
        record(
            "true cells (the targets' own resolution)",
            adhesive_error(g.double(), h.double(), targets, s, w, n_delta=512),
        )
        nets = {
            "shipped surrogate": default_model_path(),
            "shipped friction-law network": default_laws_model_path(),
            "shipped adhesive network": default_adhesive_model_path(),
        }
        for name in VARIANTS:
            path = Path(args.out) / name / "model.pt"
            if path.is_file():
                nets[f"adhesive, {name}"] = path
        for name, path in nets.items():
            net, _, _ = load_model(path)
            net = net.to(dev)
            x = feats if net.adhesion_input else feats[:, :-1]
            gp, hp = net.design(x, s)
            record(
                name,
                adhesive_error(gp.double(), hp.double(), targets, s, w, n_delta=512),
            )
    header = ["network", *next(iter(rows.values())).keys()]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" + "---:|" * (len(header) - 1)]
    for name, r in rows.items():
        cells = [f"{100 * m:.2f} / {100 * p:.2f} %" for m, p in r.values()]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    table = "\n".join(lines)
    print(
        f"\n{len(split)} adhesive targets from {len(test)} test cells "
        f"(median / p90 relative curve error):\n{table}"
    )
    (Path(args.out) / "evaluation.md").write_text(table + "\n")
    (Path(args.out) / "evaluation.json").write_text(json.dumps(rows, indent=1))


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = (
    "--out {tmp} --samples 1000 --budget 2 --max-epochs 1 --eval-cells 20 --variants input"
    " --physics-steps 32 --batch-size 128"
)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--dataset")
    ap.add_argument("--samples", type=int, default=100_000)
    ap.add_argument("--device", default="auto")
    ap.add_argument("--budget", type=float, default=240.0, help="seconds of training a variant")
    ap.add_argument("--max-epochs", type=int, default=60)
    ap.add_argument("--batch-size", type=int, default=1024)
    ap.add_argument("--lr", type=float, default=7e-4)
    ap.add_argument("--eval-cells", type=int, default=2000)
    ap.add_argument(
        "--lambda-start", type=float, default=0.0, help="the parameter anchor (cut targets' cells)"
    )
    ap.add_argument("--curriculum-epochs", type=int, default=0)
    ap.add_argument("--physics-steps", type=int, default=256)
    ap.add_argument("--evaluate-only", action="store_true")
    ap.add_argument("--variants", nargs="+", choices=list(VARIANTS), default=list(VARIANTS))
    ap.add_argument("--train", choices=list(VARIANTS), help=argparse.SUPPRESS)
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.dataset is None:
        args.dataset = str(out / "dataset.npz")
    if args.train:
        train_one(args, args.train)
        return
    if not args.evaluate_only:
        if not Path(args.dataset).is_file():
            t0 = time.perf_counter()
            mi.generate_dataset(
                args.samples, args.dataset, seed=0, progress=False, device=args.device
            )
            print(
                f"dataset: {args.samples} samples in {time.perf_counter() - t0:.1f} s", flush=True
            )
        base = [sys.executable, __file__, *sys.argv[1:], "--dataset", args.dataset]
        procs = [subprocess.Popen([*base, "--train", name]) for name in args.variants]
        for p in procs:
            p.wait()
    evaluate(args)


if __name__ == "__main__":
    main()
