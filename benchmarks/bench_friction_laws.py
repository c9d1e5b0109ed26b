"""The surrogate's zero-shot error on friction laws (issue 28): targets without stiffness.

50 friction laws in newtons, seeded, in four families (Amontons with an offset, saturating,
power laws, bilinear), each turned into an alpha(P*) target at the scale that makes it
reachable (``mi.feasible_scale``: the middle of the widest feasible area range, else of the
modulus range, else the closest scale), 40 rows each, no stiffness column: what a user's
``--friction-csv`` gives. Reported: the zero-shot relative curve error of the surrogate
(``design(refine=False, hedge=0, fallback=0)``) per family, and, as the reference the
network was trained for, the same on --cells exact curves of random cells given with their
stiffness and without it. Optionally the refined error (``--refine``, the CLI's defaults).

Run: python benchmarks/bench_friction_laws.py [--laws 50] [--out results/friction_laws.md]
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import metainterface as mi
from metainterface.physical.friction import FrictionLaw, friction_target

sys.path.insert(0, str(Path(__file__).parent))

FAMILIES = ("amontons-offset", "saturating", "power", "bilinear")
TAU, E_STAR, RADIUS, AREA = 0.25e6, 2e6, 0.5e-3, 4e-4
ROWS = 40


def make_law(family: str, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """(F_n, F_f) (ROWS,) [N] of one law of the family, random parameters."""
    top = rng.uniform(2.0, 20.0)  # largest normal force [N]
    fn = np.linspace(top / ROWS, top, ROWS)
    if family == "amontons-offset":  # F_f = mu F_n + an offset that builds up quickly
        mu, off, f1 = rng.uniform(0.1, 0.6), rng.uniform(0.05, 0.4), rng.uniform(0.03, 0.2)
        ff = mu * fn + off * top * (1 - np.exp(-fn / (f1 * top)))
    elif family == "saturating":
        fs, fc = rng.uniform(0.2, 0.8) * top, rng.uniform(0.15, 0.6) * top
        ff = fs * (1 - np.exp(-fn / fc))
    elif family == "power":
        k, m = rng.uniform(0.2, 0.8), rng.uniform(0.4, 1.0)
        ff = k * top * (fn / top) ** m
    else:  # bilinear: slope s1 up to a knee, then s2
        s1, ratio, knee = rng.uniform(0.3, 1.0), rng.uniform(0.15, 1.6), rng.uniform(0.2, 0.7)
        fb = knee * top
        ff = np.where(fn <= fb, s1 * fn, s1 * fb + ratio * s1 * (fn - fb))
    return fn, ff


def law_targets(count: int, seed: int) -> tuple[list[mi.Target], list[str], int]:
    """Targets of ``count`` laws (families in turn) at a feasible scale, no stiffness."""
    rng = np.random.default_rng(seed)
    out, fams, infeasible = [], [], 0
    for i in range(count):
        fam = FAMILIES[i % len(FAMILIES)]
        fn, ff = make_law(fam, rng)
        law = FrictionLaw(fn, ff, rows=np.arange(1, ROWS + 1), source=f"{fam}-{i}")
        fs = mi.feasible_scale(
            law, shear_strength=TAU, modulus=E_STAR, radius=RADIUS, area=AREA, fit="never"
        )
        at = {"area": AREA, "modulus": E_STAR, "shear_strength": TAU}
        var = next((v for v in ("area", "modulus", "shear_strength") if fs.ranges[v]), None)
        if var is None:
            infeasible += 1
            var = min(fs.best, key=lambda v: fs.best_outside[v])
        at[var] = fs.best[var]
        ft = friction_target(
            law,
            shear_strength=at["shear_strength"],
            e_star=at["modulus"],
            radius=RADIUS,
            area=at["area"],
            fit="never",
        )
        out.append(mi.Target(p_star=ft.p_star, alpha=ft.alpha, name=f"{fam}-{i}"))
        fams.append(fam)
    return out, fams, infeasible


def idle_count(r) -> int:
    """Asperities of a result's design that never touch over its target's range."""
    import torch

    from metainterface.inverse.reseed import idle_in_range

    g, h = r.design.tensors()
    p = torch.tensor([r.target.p_star_max], dtype=torch.float64)
    idle, _ = idle_in_range(g, h, r.design.settings, p, r.model)
    return int(idle.sum())


def zero_shot(targets: list[mi.Target]) -> np.ndarray:
    rs = mi.design(targets, refine=False, hedge=0, fallback=0)
    return np.array([r.error for r in rs])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--laws", type=int, default=50, help="friction laws (50)")
    ap.add_argument("--cells", type=int, default=50, help="exact curves of random cells (50)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--refine", action="store_true", help="also the refined error (slow)")
    ap.add_argument("--out", help="write the markdown table here")
    args = ap.parse_args()
    from bench_design import realisable_targets

    t0 = time.perf_counter()
    targets, fams, infeasible = law_targets(args.laws, args.seed)
    laws = zero_shot(targets)
    cells = realisable_targets(args.cells, args.seed)
    with_s = zero_shot(cells)
    bare = [mi.Target(p_star=t.p_star, alpha=t.alpha, name=t.name) for t in cells]
    without_s = zero_shot(bare)
    rows = [("all friction laws", laws)]
    rows += [(f"  {f}", laws[[x == f for x in fams]]) for f in FAMILIES]
    rows += [
        ("cell curves, with stiffness", with_s),
        ("cell curves, no stiffness", without_s),
    ]
    refined, idle_designs, idle_total = None, 0, 0
    if args.refine:
        made = mi.design(targets)
        refined = np.array([r.error for r in made])
        counts = [idle_count(r) for r in made]
        idle_designs, idle_total = sum(c > 0 for c in counts), sum(counts)
    lines = [
        "| targets | n | median zero-shot | p90 zero-shot |",
        "| --- | ---: | ---: | ---: |",
    ]
    for name, e in rows:
        med, p90 = 100 * np.median(e), 100 * np.quantile(e, 0.9)
        lines.append(f"| {name} | {e.size} | {med:.3g} % | {p90:.3g} % |")
    if refined is not None:
        lines.append(
            f"| friction laws, refined (CLI defaults) | {refined.size} | "
            f"{100 * np.median(refined):.3g} % | {100 * np.quantile(refined, 0.9):.3g} % |"
        )
        lines.append(
            f"\n{idle_designs} of {refined.size} refined designs have an asperity that never "
            f"touches over the law's range ({idle_total} such asperities in all)"
        )
    text = "\n".join(lines)
    print(text)
    print(f"{infeasible} of {args.laws} laws had no feasible scale (set at the closest)")
    print(f"{time.perf_counter() - t0:.1f} s")
    if args.out:
        Path(args.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
