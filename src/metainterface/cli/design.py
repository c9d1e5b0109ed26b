"""`metainterface design`: a unit cell whose alpha(P*) follows a target contact law."""

from __future__ import annotations

import argparse
from typing import Any

from metainterface._names import (
    DEFAULT_ENGINE,
    DEFAULT_MODEL,
    ENGINE_NAMES,
    FIT_NAMES,
    METHOD_NAMES,
    MODEL_NAMES,
)
from metainterface.cli._design_options import command, groups, settings, verify
from metainterface.cli._design_report import table
from metainterface.cli.common import SHOWN, add_device, positive_int


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "design",
        help="design a unit cell for a target contact law (the main job)",
        description="Zero-shot prediction by the shipped surrogate, then multi-stage L-BFGS "
        "refinement (or a multistart / Hertz-only baseline). Writes design.json, curve.csv "
        "and design.png into --out (one folder per target when there are several). Each "
        "design is then checked in the boundary element method (BEM) and its BEM error to the "
        "target reported beside the model's; exit status 3 when a design's BEM error is above "
        "--max-bem-error or, for a friction law with an offset (adhesion), its friction at "
        "zero load F_0 is more than 2 % off the law's (the files are written all the same), "
        "2 on bad input.",
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
        from metainterface.inverse.targets import friction_law_target
        from metainterface.units.friction import friction_target_from_options

        ft = friction_target_from_options(
            args.friction_csv,
            shear_strength=args.shear_strength,
            modulus=args.modulus,
            radius=args.radius,
            area=args.area,
            fit=args.fit,
            work_of_adhesion=getattr(args, "work_of_adhesion", None),
        )
        targets.append(friction_law_target(ft, args.friction_csv))
        fit = targets[-1].meta["friction"].get("fit")
        if fit is not None:
            print(f"{targets[-1].name}: {fit['summary']}")
        _advise(args, targets[-1])
    if not targets:
        raise mi.MetainterfaceError("give at least one --target, --target-csv or --friction-csv")
    return targets


def _scale_free(args: argparse.Namespace) -> bool:
    """Whether --area, --modulus or --shear-strength is 'auto' or a range."""
    return any(
        v is not None and (v.strip().lower() == "auto" or ".." in v)
        for v in (args.area, args.modulus, args.shear_strength)
    )


def _advise(args: argparse.Namespace, target: Any) -> None:
    """Before designing a friction law at a fixed scale: where it is out of reach, say
    which area, modulus or shear strength would bring it in."""
    import metainterface as mi

    name = target.name
    # with adhesion each modulus the search tries costs an envelope: ask the target first
    if args.work_of_adhesion is not None and mi.reachability(target).reachable:
        return
    fs = mi.feasible_scale(
        args.friction_csv,
        shear_strength=args.shear_strength,
        modulus=args.modulus,
        radius=args.radius,
        area=args.area,
        fit=args.fit,
        work_of_adhesion=args.work_of_adhesion,
    )
    if not fs.reachable:
        for line in fs.summary():
            print(f"{name}: {line}")
        print(f"{name}: --area auto (or a range, e.g. --modulus 1MPa..20MPa) chooses it")


def _design_scale(args: argparse.Namespace, options: dict) -> list:
    """--friction-csv with a free area, modulus or shear strength: the scale designed too."""
    import metainterface as mi
    from metainterface.scaling.choose import scale_line

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
    # the scale search sets the modulus, radius and area; a total force stays the user's
    options["scale"] = mi.Scale(total_force=args.total_force)
    r = mi.design_scale(
        args.friction_csv,
        shear_strength=args.shear_strength,
        modulus=args.modulus,
        radius=args.radius,
        area=args.area or "auto",
        fit=args.fit,
        work_of_adhesion=args.work_of_adhesion,
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
        model=args.physics,
        max_pressure=args.max_pressure,
        settings=settings(args),
        full_target=args.full_target,
        device=args.device,
        force=args.force,
        verify=verify(args),
        **groups(args),
    )
    if args.work_of_adhesion is not None and not args.friction_csv:  # a friction law carries it
        if args.compare:
            raise mi.MetainterfaceError(
                "--work-of-adhesion with --compare takes a --friction-csv target",
                argument="--work-of-adhesion",
            )
        from dataclasses import replace

        options["scale"] = replace(options["scale"], work_of_adhesion=args.work_of_adhesion)
    from metainterface._files.provenance import recording_command

    try:
        with recording_command(command(args)):  # design.json records the command line
            results = _run(args, targets, options)
    except mi.UnreachableError as exc:  # two lines: what is out of reach, what would fix it
        head, _, advice = exc.reachability.message.partition("\n")
        print(f"metainterface design: error: {exc.target}: {head}", file=sys.stderr)
        print(f"{advice} --force designs the closest cell anyway.".strip(), file=sys.stderr)
        return 2
    for r in results:
        for note in r.notes:
            if not any(note in said for said in SHOWN):  # said once already, before the work
                print(f"warning: {note}", file=sys.stderr)
        if r.pressure is not None:
            print(f"{r.target.name} ({r.method}): {r.pressure.summary()}")
    table(args, results)
    if args.html:  # one page per design folder
        from pathlib import Path

        out = Path(args.out)
        for r in results:
            page = mi.view(out if len(results) == 1 else out / r.target.name)
            print(f"{page}: interactive view, opens in a browser")
    print(f"written to {args.out}")
    high = [r for r in results if r.bem is not None and not r.bem_ok]
    for r in high:
        # the model's error at the check's own loads tells a design's miss there (the BEM
        # agrees) from mechanics the model leaves out; the table's error is on the target's
        # grid, which weighs the loads otherwise
        print(
            f"{r.target.name}: BEM error {r.bem.error_text()} is above "
            f"--max-bem-error {100 * r.bem.max_error:g} %: the made surface will miss the "
            f"target (the model's error at the same loads: {100 * r.bem.model_error:.3g} %)"
        )
    unmet = [r for r in results if r.f0_met is False]
    for r in unmet:  # an offset law's F_0: what a gripper is specified by
        print(
            f"{r.target.name}: friction at zero load F_0 is {100 * r.f0_error:.3g} % off the "
            "law's, above 2 %: the design does not meet the law's offset"
        )
    return 3 if high or unmet else 0


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
