"""`metainterface design`: a unit cell whose alpha(P*) follows a target contact law."""

from __future__ import annotations

import argparse

from metainterface.cli.common import positive_int


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "design",
        help="design a unit cell for a target contact law (the main job)",
        description="Zero-shot prediction by the shipped surrogate, then multi-stage L-BFGS "
        "refinement (or a multistart / Hertz-only baseline). Writes, per target, design.json, "
        "target.csv, curve.csv and design.png under --out.",
    )
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
        help="CSV with header p_star,alpha",
    )
    src.add_argument(
        "--friction-csv",
        metavar="FILE",
        help="CSV normal_force,friction_force [N] (or normal_force,friction_coefficient)"
        "; needs --shear-strength --modulus --radius --area",
    )
    phys = p.add_argument_group("physical units (with --friction-csv, or for a physical block)")
    phys.add_argument("--shear-strength", help="interface shear strength tau, e.g. 0.25MPa")
    phys.add_argument("--modulus", help="equivalent modulus E*, e.g. 2MPa")
    phys.add_argument("--radius", help="asperity radius R, e.g. 0.5mm")
    phys.add_argument("--area", help="nominal area of the whole interface, e.g. 4cm2")
    phys.add_argument("--total-force", help="total normal force, e.g. 10N (number of cells)")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--method", choices=("surrogate", "multistart", "hertz"), default="surrogate")
    p.add_argument("--refine", choices=("lbfgs", "none"), default="lbfgs")
    p.add_argument(
        "--compare",
        action="store_true",
        help="run all three methods and draw them together (paper fig. 5)",
    )
    p.add_argument("--starts", type=positive_int, default=50, help="random starts (baselines)")
    p.add_argument("--seed", type=int, default=0)
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
        help="surrogate method: a target still missed by more than 2 %% after refinement also "
        "gets a multistart with this many random starts, the better design kept (default 50; "
        "0 = off)",
    )
    p.add_argument(
        "--physics",
        choices=("independent", "interacting"),
        default="independent",
        help="forward model to refine and measure with (default: the paper's independent one)",
    )
    p.add_argument(
        "--max-pressure",
        help="peak contact pressure limit: p/E* (number) or a stress with --modulus",
    )
    p.set_defaults(func=run)


def _targets(args: argparse.Namespace):
    from metainterface.design import builtin_target, target_from_csv
    from metainterface.errors import MetainterfaceError

    targets = [builtin_target(n) for n in args.target]
    targets += [target_from_csv(f) for f in args.target_csv]
    friction = None
    if args.friction_csv:
        from metainterface.design.targets import Target
        from metainterface.io.friction import friction_target_from_options

        friction = friction_target_from_options(
            args.friction_csv,
            shear_strength=args.shear_strength,
            modulus=args.modulus,
            radius=args.radius,
            area=args.area,
        )
        from pathlib import Path

        targets.append(
            Target(
                Path(args.friction_csv).stem,
                friction.p_star,
                friction.alpha,
                None,
                args.friction_csv,
                {"friction": friction.record()},
            )
        )
    if not targets:
        raise MetainterfaceError("give at least one --target, --target-csv or --friction-csv")
    names = [t.name for t in targets]
    if len(set(names)) != len(names):
        raise MetainterfaceError(f"target names must be distinct, got {', '.join(names)}")
    return targets


def run(args: argparse.Namespace) -> int:
    import sys
    from pathlib import Path

    from metainterface.design import design, reachability_warnings
    from metainterface.io.units import parse_pressure, parse_pressure_limit

    targets = _targets(args)
    e_star = parse_pressure(args.modulus, option="--modulus") if args.modulus else None
    extra = None
    limit = None
    if args.max_pressure:
        from metainterface.physics.limits import pressure_penalty

        limit = parse_pressure_limit(args.max_pressure, e_star=e_star)

        def extra(gamma, h, settings, limit=limit):
            return 10.0 * pressure_penalty(gamma, h, settings, limit)

    methods = ["surrogate", "multistart", "hertz"] if args.compare else [args.method]
    all_results = [
        design(
            targets,
            method,
            refine_designs=args.refine == "lbfgs",
            model_path=args.model,
            starts=args.starts,
            seed=args.seed,
            extra_loss=extra,
            physics=args.physics,
            hedge=args.hedge if method == "surrogate" else 0,
            fallback=args.fallback if method == "surrogate" else 0,
        )
        for method in methods
    ]
    for t, r in zip(targets, all_results[0], strict=True):
        for w in reachability_warnings(t, r.settings):
            print(f"warning: {w}", file=sys.stderr)
    from metainterface.io.report import pressure_check, write_design_outputs
    from metainterface.physics.cell import Design

    out = Path(args.out)
    rows = []
    for i, t in enumerate(targets):
        per_method = [res[i] for res in all_results]
        for r in per_method:
            folder = out / t.name if len(methods) == 1 else out / t.name / r.method
            check = None
            if limit is not None:
                check = pressure_check(
                    Design(gamma=r.gamma, h=r.h, settings=r.settings), limit, e_star
                )
                print(f"{t.name} ({r.method}): {check.summary()}")
            write_design_outputs(folder, r, args=args, pressure=check)
            rows.append((t.name, r.method, r.initial_error, r.error, r.seconds, folder))
        if args.compare:
            from metainterface.plots import plot_comparison, save_figure

            save_figure(
                plot_comparison([per_method]),
                out / t.name / "compare.png",
                command="design --compare",
            )
    print(f"{'target':<14}{'method':<12}{'zero-shot':>10}{'error':>9}{'seconds':>9}  output")
    for name, method, e0, e, sec, folder in rows:
        print(f"{name:<14}{method:<12}{100 * e0:>9.2f}%{100 * e:>8.2f}%{sec:>9.2f}  {folder}")
    return 0
