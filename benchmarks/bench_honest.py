"""Honest results for the issue's three everyday friction laws (E* = 2 MPa, tau = 0.25 MPa,
R = 0.5 mm, 4 cm^2): the reachability verdict, the forced designs' error, coverage and
load-carrying asperities, and the size of a 10 x 10 tile STL export before and after the
coarser flanks. Writes benchmarks/results/honest.md (not with --quick).
Run: python benchmarks/bench_honest.py [--quick]
"""

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np

import metainterface as mi
from metainterface.io.export import file_bytes, height_patch, mesh_lines, stl_triangles

UNITS = dict(shear_strength="0.25MPa", modulus="2MPa", radius="0.5mm", area="4cm2")


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--quick"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--quick", action="store_true", help="zero-shot designs, no BEM check, no file written"
    )
    args = ap.parse_args()
    fn = np.linspace(0.25, 6.0, 24)
    laws = {
        "F_f = 0.4 F_n": 0.4 * fn,
        "F_f = 1.2 (1 - exp(-F_n / 1.5))": 1.2 * (1 - np.exp(-fn / 1.5)),
        "F_f = 0.3 F_n^(2/3)": 0.3 * fn ** (2 / 3),
    }
    lines = [
        "# Honest results (issue 31)",
        "",
        f"`python benchmarks/bench_honest.py{' --quick' if args.quick else ''}`; "
        f"load average {os.getloadavg()[0]:.1f} (a shared 2-core machine: times are noisy).",
        "",
        "| law | reachable | law mu | reachable mu | error | coverage | carrying | s |",
        "|---|---|---|---|---|---|---|---|",
    ]
    design = None
    with tempfile.TemporaryDirectory() as tmp:
        for i, (name, ff) in enumerate(laws.items()):
            law = Path(tmp) / f"law{i}.csv"
            rows = "".join(f"{a},{b}\n" for a, b in zip(fn, ff, strict=True))
            law.write_text("normal_force,friction_force\n" + rows)
            r = mi.reachability(law, **UNITS)
            t0 = time.perf_counter()
            res = mi.design(
                mi.Target.from_friction(law, **UNITS),
                force=True,
                effort=mi.Effort(refine=not args.quick),
                verify=not args.quick,
            )
            sec = time.perf_counter() - t0
            design = design or res.design
            row = (
                f"| {name} | {r.reachable} | {r.law_mu[0]:.3g}-{r.law_mu[1]:.3g} | "
                f"{r.reachable_mu[0]:.3g}-{r.reachable_mu[1]:.3g} | {100 * res.error:.3g} % | "
                f"{100 * res.coverage:.3g} % | {res.carrying}/9 | {sec:.1f} |"
            )
            print(row)
            lines.append(row)
    lines += ["", "10 x 10 tile STL of the first design at the default resolution:", ""]
    patch = height_patch(design, radius=0.5e-3, tiles=(10, 10))
    for step in (1, 4):
        lx, ly = mesh_lines(patch, step)
        row = (
            f"- flank step {step}: {stl_triangles(lx.size, ly.size) / 1e6:.3g} M triangles, "
            f"{file_bytes(patch, 'stl', step) / 1e6:.0f} MB"
        )
        print(row)
        lines.append(row)
    if not args.quick:
        out = Path(__file__).parent / "results" / "honest.md"
        out.write_text("\n".join(lines) + "\n")
        print(f"written to {out}")


if __name__ == "__main__":
    main()
