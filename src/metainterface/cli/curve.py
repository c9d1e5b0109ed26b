"""`metainterface curve`: the alpha(P*) curve of a design file."""

from __future__ import annotations

import argparse

from metainterface.cli.common import positive_float, positive_int


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
        choices=("independent", "interacting"),
        default="independent",
        help="forward model: the paper's independent asperities (default) or with their "
        "elastic interaction through the periodic lattice",
    )
    p.add_argument("--out", required=True, help="output CSV")
    p.add_argument("--plot", help="also draw alpha(P*) and S*(P*) to this PNG/PDF")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from metainterface.io import load_design, write_columns
    from metainterface.physics.forward import design_sweep_for

    design = load_design(args.design)
    sw = design_sweep_for(design, physics=args.physics, n_delta=args.steps, smooth=args.smooth)
    write_columns(
        args.out,
        {
            "delta": sw.delta.numpy(),
            "p_star": sw.p_star[0].numpy(),
            "alpha": sw.alpha[0].numpy(),
            "stiffness": sw.stiffness[0].numpy(),
        },
        command="curve",
        design=args.design,
        steps=args.steps,
        smooth=args.smooth,
        physics=args.physics,
        cell=design.settings.to_dict(),
    )
    if args.plot:
        from metainterface.plots import plot_curve, save_figure

        save_figure(plot_curve(sw, title=args.design), args.plot, command="curve")
    print(
        f"{args.out}: {args.steps} points ({args.physics}), "
        f"P*_max = {float(sw.p_star[0, -1]):.4g}, alpha_max = {float(sw.alpha[0, -1]):.4g}"
    )
    return 0
