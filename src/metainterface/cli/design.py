"""`metainterface design`: a unit cell whose alpha(P*) follows a target contact law."""

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


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "design",
        help="design a unit cell for a target contact law (the main job)",
        description="Zero-shot prediction by the shipped surrogate, then multi-stage L-BFGS "
        "refinement (or a multistart / Hertz-only baseline). Writes design.json, curve.csv "
        "and design.png into --out (one folder per target when there are several). Each "
        "design is then checked in the boundary element method (BEM) and its BEM error to the "
        "target reported beside the model's; exit status 3 when a design's BEM error is above "
        "--max-bem-error (the files are written all the same), 2 on bad input.",
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
    src.add_argument(
        "--fit",
        choices=FIT_NAMES,
        default="auto",
        help="replace the friction rows by a monotone smooth fit (a cubic spline, knots by "
        "cross-validation): auto (default) fits rows with scatter, repeated or unsorted loads, "
        "or 5-9 rows; the fit is drawn in friction_fit.png",
    )
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
        "--area",
        help="nominal area of the whole interface, e.g. 4cm2; with --friction-csv also "
        "'auto' or a range (2cm2..10cm2): the area is designed with the cell (one of --area, "
        "--modulus, --shear-strength may be free)",
    )
    phys.add_argument("--total-force", help="total normal force, e.g. 10N (number of cells)")
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
        help="surrogate method: a target still missed by more than 2 %% after refinement also "
        "gets a multistart with this many random starts, the better design kept (default 50; "
        "0 = off)",
    )
    p.add_argument(
        "--physics",
        choices=MODEL_NAMES,
        default=DEFAULT_MODEL,
        help="forward model to refine and measure with (default: the paper's independent one)",
    )
    space = p.add_argument_group(
        "design space (default: the paper's cell, which the shipped surrogate was trained for; "
        "another cell is designed by multistart)"
    )
    space.add_argument("--n-asperities", type=int, metavar="N", help="a perfect square (9)")
    space.add_argument("--gamma-min", type=float, help="smallest shape exponent (1.8)")
    space.add_argument("--gamma-max", type=float, help="largest shape exponent (4.0)")
    space.add_argument("--delta-max", type=float, help="largest indentation in units of R (0.02)")
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
    p.set_defaults(func=run)


def _targets(args: argparse.Namespace) -> list:
    import metainterface as mi

    targets = [mi.Target.builtin(n) for n in args.target]
    targets += [mi.Target.from_csv(f) for f in args.target_csv]
    if args.friction_csv and not _scale_free(args):
        given = {
            "--shear-strength": args.shear_strength,
            "--modulus": args.modulus,
            "--radius": args.radius,
            "--area": args.area,
        }
        missing = [name for name, value in given.items() if value is None]
        if missing:
            raise mi.MetainterfaceError(
                "--friction-csv needs --shear-strength, --modulus, --radius and --area "
                f"(missing {', '.join(missing)})"
            )
        targets.append(
            mi.Target.from_friction(
                args.friction_csv,
                shear_strength=args.shear_strength,
                modulus=args.modulus,
                radius=args.radius,
                area=args.area,
                fit=args.fit,
            )
        )
        fit = targets[-1].meta["friction"].get("fit")
        if fit is not None:
            print(f"{targets[-1].name}: {fit['summary']}")
        _advise(args, targets[-1].name)
    if not targets:
        raise mi.MetainterfaceError("give at least one --target, --target-csv or --friction-csv")
    return targets


def _scale_free(args: argparse.Namespace) -> bool:
    """Whether --area, --modulus or --shear-strength is 'auto' or a range."""
    return any(
        v is not None and (v.strip().lower() == "auto" or ".." in v)
        for v in (args.area, args.modulus, args.shear_strength)
    )


def _advise(args: argparse.Namespace, name: str) -> None:
    """Before designing a friction law at a fixed scale: where it is out of reach, say
    which area, modulus or shear strength would bring it in."""
    import metainterface as mi

    fs = mi.feasible_scale(
        args.friction_csv,
        shear_strength=args.shear_strength,
        modulus=args.modulus,
        radius=args.radius,
        area=args.area,
        fit=args.fit,
    )
    if not fs.reachable:
        for line in fs.summary():
            print(f"{name}: {line}")
        print(f"{name}: --area auto (or a range, e.g. --modulus 1MPa..20MPa) chooses it")


