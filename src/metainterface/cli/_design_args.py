"""`metainterface design`'s command-line options, registered group by group (the targets,
units, outputs, method, design space, manufacturing, limits and the BEM check)."""

from __future__ import annotations

import argparse

from metainterface._names import (
    DEFAULT_ENGINE,
    DEFAULT_MODEL,
    ENGINE_NAMES,
    FIT_NAMES,
    METHOD_NAMES,
    MODEL_NAMES,
)
from metainterface.cli.common import add_device, positive_int


def target_arguments(p: argparse.ArgumentParser) -> None:
    """`design`'s targets: built-in names, CSV files of alpha(P*) or of friction, the fit."""
    src = p.add_argument_group("targets (one or more)")
    src.add_argument(
        "--target",
        action="append",
        default=[],
        metavar="NAME",
        help="built-in target: saturating, bilinear or linear",
    )
    src.add_argument(
        "--target-csv",
        action="append",
        default=[],
        metavar="FILE",
        help="CSV with header p_star,alpha (comma, ';' or tab; decimal commas with ';')",
    )
    src.add_argument(
        "--friction-csv",
        metavar="FILE",
        help="CSV normal_force,friction_force [N] (or normal_force,friction_coefficient; units "
        "in the header, e.g. 'normal_force [mN]'; comma, ';' or tab)"
        "; needs --shear-strength --modulus --radius --area",
    )
    src.add_argument(
        "--fit",
        choices=FIT_NAMES,
        default="auto",
        help="replace the friction rows by a monotone smooth fit (a cubic spline, knots by "
        "cross-validation): auto (default) fits rows with scatter, repeated or unsorted loads, "
        "or 5-9 rows; the fit is drawn in friction_fit.png",
    )


def unit_arguments(p: argparse.ArgumentParser) -> None:
    """`design`'s options: the physical units of a friction law or a physical block."""
    phys = p.add_argument_group("physical units (with --friction-csv, or for a physical block)")
    phys.add_argument(
        "--shear-strength",
        help="interface shear strength tau, e.g. 0.25MPa (or a range, as --area)",
    )
    phys.add_argument(
        "--modulus", help="equivalent modulus E*, e.g. 2MPa (or a range, e.g. 1MPa..20MPa)"
    )
    phys.add_argument("--radius", help="asperity radius R, e.g. 0.5mm")
    phys.add_argument(
        "--work-of-adhesion",
        help="work of adhesion w of the interface, e.g. 50mJ/m2 (PDMS on glass): JKR "
        "asperities, and friction at zero load (an offset law) is accepted and kept",
    )
    phys.add_argument(
        "--area",
        help="nominal area of the whole interface, e.g. 4cm2; with --friction-csv also "
        "'auto' or a range (2cm2..10cm2): the area is designed with the cell (one of --area, "
        "--modulus, --shear-strength may be free)",
    )
    phys.add_argument("--total-force", help="total normal force, e.g. 10N (number of cells)")


def output_arguments(p: argparse.ArgumentParser) -> None:
    """`design`'s options: what is written, and where."""
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument(
        "--full-target",
        action="store_true",
        help="also write the whole target to target.csv (design.json keeps it decimated)",
    )
    p.add_argument(
        "--html",
        action="store_true",
        help="also write view.html, an interactive page of each design (needs the [view] extra)",
    )


def method_arguments(p: argparse.ArgumentParser) -> None:
    """`design`'s method and effort: refinement, hedges, fallback, forward model."""
    p.add_argument("--method", choices=METHOD_NAMES, default="surrogate")
    p.add_argument("--refine", choices=("lbfgs", "none"), default="lbfgs")
    p.add_argument(
        "--compare",
        action="store_true",
        help="run all three methods and draw them together (paper fig. 5)",
    )
    p.add_argument("--starts", type=positive_int, default=50, help="random starts (baselines)")
    p.add_argument("--seed", type=int, default=0, help="seed of every random draw (default 0)")
    p.add_argument("--model", help="surrogate model file (default: the shipped one)")
    p.add_argument(
        "--hedge",
        type=int,
        default=8,
        help="surrogate method: also refine this many starts beside the zero-shot prediction "
        "(half jittered copies of it, half random) and keep the best (default 8; 0 = the "
        "paper's pure pipeline)",
    )
    p.add_argument(
        "--fallback",
        type=int,
        default=50,
        help="surrogate method: a target still missed by more than 2 %% (1 %% with adhesion) "
        "after refinement also gets a multistart with this many random starts, the better "
        "design kept (default 50; 0 = off)",
    )
    p.add_argument(
        "--physics",
        choices=MODEL_NAMES,
        default=DEFAULT_MODEL,
        help="forward model to refine and measure with (default: the paper's independent one)",
    )


