"""`metainterface measure`: a scan of a made part in; its fit, predicted law and the next
print's correction out."""

from __future__ import annotations

import argparse

from metainterface._names import DEFAULT_MODEL, MODEL_NAMES
from metainterface.cli.common import add_device


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "measure",
        help="a scan of the made part: asperities fitted, friction law predicted, next print "
        "corrected",
        description="Read a scan of a made part (any format SurfaceTopography reads: X3P, SUR, "
        "OPD, DATX, GWY, NPY, text, ...; the [measure] extra), level it and register it to "
        "the design's lattice, fit every asperity of every cell, and predict the part's "
        "alpha(P*) by BEM on the measured cell and by the forward model with the fitted "
        "asperities, against the design's target. Writes DIR/measured.json (fitted "
        "asperities, made vs designed in um and as share of the curve error, the fitted map), "
        "DIR/bem.csv (p_star, alpha_bem, ... and forces in N with --modulus, --shear-strength "
        "and --area), DIR/measured.png and, with --compensate, DIR/compensated.json: the "
        "design to print next so that the made part meets the target. Quantities take units "
        "(0.5mm, 2MPa); a plain number is SI.",
    )
    p.add_argument("scan", help="scan file of the made part")
    p.add_argument("--design", required=True, help="the design file that was printed")
    p.add_argument("--radius", required=True, help="asperity radius R, e.g. 0.5mm")
    p.add_argument(
        "--size",
        metavar="LENGTH[,LENGTH]",
        help="the scan's lateral size (width along x, height along y) where its file gives "
        "none, e.g. 4mm or 4mm,3mm",
    )
    p.add_argument(
        "--height-unit", help="the scan's height unit where its file gives none, e.g. um"
    )
    p.add_argument("--modulus", help="equivalent modulus E*, e.g. 2MPa")
    p.add_argument("--shear-strength", help="interface shear strength tau, e.g. 0.25MPa")
    p.add_argument("--area", help="nominal contact area, e.g. 1cm^2")
    p.add_argument(
        "--compensate",
        action="store_true",
        help="also write compensated.json, the geometry to print next",
    )
    p.add_argument(
        "--also",
        nargs=2,
        action="append",
        default=[],
        metavar=("SCAN", "DESIGN"),
        help="with --compensate: another scan of the same print and the design it was "
        "printed from, whose asperities join the map from designed to made (repeatable)",
    )
    p.add_argument(
        "--z-step",
        help="the printer's layer step, e.g. 1um: the correction models the layers with it "
        "(default: read from the scan where it shows terraces)",
    )
    p.add_argument(
        "--work-of-adhesion",
        help="an adhesive part's work of adhesion, e.g. 50mJ/m2 (with --modulus): the "
        "measured cell solved in the JKR-limit BEM against the design's adhesive target",
    )
    p.add_argument(
        "--max-error",
        default="5%",
        help="exit status 3 when the made error (BEM) is above this (default 5%%)",
    )
    p.add_argument("--loads", type=int, default=8, help="BEM loads (default 8)")
    p.add_argument(
        "--grid",
        type=int,
        help="BEM grid points per cell side (default: the scan's resolution, 64 n to 256 n)",
    )
    p.add_argument(
        "--model",
        choices=MODEL_NAMES,
        default=DEFAULT_MODEL,
        help="forward model (default: the paper's independent asperities)",
    )
    p.add_argument("--out", required=True, help="output folder")
    add_device(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import metainterface as mi
    from metainterface.manufacture.tolerance import _max_error

    max_error = _max_error(args.max_error, "--max-error")
    size = None if args.size is None else [s.strip() for s in args.size.split(",")]
    if size is not None and len(size) not in (1, 2):
        raise mi.MetainterfaceError("--size takes one length or two, e.g. 4mm,3mm")
    result = mi.measure(
        args.scan,
        args.design,
        radius=args.radius,
        size=None if size is None else (size * 2)[:2],
        height_unit=args.height_unit,
        modulus=args.modulus,
        shear_strength=args.shear_strength,
        area=args.area,
        loads=args.loads,
        grid=args.grid,
        model=args.model,
        out=args.out,
        compensate=args.compensate,
        device=args.device,
        z_step=args.z_step,
        work_of_adhesion=args.work_of_adhesion,
        also=[tuple(pair) for pair in args.also],
    )
    print(result.report(max_error))
    return 3 if result.error > max_error else 0