def _design_scale(args: argparse.Namespace, options: dict) -> list:
    """--friction-csv with a free area, modulus or shear strength: the scale designed too."""
    import metainterface as mi
    from metainterface.api.scale import scale_line

    if args.target or args.target_csv or args.compare:
        raise mi.MetainterfaceError(
            "a free --area/--modulus/--shear-strength ('auto' or a range) designs one "
            "--friction-csv alone; leave out --target, --target-csv and --compare"
        )
    missing = [
        name
        for name, value in (
            ("--shear-strength", args.shear_strength),
            ("--modulus", args.modulus),
            ("--radius", args.radius),
        )
        if value is None
    ]
    if missing:
        raise mi.MetainterfaceError(f"--friction-csv needs {', '.join(missing)}")
    for key in ("modulus", "radius", "area"):  # the scale search sets them
        options.pop(key)
    if args.total_force is None:
        options.pop("total_force")
    r = mi.design_scale(
        args.friction_csv,
        shear_strength=args.shear_strength,
        modulus=args.modulus,
        radius=args.radius,
        area=args.area or "auto",
        fit=args.fit,
        method=args.method,
        out=args.out,
        **options,
    )
    fit = r.target.meta["friction"].get("fit")
    if fit is not None:
        print(f"{r.target.name}: {fit['summary']}")
    # the feasible ranges (the line on the scale 'given' would name the range's middle)
    for line in r.target.meta["scale"]["feasibility"]["summary"][1:]:
        print(f"{r.target.name}: {line}")
    print(scale_line(r))
    return [r]


def run(args: argparse.Namespace) -> int:
    import sys

    import metainterface as mi

    targets = [] if args.friction_csv and _scale_free(args) else _targets(args)
    options = dict(
        refine=args.refine == "lbfgs",
        surrogate=args.model,
        starts=args.starts,
        seed=args.seed,
        model=args.physics,
        hedge=args.hedge,
        fallback=args.fallback,
        max_pressure=args.max_pressure,
        modulus=args.modulus,
        radius=args.radius,
        total_force=args.total_force,
        area=args.area if args.total_force is None else None,
        settings=_settings(args),
        meta=_command(args),
        full_target=args.full_target,
        device=args.device,
        force=args.force,
        verify=_verify(args),
        **_manufacturing(args),
    )
    try:
        results = _run(args, targets, options)
    except mi.UnreachableError as exc:  # two lines: what is out of reach, what would fix it
        head, _, advice = exc.reachability.message.partition("\n")
        print(f"metainterface design: error: {exc.target}: {head}", file=sys.stderr)
        print(f"{advice} --force designs the closest cell anyway.".strip(), file=sys.stderr)
        return 2
    for r in results:
        for note in r.notes:
            print(f"warning: {note}", file=sys.stderr)
        if r.pressure is not None:
            print(f"{r.target.name} ({r.method}): {r.pressure.summary()}")
    _table(args, results)
    if args.html:  # one page per design folder
        from pathlib import Path

        out = Path(args.out)
        for r in results:
            page = mi.view(out if len(results) == 1 else out / r.target.name)
            print(f"{page}: interactive view, opens in a browser")
    print(f"written to {args.out}")
    high = [r for r in results if r.bem is not None and not r.bem_ok]
    for r in high:
        print(
            f"{r.target.name}: BEM error {100 * r.bem.bem_error:.3g} % is above "
            f"--max-bem-error {100 * r.bem.max_error:g} %: the made surface will miss the target"
        )
    return 3 if high else 0


def _run(args: argparse.Namespace, targets: list, options: dict) -> list:
    import metainterface as mi

    if not targets:  # a friction law with its scale free: the scale is designed too
        return _design_scale(args, options)
    if args.compare:
        if args.html:
            raise mi.MetainterfaceError("--html draws one design per page; leave out --compare")
        one = targets[0] if len(targets) == 1 else targets  # one target: files in --out
        by_method = mi.compare(one, out=args.out, **options)
        results = [r for m in by_method.values() for r in m]
    else:  # one target: its files directly in --out; several: one folder each
        made = mi.design(
            targets[0] if len(targets) == 1 else targets,
            method=args.method,
            out=args.out,
            **options,
        )
        results = made if isinstance(made, list) else [made]
    return results