def space_arguments(p: argparse.ArgumentParser) -> None:
    """`design`'s options: the design space: the cell's asperities and bounds."""
    space = p.add_argument_group(
        "design space (default: the paper's cell, which the shipped surrogate was trained for; "
        "another cell is designed by multistart)"
    )
    space.add_argument("--n-asperities", type=int, metavar="N", help="a perfect square (9)")
    space.add_argument("--gamma-min", type=float, help="smallest shape exponent (1.8)")
    space.add_argument("--gamma-max", type=float, help="largest shape exponent (4.0)")
    space.add_argument("--delta-max", type=float, help="largest indentation in units of R (0.02)")


def manufacturing_arguments(p: argparse.ArgumentParser) -> None:
    """`design`'s options: manufacturing errors: robust design and the printer's layer height."""
    made = p.add_argument_group(
        "manufacturing (lengths with a unit need --radius; a plain number is in units of R, "
        "and Delta_max is 0.02 R)"
    )
    made.add_argument(
        "--robust",
        action="store_true",
        help="design for the errors below: refine the mean error over --robust-samples "
        "perturbed copies of each start; design.json keeps the nominal relative_error and "
        "adds the made cells' median and p95",
    )
    made.add_argument("--sigma-h", metavar="LENGTH", help="height error (one sd), e.g. 1um")
    made.add_argument("--sigma-gamma", type=float, default=0.0, help="shape-exponent error")
    made.add_argument(
        "--scale-sigma", type=float, default=0.0, help="relative error of the heights' scale"
    )
    made.add_argument(
        "--robust-samples", type=int, default=16, help="perturbed copies per start (16)"
    )
    made.add_argument(
        "--z-step",
        metavar="LENGTH",
        help="printer layer height, e.g. 1um: heights snapped to its multiples, the shapes "
        "re-refined; the error before and after is reported",
    )


def limit_arguments(p: argparse.ArgumentParser) -> None:
    """`design`'s options: forced designs, the pressure limit and the device."""
    p.add_argument(
        "--force",
        action="store_true",
        help="design a friction law that no cell can follow anyway (the closest cell, marked "
        "as forced); without it such a law exits with status 2, writing nothing",
    )
    p.add_argument(
        "--max-pressure",
        help="peak contact pressure limit: p/E* (number) or a stress with --modulus",
    )
    add_device(p)


def check_arguments(p: argparse.ArgumentParser) -> None:
    """`design`'s options: the BEM check, its correction and its trust threshold."""
    check = p.add_argument_group(
        "BEM check (on by default; docs: concepts/verification)",
        "each design is solved in BEM at --verify-loads loads over the target's range and "
        "its error to the target reported; exit status 3 when above --max-bem-error",
    )
    check.add_argument(
        "--no-verify",
        dest="verify",
        action="store_false",
        help="skip the BEM check (and the correction)",
    )
    check.add_argument(
        "--verify-grid",
        type=positive_int,
        metavar="M",
        help="BEM grid points per cell side, a multiple of sqrt(N) (default 128 sqrt(N): 384; "
        "768 is the paper's resolution)",
    )
    check.add_argument(
        "--verify-loads", type=int, default=10, metavar="K", help="loads of the check (10)"
    )
    check.add_argument(
        "--correct",
        dest="correct",
        action="store_true",
        default=None,
        help="correct every design in BEM (output space mapping, up to 3 BEM solves); by "
        "default only where the BEM adds more than 0.5 points to the model's error",
    )
    check.add_argument(
        "--no-correct", dest="correct", action="store_false", help="never correct in BEM"
    )
    check.add_argument(
        "--correct-model",
        choices=[*MODEL_NAMES, "design"],
        default="interacting",
        help="the forward model the correction re-refines on: interacting (default; its "
        "defect to the BEM is smaller), independent, or design (the design's own --physics)",
    )
    check.add_argument(
        "--max-bem-error",
        type=float,
        default=2.0,
        metavar="PERCENT",
        help="BEM error a design is trusted within, in per cent (default 2): above it the "
        "summary says so and the exit status is 3",
    )
    check.add_argument(
        "--verify-engine",
        choices=ENGINE_NAMES,
        default=DEFAULT_ENGINE,
        help="contact solver of the check: torch (default; CPU threads or a GPU) or tamaas "
        "(the [bem] extra, the reference)",
    )
