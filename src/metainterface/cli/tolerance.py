"""`metainterface tolerance`: how a design degrades when it is made, and what printer it needs."""

from __future__ import annotations

import argparse

from metainterface._names import MODEL_NAMES
from metainterface.cli.common import add_device

#: How the library's errors name the options: as typed on the command line.
OPTION_NAMES = {
    "sigma_h": "--sigma-h",
    "sigma_gamma": "--sigma-gamma",
    "scale_sigma": "--scale-sigma",
    "samples": "--samples",
    "seed": "--seed",
    "radius": "--radius",
    "shear_strength": "--shear-strength",
    "modulus": "--modulus",
    "printer_sigma": "--printer-sigma",
    "max_error": "--max-error",
}


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "tolerance",
        help="the alpha(P*) band and error distribution of a design under manufacturing errors",
        description="Sample made cells (independent Gaussian errors on every asperity's height "
        "and shape exponent, and an optional common scale of the heights) through the batched "
        "forward model, and write DIR/band.csv (p_star,alpha_nominal,alpha_p05,alpha_p50,"
        "alpha_p95 over the design's pressure range), DIR/tolerance.json (error_median, "
        "error_p95 of the relative curve error to the design's target, or to its own curve "
        "when it has none, the first-order estimates, the settings) and DIR/tolerance.png. "
        "With --printer-sigma and --max-error: the smallest radius R at which the p95 error "
        "stays within the budget, and the analysis at that R.",
    )
    p.add_argument("design", help="design file (metainterface/design-v1 JSON)")
    p.add_argument(
        "--sigma-h",
        metavar="LENGTH",
        help="height error of each asperity, one standard deviation: a length with a unit "
        "(1um, needs --radius) or a plain number in units of R (Delta_max is 0.02 R)",
    )
    p.add_argument(
        "--sigma-gamma",
        type=float,
        default=0.0,
        help="error of each shape exponent, absolute (default 0); sampled gammas below 1.01 "
        "are clipped to 1.01",
    )
    p.add_argument(
        "--scale-sigma",
        type=float,
        default=0.0,
        help="relative error of a common scale of all heights, e.g. shrinkage (default 0)",
    )
    p.add_argument("--radius", help="asperity radius R, e.g. 0.5mm (default: the design file's)")
    p.add_argument("--samples", type=int, default=None, help="made cells sampled (default 4096)")
    p.add_argument("--seed", type=int, default=0, help="seed of the draws (default 0)")
    p.add_argument(
        "--model",
        choices=MODEL_NAMES,
        default=None,
        help="forward model (default: the design file's own model, its adhesion included; "
        "the paper's independent asperities for a file without)",
    )
    p.add_argument(
        "--target",
        help="measure errors to this built-in target, or 'nominal' for the design's own curve "
        "(default: the design file's target, else its own curve)",
    )
    p.add_argument("--shear-strength", help="interface shear strength tau, e.g. 0.25MPa")
    p.add_argument("--modulus", help="equivalent modulus E*, e.g. 2MPa")
    sizing = p.add_argument_group("printer sizing")
    sizing.add_argument(
        "--printer-sigma",
        metavar="LENGTH",
        help="the printer's height error (one standard deviation, e.g. 1um): find the "
        "smallest R that meets --max-error (instead of --sigma-h and --radius)",
    )
    sizing.add_argument("--max-error", help="p95 error budget, e.g. 5%% or 0.05")
    p.add_argument("--out", required=True, help="output folder")
    add_device(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import metainterface as mi

    common = dict(
        sigma_gamma=args.sigma_gamma,
        scale_sigma=args.scale_sigma,
        seed=args.seed,
        model=args.model,
        target=args.target,
        option_names=OPTION_NAMES,
        device=args.device,
    )
    printer = None
    radius, sigma_h = args.radius, args.sigma_h
    if args.printer_sigma is not None or args.max_error is not None:
        if args.printer_sigma is None or args.max_error is None:
            raise mi.MetainterfaceError("--printer-sigma and --max-error go together")
        if args.sigma_h is not None or args.radius is not None:
            raise mi.MetainterfaceError(
                "--printer-sigma finds the radius: leave out --sigma-h and --radius"
            )
        sizing = mi.min_radius(
            args.design,
            printer_sigma=args.printer_sigma,
            max_error=args.max_error,
            progress=True,
            **({} if args.samples is None else {"samples": args.samples}),
            **common,
        )
        print(repr(sizing))
        printer = sizing.to_dict()
        if not sizing.feasible:
            print("no radius meets the budget; the analysis below has no height error")
        elif sizing.radius_m == 0.0:
            print("any radius meets the budget; the analysis below has no height error")
        else:
            radius, sigma_h = sizing.radius_m, args.printer_sigma
    r = mi.tolerance(
        args.design,
        sigma_h=0.0 if sigma_h is None else sigma_h,
        radius=radius,
        samples=4096 if args.samples is None else args.samples,
        shear_strength=args.shear_strength,
        modulus=args.modulus,
        **common,
    )
    extra = {"command": {k: v for k, v in vars(args).items() if k != "func"}}
    if printer is not None:
        extra["printer"] = printer
    r.save(args.out, **extra)
    print(repr(r))
    print(f"written to {args.out}")
    return 0
