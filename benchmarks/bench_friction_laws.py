"""The surrogate's zero-shot error on friction laws (issue 28): targets without stiffness.

50 friction laws in newtons, seeded, in four families (Amontons with an offset, saturating,
power laws, bilinear), each turned into an alpha(P*) target at the scale that makes it
reachable (``mi.feasible_scale``: the middle of the widest feasible area range, else of the
modulus range, else the closest scale), 40 rows each, no stiffness column: what a user's
``--friction-csv`` gives. Reported: the zero-shot relative curve error of the surrogate
(``design(effort=Effort(refine=False, hedge=0, fallback=0))``) per family, and, as the reference the
network was trained for, the same on --cells exact curves of random cells given with their
stiffness and without it. Optionally the refined error (``--refine``, the CLI's defaults).
The same 50 laws are also given as measured: 8 random rows of the 40 with a 3 % scatter in
friction, fitted by the monotone spline as `design` fits such rows.

Each row is measured twice in one run: with the shipped surrogate alone (a copy of its file,
so `design` does not add the friction-law network) and as `design` runs by default, where
targets without stiffness are also read by the friction-law network
(weights/surrogate_laws.pt, trained on targets made from cells, not on these laws). Two
families the network's training shapes do not include (logarithmic and S-shaped laws, 10
each, their own seed) show whether it learned the families or the task.

Run: python benchmarks/bench_friction_laws.py [--laws 50] [--out results/friction_laws.md]
"""

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import metainterface as mi
from metainterface.units.friction import FrictionLaw, friction_target_in_units

sys.path.insert(0, str(Path(__file__).parent))

FAMILIES = ("amontons-offset", "saturating", "power", "bilinear")
HELD_OUT = ("logarithmic", "s-shaped")
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
    elif family == "bilinear":  # slope s1 up to a knee, then s2
        s1, ratio, knee = rng.uniform(0.3, 1.0), rng.uniform(0.15, 1.6), rng.uniform(0.2, 0.7)
        fb = knee * top
        ff = np.where(fn <= fb, s1 * fn, s1 * fb + ratio * s1 * (fn - fb))
    elif family == "logarithmic":  # F_f = a ln(1 + F_n / c)
        a, c = rng.uniform(0.05, 0.4) * top, rng.uniform(0.02, 0.5) * top
        ff = a * np.log1p(fn / c)
    else:  # s-shaped: slow start, a steep rise around F_0, then a softer slope
        f0, w = rng.uniform(0.25, 0.6) * top, rng.uniform(0.08, 0.25) * top
        lo = rng.uniform(0.1, 0.4)
        ff = top * (lo * fn / top + 0.3 * (np.tanh((fn - f0) / w) - np.tanh(-f0 / w)))
    return fn, ff


#: Measured laws: rows kept of the 40, and the relative scatter of their friction.
MEASURED_ROWS, SCATTER = 8, 0.03


def law_targets(
    count: int, seed: int, families: tuple[str, ...] = FAMILIES, measured: bool = False
) -> tuple[list[mi.Target], list[str], int]:
    """Targets of ``count`` laws (families in turn) at a feasible scale, no stiffness.
    ``measured``: the same laws as measured, MEASURED_ROWS random rows of the 40 with a
    normal scatter of SCATTER in friction, fitted as `design` fits them (``fit="auto"``)."""
    rng = np.random.default_rng(seed)
    noise = np.random.default_rng(seed + 100)  # apart, so the laws are the clean ones
    out, fams, infeasible = [], [], 0
    fit = "auto" if measured else "never"
    for i in range(count):
        fam = families[i % len(families)]
        fn, ff = make_law(fam, rng)
        rows = np.arange(1, ROWS + 1)
        if measured:
            rows = np.sort(noise.choice(ROWS, MEASURED_ROWS, replace=False)) + 1
            fn = fn[rows - 1]
            ff = ff[rows - 1] * (1 + SCATTER * noise.standard_normal(rows.size))
        law = FrictionLaw(fn, ff, rows=rows, source=f"{fam}-{i}")
        fs = mi.feasible_scale(
            law, shear_strength=TAU, modulus=E_STAR, radius=RADIUS, area=AREA, fit=fit
        )
        infeasible += not any(fs.ranges.values())
        ft = friction_target_in_units(law, **fs.suggest(), fit=fit)
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


def zero_shot_designs(targets: list[mi.Target], surrogate: str | None = None) -> list:
    """Zero-shot designs; ``surrogate`` a model file (None: `design`'s default networks)."""
    return mi.design(
        targets,
        verify=False,
        effort=mi.Effort(refine=False, hedge=0, fallback=0, surrogate=surrogate),
    )


def zero_shot(targets: list[mi.Target], surrogate: str | None = None) -> np.ndarray:
    """Zero-shot errors, as :func:`zero_shot_designs`."""
    return np.array([r.error for r in zero_shot_designs(targets, surrogate)])


