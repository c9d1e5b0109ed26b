"""Zero-shot quality of a surrogate on the test split, per topography category.

Relative curve error: ||alpha_pred - alpha_true||_2 / ||alpha_true||_2 on the 128-point
pressure grid of each test curve, alpha_pred from the exact forward model of the predicted
design (held at its last value beyond its P*_max). Also the absolute errors of log10 P*_max and
log10 alpha_max, and the train/test loss gap (exact physics, eval mode).

A friction-law network (trained with ``reads="laws"``), or an adhesive one
(``reads="adhesive"``: errors of the adhesive loading curves at each target's work of
adhesion), is evaluated on targets made from the test split's cells the way it was trained
(``metainterface.surrogate.laws``, ``metainterface.surrogate.adhesive``), per kind, with
alpha solved exactly at each target pressure (cut targets may span a few of the design's
own grid steps); the log10 errors, which compare a law's end with the design's Delta_max,
are not reported for them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import torch

from metainterface.physics.cell import CellSettings
from metainterface.physics.curves import curve
from metainterface.physics.metrics import relative_l2
from metainterface.physics.pressures import alpha_at
from metainterface.surrogate.adhesive import adhesive_error
from metainterface.surrogate.data import Split
from metainterface.surrogate.loss import PAPER_WEIGHTS, LossWeights
from metainterface.surrogate.model import InverseMLP
from metainterface.surrogate.train import evaluate_loss


@dataclass(frozen=True)
class Predictions:
    """Per test sample: relative curve error, log10 errors; predicted designs (S, N)."""

    category: np.ndarray
    curve_error: np.ndarray
    log_p_error: np.ndarray
    log_alpha_error: np.ndarray
    gamma: np.ndarray
    h: np.ndarray


def predict_split(
    model: InverseMLP, split: Split, settings: CellSettings, chunk: int = 2048, exact: bool = False
) -> Predictions:
    """The model's designs for a split's targets and their errors (``exact``: alpha solved
    at each target pressure, else interpolated in the design's own sweep)."""
    model.eval()
    errs, lp, la, gs, hs = [], [], [], [], []
    with torch.no_grad():
        for lo in range(0, len(split), chunk):
            idx = torch.arange(lo, min(lo + chunk, len(split)))
            feats, t, _, _ = split.rows(idx)
            gamma, h = model.design(feats, settings)
            gamma, h = gamma.double(), h.double()
            if split.adhesion is not None:  # adhesive targets: their loading curves
                w = split.adhesion_rows(idx)
                errs.append(adhesive_error(gamma, h, t, settings, w, n_delta=512).numpy())
                lp.append(np.full(len(idx), np.nan))
                la.append(np.full(len(idx), np.nan))
            else:
                p_grid = (
                    torch.linspace(0, 1, settings.n_steps, dtype=torch.float64)[None]
                    * t.p_star_max.double()[:, None]
                )
                alpha_true = t.alpha_hat.double() * t.alpha_max.double()[:, None]
                alpha_pred, _ = alpha_at(gamma, h, settings, p_grid, exact=exact)
                errs.append(relative_l2(alpha_pred, alpha_true).numpy())
                c = curve(gamma, h, settings)
                for out, have, want in (
                    (lp, c.p_star_max, t.p_star_max),
                    (la, c.alpha_max, t.alpha_max),
                ):
                    out.append((torch.log10(have) - torch.log10(want.double())).abs().numpy())
            gs.append(gamma.numpy())
            hs.append(h.numpy())
    cat = np.concatenate
    return Predictions(split.category, cat(errs), cat(lp), cat(la), cat(gs), cat(hs))


def evaluate(
    model: InverseMLP,
    train: Split,
    test: Split,
    settings: CellSettings,
    weights: LossWeights = PAPER_WEIGHTS,
    reads: str = "curves",
) -> dict:
    """The evaluation table: per category and overall, plus the train/test loss gap (the
    loss with ``weights``: those the model was trained with, see :func:`weights_of`).
    ``reads="laws"``: the splits hold friction-law-like targets (categories: their kinds);
    ``"adhesive"``: adhesive targets (categories: the decade of their work of adhesion)."""
    laws = reads in ("laws", "adhesive")
    pred = predict_split(model, test, settings, exact=laws)
    rows = {}
    for name in [*sorted(set(pred.category.tolist())), "all"]:
        m = np.ones_like(pred.curve_error, bool) if name == "all" else pred.category == name
        rows[name] = {
            "samples": int(m.sum()),
            "median_curve_error": float(np.median(pred.curve_error[m])),
            "p90_curve_error": float(np.percentile(pred.curve_error[m], 90)),
            "mean_abs_log10_p_star_max_error": math.nan
            if laws
            else float(pred.log_p_error[m].mean()),
            "mean_abs_log10_alpha_max_error": math.nan
            if laws
            else float(pred.log_alpha_error[m].mean()),
        }
    train_loss = evaluate_loss(model, train, settings, weights, reads=reads)
    test_loss = evaluate_loss(model, test, settings, weights, reads=reads)
    return {
        "reads": reads,
        "categories": rows,
        "train_loss": train_loss,
        "test_loss": test_loss,
        "loss_gap": (test_loss - train_loss) / train_loss,
    }


def format_table(result: dict) -> str:
    """A markdown table of an :func:`evaluate` result."""
    lines = [
        "| category | samples | median curve error | p90 curve error "
        "| abs log10 P*max err | abs log10 alpha_max err |",
        "| --- | ---: | ---: | ---: | ---: | ---: |",
    ]

    def log_error(x: float) -> str:
        return "n/a" if math.isnan(x) else f"{x:.4f}"

    for name, r in result["categories"].items():
        lines.append(
            f"| {name} | {r['samples']} | {100 * r['median_curve_error']:.3g} % | "
            f"{100 * r['p90_curve_error']:.3g} % | "
            f"{log_error(r['mean_abs_log10_p_star_max_error'])} | "
            f"{log_error(r['mean_abs_log10_alpha_max_error'])} |"
        )
    lines.append(
        f"\ntrain loss {result['train_loss']:.4f}, test loss {result['test_loss']:.4f}, "
        f"gap {100 * result['loss_gap']:+.2f} %"
    )
    return "\n".join(lines)
