"""`metainterface curve`: the alpha(P*) curve of a design file."""

from __future__ import annotations

import argparse

from metainterface._names import MODEL_NAMES
from metainterface.cli.common import add_device, positive_float, positive_int


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "curve",
        help="alpha(P*) and S*(P*) of a design file, as CSV (and a plot)",
        description="Sweep the global indentation over [0, Delta_max] and write "
        "delta,p_star,alpha,stiffness (exact physics unless --smooth).",
    )
    p.add_argument("design", help="design file (metainterface/design-v1 JSON)")
    p.add_argument("--steps", type=positive_int, default=128, help="Delta samples (default 128)")
    p.add_argument(
        "--smooth",
        type=positive_float,
        metavar="KAPPA",
        help="softplus steepness kappa_s [1/R] instead of the exact Macaulay bracket",
    )
    p.add_argument(
        "--physics",
        choices=MODEL_NAMES,
        default=None,
        help="forward model: the paper's independent asperities or with their elastic "
        "interaction through the periodic lattice (default: the design file's own model, "
        "its adhesion included; the independent one for a file without)",
    )
    p.add_argument("--out", required=True, help="output CSV")
    p.add_argument("--plot", help="also draw alpha(P*) and S*(P*) to this PNG/PDF")
    add_device(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import sys

    import metainterface as mi
    from metainterface._files import write_columns

    c = mi.curve(
        args.design, model=args.physics, steps=args.steps, smooth=args.smooth, device=args.device
    )
    write_columns(
        args.out,
        c.columns(),
        command="curve",
        design=args.design,
        steps=args.steps,
        smooth=args.smooth,
        model=c.model,
    )
    if args.plot is not None:
        from pathlib import Path

        from metainterface.plots import plot_curve, save_figure

        path = Path(args.design)  # "FOLDER: design.json": the file name alone is often the same
        title = f"{path.parent.name}: {path.name}" if path.parent.name else path.name
        save_figure(plot_curve(c, title=title), args.plot, command="curve")
    for note in c.notes:
        print(f"warning: {note}", file=sys.stderr)
    print(
        f"{args.out}: {args.steps} points ({c.model}), "
        f"P*_max = {c.p_star_max:.4g}, alpha_max = {c.alpha_max:.4g}"
    )
    return 0
