"""BEM contact area: sub-pixel edges (``bem.contact_area``) against the plain count.

One power-law asperity (N = 1, default cell) per gamma in 1.8, 2, 3, 4, solved by Tamaas at
M x M (default 256) at loads that give contact radii of 10-30 grid steps by Sneddon's closed
form: F = 2 gamma / (gamma + 1) kappa c a^(gamma + 1), kappa = sqrt(pi) G(gamma/2 + 1) /
G((gamma + 1)/2), c = 1/2 (R = E* = 1). Prints alpha / alpha_Sneddon - 1 of both measures.
Run: python benchmarks/bench_contact_area.py [--grid 256]
"""

import argparse
import math

import numpy as np

from metainterface.physics import CellSettings, Design
from metainterface.validation import solve_path
from metainterface.validation.heightmap import height_map

RADII = np.array([10.0, 14.0, 18.0, 22.0, 26.0, 30.0])  # grid steps


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--grid 64"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--grid", type=int, default=256)
    args = ap.parse_args()
    m = args.grid
    print(f"grid {m} x {m}; contact radius [grid steps]: " + ", ".join(f"{r:g}" for r in RADII))
    for gamma in (1.8, 2.0, 3.0, 4.0):
        design = Design(
            gamma=np.array([gamma]), h=np.array([0.0]), settings=CellSettings(n_asperities=1)
        )
        hm = height_map(design, m)
        side = hm.cell_side
        kappa = math.sqrt(math.pi) * math.gamma(gamma / 2 + 1) / math.gamma((gamma + 1) / 2)
        radii = RADII * side / m
        loads = 2 * gamma / (gamma + 1) * kappa * 0.5 * radii ** (gamma + 1) / side**2
        path = solve_path(hm.heights, side, loads, hm.owner, 1)
        exact = math.pi * radii**2 / side**2
        for label, alpha in (("sub-pixel", path.alpha), ("count", path.alpha_pixels)):
            err = ", ".join(f"{100 * e:+.2f}" for e in alpha / exact - 1)
            print(f"gamma {gamma:g}  {label:<9} alpha / alpha_Sneddon - 1 [%]: {err}")


if __name__ == "__main__":
    main()