def _table(args: argparse.Namespace, results: list) -> None:
    """The summary table: errors (the one curve error), coverage and carrying asperities."""
    width = max(len("target"), *(len(r.target.name) for r in results)) + 2
    head = (
        f"{'target':<{width}}{'method':<12}{'zero-shot':>11}{'error':>11}{'coverage':>10}"
        f"{'carrying':>10}{'seconds':>9}"
    )
    checked = [r for r in results if r.bem is not None]
    if checked:
        head += f"{'BEM':>11}{'BEM s':>8}"
    if args.robust:
        head += f"{'made p50':>11}{'made p95':>11}"
    if args.z_step is not None:
        head += f"{'unsnapped':>11}{'snapped':>11}"
    print(head)
    for r in results:
        line = (
            f"{r.target.name:<{width}}{r.method:<12}{100 * r.initial_error:>9.3g} %"
            f"{100 * r.error:>9.3g} %{100 * r.coverage:>8.3g} %"
            f"{f'{r.carrying}/{r.design.n_asperities}':>10}{r.seconds:>9.2f}"
        )
        if r.robust:
            line += f"{100 * r.robust['error_median']:>9.3g} %{100 * r.robust['error_p95']:>9.3g} %"
        if r.printable:
            q = r.printable
            line += f"{100 * q['error_before_snap']:>9.3g} %{100 * q['error_after_snap']:>9.3g} %"
        if r.bem is not None:
            line += f"{100 * r.bem.bem_error:>9.3g} %{_bem_seconds(r):>8.1f}"
        if r.forced:
            line += "  FORCED (out of reach)"
        print(line)
    if args.robust:
        print("error: the nominal design's; made p50/p95: of cells made with the errors given")
    if args.z_step is not None:
        print(
            "unsnapped/snapped: before the snap to the layer grid and right after it; error: "
            "after the shapes were re-refined"
        )
    print(
        "error: sqrt(fit^2 + (1 - coverage)^2), fit over the loads the design reaches; "
        "coverage: the share of the target's load range it reaches"
    )
    if checked:
        print(_bem_legend(checked))


def _verify(args: argparse.Namespace):
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


def _bem_seconds(r) -> float:
    """Wall time of a result's BEM solves [s]: the check, and the correction's."""
    return (r.bem_before or r.bem).seconds + sum(c.seconds for c in r.corrections)


def _bem_legend(results: list) -> str:
    """What the BEM column is, in one line (with the corrections made)."""
    b = results[0].bem
    line = (
        f"BEM: the design solved in BEM ({b.engine}, {b.grid}^2, {b.p_star.size} loads), "
        "its error to the target"
    )
    fixed = [r for r in results if r.bem_before is not None and r.bem is not r.bem_before]
    for r in fixed:
        steps = ", ".join(
            f"{100 * c.bem_error:.3g} %{'' if c.accepted else ' (not kept)'}" for c in r.corrections
        )
        line += (
            f"; {r.target.name} corrected in BEM: {100 * r.bem_before.bem_error:.3g} % -> "
            f"{100 * r.bem.bem_error:.3g} % (iterations: {steps})"
        )
    return line


def _manufacturing(args: argparse.Namespace) -> dict:
    """The robust-design and layer options, lengths in units of R (errors name the options)."""
    import metainterface as mi
    from metainterface.api.tolerance import layer_step, length_in_r
    from metainterface.physical import parse_length

    radius = None if args.radius is None else parse_length(args.radius, option="--radius")
    out: dict = {}
    if args.z_step is not None:
        delta_max = (_settings(args) or mi.CellSettings()).delta_max
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
    out.update(
        robust=True,
        sigma_h=sigma_h,
        sigma_gamma=args.sigma_gamma,
        scale_sigma=args.scale_sigma,
        robust_samples=args.robust_samples,
    )
    return out


def _settings(args: argparse.Namespace):
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


def _command(args: argparse.Namespace) -> dict:
    """The options as given, recorded in design.json."""
    return {k: v for k, v in vars(args).items() if k != "func"}
