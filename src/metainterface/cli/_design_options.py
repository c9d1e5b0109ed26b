"""`metainterface design`'s options turned into the API's arguments: the cell, the
manufacturing errors and layer, the BEM check, and the record of the command."""

from __future__ import annotations

import argparse


def verify(args: argparse.Namespace):
    """The BEM check's settings from the options, or False with --no-verify."""
    import metainterface as mi
    from metainterface.verify import Verify

    if not args.verify:
        return False
    if not 0 < args.max_bem_error <= 100:
        raise mi.MetainterfaceError(
            f"--max-bem-error must be a percentage in (0, 100], got {args.max_bem_error:g}"
        )
    return Verify(
        grid=args.verify_grid,
        loads=args.verify_loads,
        correct=args.correct,
        inner=None if args.correct_model == "design" else args.correct_model,
        max_error=args.max_bem_error / 100,
        engine=args.verify_engine,
        device=args.device,
    )


def _manufacturing(args: argparse.Namespace) -> dict:
    """The robust-design and layer options, lengths in units of R (errors name the options)."""
    import metainterface as mi
    from metainterface.units import parse_length
    from metainterface.units.printer import layer_step, length_in_r

    radius = None if args.radius is None else parse_length(args.radius, option="--radius")
    out: dict = {}
    if args.z_step is not None:
        delta_max = (settings(args) or mi.CellSettings()).delta_max
        out["z_step"] = layer_step(
            args.z_step, radius, delta_max, option="--z-step", radius_option="--radius"
        )
    given = args.sigma_h is not None or args.sigma_gamma or args.scale_sigma
    if not args.robust:
        if given:
            raise mi.MetainterfaceError("--sigma-h, --sigma-gamma, --scale-sigma need --robust")
        return out
    sigma_h = 0.0
    if args.sigma_h is not None:
        sigma_h = length_in_r(args.sigma_h, radius, option="--sigma-h", radius_option="--radius")
    # --sigma-gamma, --scale-sigma and --robust-samples are checked by mi.design, whose
    # errors carry the argument and so are shown under these option names
    if sigma_h == args.sigma_gamma == args.scale_sigma == 0.0:
        raise mi.MetainterfaceError("--robust needs --sigma-h, --sigma-gamma or --scale-sigma > 0")
    out["robust"] = mi.Robust(
        sigma_h=sigma_h,
        sigma_gamma=args.sigma_gamma,
        scale_sigma=args.scale_sigma,
        samples=args.robust_samples,
    )
    return out


def groups(args: argparse.Namespace) -> dict:
    """The command line's flat options mapped to ``mi.design``'s groups: the one place where
    they meet (``effort``, ``scale``, ``robust`` and ``z_step``)."""
    import metainterface as mi

    def given(**values):
        return {k: v for k, v in values.items() if v is not None}

    effort = given(
        refine=args.refine == "lbfgs",
        surrogate=args.model,
        starts=args.starts,
        seed=args.seed,
        hedge=args.hedge,
        fallback=args.fallback,
    )
    scale = given(
        modulus=args.modulus,
        radius=args.radius,
        total_force=args.total_force,
        area=args.area if args.total_force is None else None,
    )
    return {"effort": mi.Effort(**effort), "scale": mi.Scale(**scale), **_manufacturing(args)}


def settings(args: argparse.Namespace):
    """The cell from the design-space options, or None for the surrogate's own cell."""
    import metainterface as mi

    given = {
        k: v
        for k, v in (
            ("n_asperities", args.n_asperities),
            ("gamma_min", args.gamma_min),
            ("gamma_max", args.gamma_max),
            ("delta_max", args.delta_max),
        )
        if v is not None
    }
    return mi.CellSettings(**given) if given else None


def command(args: argparse.Namespace) -> dict:
    """The options as given, recorded in design.json."""
    return {k: v for k, v in vars(args).items() if k != "func"}