def figure(targets: list[mi.Target], fams: list[str], alone: str, path: str) -> None:
    """One law a family (the one with the median gain): the law, and the zero-shot designs of
    the surrogate alone and of `design` with the friction-law network."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    before, after = zero_shot_designs(targets, alone), zero_shot_designs(targets)
    fig, axes = plt.subplots(1, len(FAMILIES), figsize=(12, 3.3), constrained_layout=True)
    for ax, fam in zip(axes, FAMILIES, strict=True):
        idx = [i for i, f in enumerate(fams) if f == fam]
        gain = [before[i].error - after[i].error for i in idx]
        i = idx[int(np.argsort(gain)[len(gain) // 2])]
        t, top = targets[i], targets[i].p_star_max
        ax.plot(1e3 * t.p_star, t.alpha, "o", ms=3, color="k", label="law (40 rows)")
        for r, style, name in (
            (before[i], "--", "surrogate alone"),
            (after[i], "-", "with the friction-law network"),
        ):
            c = r.curve()
            keep = c.p_star <= top
            ax.plot(
                1e3 * c.p_star[keep], c.alpha[keep], style, label=f"{name}: {100 * r.error:.2g} %"
            )
        ax.set_title(f"{fam} ({t.name})", fontsize=9)
        ax.set_xlabel(r"$P^*$ ($\times 10^{-3}$)")
        ax.legend(fontsize=7, loc="lower right")
    axes[0].set_ylabel(r"$\alpha$")
    fig.suptitle("Zero-shot designs of friction laws (no stiffness column)", fontsize=10)
    fig.savefig(path, dpi=110)


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--laws 4 --held-out 2 --cells 2"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--laws", type=int, default=50, help="friction laws (50)")
    ap.add_argument("--held-out", type=int, default=20, help="laws of held-out families (20)")
    ap.add_argument("--cells", type=int, default=50, help="exact curves of random cells (50)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--refine", action="store_true", help="also the refined error (slow)")
    ap.add_argument("--out", help="write the markdown table here")
    ap.add_argument("--figure", help="draw one law a family with both zero-shot designs here")
    args = ap.parse_args()
    from bench_design import realisable_targets
    from metainterface.surrogate.checkpoint import default_model_path

    t0 = time.perf_counter()
    targets, fams, infeasible = law_targets(args.laws, args.seed)
    held, held_fams, held_bad = law_targets(args.held_out, args.seed + 1, HELD_OUT)
    measured, _, measured_bad = law_targets(args.laws, args.seed, measured=True)
    cells = realisable_targets(args.cells, args.seed)
    bare = [mi.Target(p_star=t.p_star, alpha=t.alpha, name=t.name) for t in cells]
    with tempfile.TemporaryDirectory() as tmp:
        alone = str(Path(tmp) / "surrogate.pt")
        shutil.copy(default_model_path(), alone)
        if args.figure:
            figure(targets, fams, alone, args.figure)
        runs = {
            which: {
                "laws": zero_shot(targets, path),
                "held": zero_shot(held, path),
                "measured": zero_shot(measured, path),
                "with_s": zero_shot(cells, path),
                "without_s": zero_shot(bare, path),
            }
            for which, path in (("before", alone), ("after", None))
        }
    rows = [("all friction laws", "laws", None)]
    rows += [(f"  {f}", "laws", (fams, f)) for f in FAMILIES]
    rows += [
        (f"the same laws measured: {MEASURED_ROWS} rows, {SCATTER:.0%} scatter", "measured", None)
    ]
    rows += [("held-out families", "held", None)]
    rows += [(f"  {f}", "held", (held_fams, f)) for f in HELD_OUT]
    rows += [
        ("cell curves, with stiffness", "with_s", None),
        ("cell curves, no stiffness", "without_s", None),
    ]
    lines = [
        "| targets | n | surrogate alone: median / p90 | with the friction-law network: "
        "median / p90 |",
        "| --- | ---: | ---: | ---: |",
    ]
    idle_lines: list[str] = []
    for name, key, sub in rows:
        cells_txt = []
        for which in ("before", "after"):
            e = runs[which][key]
            if sub is not None:
                e = e[[x == sub[1] for x in sub[0]]]
            med, p90 = 100 * np.median(e), 100 * np.quantile(e, 0.9)
            cells_txt.append(f"{med:.3g} % / {p90:.3g} %")
        lines.append(f"| {name} | {e.size} | {cells_txt[0]} | {cells_txt[1]} |")
    if args.refine:
        for name, group in (("friction laws", targets), ("held-out families", held)):
            made = mi.design(group, verify=False)
            refined = np.array([r.error for r in made])
            counts = [idle_count(r) for r in made]
            lines.append(
                f"| {name}, refined (CLI defaults) | {refined.size} | | "
                f"{100 * np.median(refined):.3g} % / {100 * np.quantile(refined, 0.9):.3g} % |"
            )
            idle_lines.append(
                f"{sum(c > 0 for c in counts)} of {refined.size} refined designs of the {name} "
                f"have an asperity that never touches over the law's range ({sum(counts)} such "
                "asperities in all)"
            )
    lines += ["", *idle_lines] if idle_lines else []
    text = "\n".join(lines)
    print(text)
    bad, n = infeasible + held_bad + measured_bad, 2 * args.laws + args.held_out
    print(f"{bad} of {n} laws had no feasible scale")
    print(f"{time.perf_counter() - t0:.1f} s")
    if args.out:
        Path(args.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
