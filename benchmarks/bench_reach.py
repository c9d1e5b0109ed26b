"""One answer on reach (issue 39): do ``reachability`` and ``feasible_scale``'s test agree,
and how do the laws they pass design?

Random power laws alpha = top (P*/P*_max)^m (16-20 points, P*_max up to the cell's largest
pressure) whose top point lies from a little below the exact pointwise bounds to a little
above them, the region where the package's two envelopes used to disagree. Prints how many
laws each verdict passes, how many the two verdicts disagree on, and (``--design K``) the
design error of K laws against the verdict.

    python benchmarks/bench_reach.py [--laws 3000] [--design 48]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import metainterface as mi
from metainterface._testing import borderline_laws
from metainterface.inverse.verdict import law_reachability as reachability
from metainterface.physics import CellSettings
from metainterface.scaling.search import violation


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--laws", type=int, default=3000)
    ap.add_argument("--design", type=int, default=0, help="design this many laws (0: none)")
    args = ap.parse_args()
    s = CellSettings()
    t0 = time.perf_counter()
    pairs = borderline_laws(args.laws, points=20, smallest=0.05, seed=0)
    a = np.array([reachability(p, al, settings=s, units=False).reachable for p, al in pairs])
    b = np.array([violation(p[None], al[None], s)[1][0] == 0 for p, al in pairs])
    print(
        f"{args.laws} laws: reachability passes {a.sum()}, feasible_scale's test {b.sum()}, "
        f"disagree on {(a != b).sum()} ({time.perf_counter() - t0:.1f} s)"
    )
    if args.design:
        chosen = pairs[: args.design]
        targets = [
            mi.Target(p_star=np.r_[0, p], alpha=np.r_[0, al], name=f"law{i}")
            for i, (p, al) in enumerate(chosen)
        ]
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", mi.ReachWarning)
            errors = np.array([r.error for r in mi.design(targets, verify=False)])
        passed = a[: args.design]
        for name, mask in (("passed", passed), ("refused", ~passed)):
            if mask.any():
                e = 100 * errors[mask]
                print(
                    f"designs of the {mask.sum()} laws the test {name}: error median "
                    f"{np.median(e):.2f} %, worst {e.max():.1f} %, under 2 %: "
                    f"{int((e < 2).sum())}"
                )


if __name__ == "__main__":
    main()
