"""`metainterface design`: a unit cell whose alpha(P*) follows a target contact law."""

from __future__ import annotations

import argparse
from typing import Any

from metainterface.cli import _design_args as _args
from metainterface.cli._design_options import command, groups, settings, verify
from metainterface.cli._design_report import table
from metainterface.cli.common import SHOWN


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
    _args.target_arguments(p)
    _args.unit_arguments(p)
    _args.output_arguments(p)
    _args.method_arguments(p)
    _args.space_arguments(p)
    _args.manufacturing_arguments(p)
    _args.limit_arguments(p)
    _args.check_arguments(p)
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
