"""Where the surrogate's zero-shot error comes from, per topography category (issue 4).

1. Reach of the network's height parameterisation: the share of test designs with a gap
   between consecutive heights above the cap G, and how much clipping their gaps to G changes
   their curves (median / p90 relative alpha error), for the paper's G = 2 Delta_max/(N - 1)
   and for G = 0.5, 0.75, 1.0 Delta_max.
2. For a model: the error of the normalised curve alpha_hat alone (shape) against the
   absolute log10 errors of P*_max and alpha_max (magnitudes).

Run: python benchmarks/surrogate_diagnostics.py --dataset ds100k.npz [--model FILE]
     python benchmarks/surrogate_diagnostics.py --samples 100000   (a fresh dataset, seed 0)
"""

import argparse
import tempfile
from pathlib import Path

import numpy as np
import torch

from metainterface import generate_dataset
from metainterface.data import load_dataset
from metainterface.physics.curves import curve
from metainterface.physics.metrics import relative_l2
from metainterface.physics.pressures import alpha_at
from metainterface.surrogate.checkpoint import default_model_path, load_model
from metainterface.surrogate.data import split_of


def reach(ds) -> None:
    s = ds.settings
    paper = 2.0 / (s.n_asperities - 1)
    print("gap cap G / Delta_max | category | designs with a gap > G | clipped: median / p90")
    for cap in (paper, 0.5, 0.75, 1.0):
        for cat in sorted(set(ds.category)):
            d = ds.subset(category=cat)
            gaps = np.diff(d.h, axis=1)
            clipped = np.minimum(gaps, cap * s.delta_max)
            h = np.concatenate([np.zeros((len(d), 1)), np.cumsum(clipped, axis=1)], axis=1)
            p = (
                torch.linspace(0, 1, s.n_steps, dtype=torch.float64)[None]
                * torch.tensor(d.p_star_max, dtype=torch.float64)[:, None]
            )
            a, _ = alpha_at(torch.tensor(d.gamma, dtype=torch.float64), torch.tensor(h), s, p)
            e = relative_l2(
                a, torch.tensor(d.alpha_hat * d.alpha_max[:, None], dtype=torch.float64)
            ).numpy()
            over = (gaps > cap * s.delta_max * (1 + 1e-9)).any(axis=1).mean()
            print(
                f"{cap:.3f} | {cat} | {100 * over:.0f} % | "
                f"{100 * np.median(e):.2f} % / {100 * np.percentile(e, 90):.2f} %"
            )


def shape_and_magnitude(ds, model_path) -> None:
    model, s, _ = load_model(model_path)
    test = split_of(ds, "test")
    with torch.no_grad():
        feats, t, _, _ = test.rows(torch.arange(len(test)))
        g, h = model.design(feats, s)
        c = curve(g.double(), h.double(), s)
    shape = relative_l2(c.alpha_hat, t.alpha_hat.double()).numpy()
    la = (torch.log10(c.alpha_max) - torch.log10(t.alpha_max.double())).abs().numpy()
    lp = (torch.log10(c.p_star_max) - torch.log10(t.p_star_max.double())).abs().numpy()
    print(
        f"\n{model_path}: category | alpha_hat error median | |dlog10 alpha_max| | |dlog10 P*max|"
    )
    for cat in sorted(set(test.category)):
        m = test.category == cat
        print(
            f"{cat} | {100 * np.median(shape[m]):.2f} % | {np.median(la[m]):.4f} | "
            f"{np.median(lp[m]):.4f}"
        )


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--samples 2000"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    source = ap.add_mutually_exclusive_group(required=True)
    source.add_argument("--dataset")
    source.add_argument("--samples", type=int, help="generate a dataset of this size (seed 0)")
    ap.add_argument("--model", default=None, help="default: the shipped surrogate")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = args.dataset
        if path is None:
            path = Path(tmp) / "data.npz"
            generate_dataset(args.samples, path, seed=0, progress=False)
        ds = load_dataset(path)
        reach(ds.subset("test"))
        shape_and_magnitude(ds, args.model or default_model_path())


if __name__ == "__main__":
    main()
