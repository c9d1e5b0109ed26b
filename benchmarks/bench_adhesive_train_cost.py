"""What training a surrogate that reads adhesive targets would cost (issue 38, item 2).

Per batch of B designs, in one process (compare as ratios):
  gen-adh / gen-plain : the loading curves of B random cells, no grad (dataset generation)
  step-plain : one training step of the shipped MLP through the adhesionless physics layer
               (its `law_error`-like loss: alpha at the target's 128 pressures), fwd + bwd
  step-adh   : the same step through the adhesive physics layer (the JKR sweep, 64 Delta
               samples, alpha interpolated at the target's pressures), fwd + bwd

    OMP_NUM_THREADS=1 PYTHONPATH=src python benchmarks/bench_adhesive_train_cost.py [B] [REPS]
"""

from __future__ import annotations

import sys
import time

import torch

import metainterface as mi
from metainterface.inverse.params import FULL
from metainterface.inverse.starts import random_starts
from metainterface.physics import CellSettings
from metainterface.physics.curves import features_from_points
from metainterface.physics.metrics import interp, relative_l2
from metainterface.surrogate.checkpoint import default_model_path, load_model

W = 4.2e-5


def timed(fn, reps: int):
    """(mean seconds of ``reps`` calls after one warm-up, the last result)."""
    fn()
    t = time.perf_counter()
    for _ in range(reps):
        out = fn()
    return (time.perf_counter() - t) / reps, out


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "64 1"


def main() -> None:
    s = CellSettings()
    b = int(sys.argv[1]) if len(sys.argv) > 1 else 512
    reps = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    g, h = random_starts(b, 1, s, 0, FULL)
    model, _, _ = load_model(default_model_path())

    def gen(adh):
        with torch.no_grad():
            return mi.Independent(adhesion=adh).load_area(g, h, s, n_delta=128)

    t_gen_p, sw_p = timed(lambda: gen(0.0), reps)
    t_gen_a, sw_a = timed(lambda: gen(W), reps)
    print(
        f"data  B={b}: plain {t_gen_p:.3f} s, adhesive {t_gen_a:.3f} s (x{t_gen_a / t_gen_p:.1f})"
    )

    def step(sw, adh, n_delta):
        p_t, a_t = sw.p_star, sw.alpha
        feats = features_from_points(p_t, a_t, s.n_steps).float()
        grid = torch.linspace(0, 1, s.n_steps, dtype=torch.float64)[None] * p_t[:, -1:]
        target = interp(grid, p_t, a_t)
        fm = mi.Independent(adhesion=adh)

        def run():
            model.train()
            model.zero_grad(set_to_none=True)
            gp, hp = model.design(feats, s)
            alpha, _ = fm.alpha_at(gp.double(), hp.double(), s, grid, n_delta=n_delta)
            loss = relative_l2(alpha, target).mean()
            loss.backward()
            return float(loss.detach())

        return run

    t_p, l_p = timed(step(sw_p, 0.0, 64), reps)
    t_a, l_a = timed(step(sw_a, W, 64), reps)
    print(
        f"step  B={b}: plain {t_p:.3f} s (loss {l_p:.3f}), adhesive {t_a:.3f} s "
        f"(loss {l_a:.3f}) (x{t_a / t_p:.1f})"
    )


if __name__ == "__main__":
    main()
