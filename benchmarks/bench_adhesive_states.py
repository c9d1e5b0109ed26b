"""Which BEM states the adhesive check compares (issue 38): the sampled running maximum
alone against it with the model's snap-in loads (``verify.adhesive.clear_of_snap_ins``).

Random 9-asperity cells (heights in [0, 0.3] Delta_max, so snap-ins crowd the low loads),
w = 50 mJ/m^2 on PDMS at R = 0.5 mm, the JKR-limit BEM by 2 K approaches as the check
loads it; per cell the states kept and the largest |alpha_bem / alpha_model - 1| and the
relative L2 over them (the adhesive model, load control).

    PYTHONPATH=src python benchmarks/bench_adhesive_states.py [--grid 96] [--loads 12]
        [--seeds 0 16] [--model independent|interacting]
"""

from __future__ import annotations

import argparse

import numpy as np
import torch

import metainterface as mi
from metainterface.physics import CellSettings, Design
from metainterface.validation.adhesive_path import jkr_path
from metainterface.validation.heightmap import height_map
from metainterface.verify.adhesive import APPROACHES_PER_LOAD, approaches, clear_of_snap_ins

W = 0.05 / (2.4e6 * 0.5e-3)


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--grid 48 --loads 4 --seeds 0 2"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grid", type=int, default=96)
    ap.add_argument("--loads", type=int, default=12)
    ap.add_argument("--seeds", type=int, nargs=2, default=[0, 16])
    ap.add_argument("--model", choices=["independent", "interacting"], default="independent")
    args = ap.parse_args()
    s = CellSettings()
    model = (mi.Independent if args.model == "independent" else mi.Interacting)(adhesion=W)
    worst = {"sampled maximum": [], "with snap-in loads": []}
    for seed in range(*args.seeds):
        rng = np.random.default_rng(seed)
        g = rng.uniform(1.8, 4.0, 9)
        h = rng.uniform(0, 0.3, 9) * s.delta_max
        h -= h.min()
        design = Design(gamma=g, h=h, settings=s)
        top = 0.95 * model.model_curve(design).p_star_max
        deltas = approaches(design, model, top, APPROACHES_PER_LOAD * args.loads)
        hm = height_map(design, args.grid)
        path = jkr_path(hm.heights, hm.cell_side, W * s.e_star * s.radius, deltas, owner=hm.owner)
        clear = clear_of_snap_ins(path.p_star, path.touching, model.touch_loads(design))
        gt, ht = design.tensors(torch.float64)
        loads = torch.as_tensor(np.maximum(path.p_star, 1e-30))[None]
        with torch.no_grad():
            mod = model.alpha_at_loads(gt, ht, s, loads)[0].numpy()
        line = [f"seed {seed:2d}"]
        for name, keep in zip(worst, (path.on_branch, path.on_branch & clear), strict=True):
            r = np.abs(path.alpha[keep] / mod[keep] - 1).max()
            l2 = np.linalg.norm(path.alpha[keep] - mod[keep]) / np.linalg.norm(mod[keep])
            worst[name].append(r)
            line.append(
                f"{name}: {int(keep.sum()):2d} states, max {100 * r:5.1f} %, L2 {100 * l2:4.1f} %"
            )
        print(" | ".join(line), flush=True)
    for name, r in worst.items():
        r = np.array(r)
        print(
            f"{name}: median of the cells' largest {100 * np.median(r):.1f} %, worst "
            f"{100 * r.max():.1f} %, cells above 20 %: {int((r > 0.2).sum())} of {r.size}"
        )


if __name__ == "__main__":
    main()
