"""What `design` writes for each target: design.json, target.csv, curve.csv, design.png."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from metainterface.io.csvfiles import write_columns
from metainterface.io.design_file import save_design
from metainterface.physics.cell import Design
from metainterface.physics.forward import design_sweep_for
from metainterface.physics.limits import PressureCheck, check_pressure


def pressure_check(design: Design, limit: float, e_star: float | None = None) -> PressureCheck:
    """Peak pressures of a design against a limit given as p/E* (reported in Pa with E*)."""
    # check_pressure takes a stress [Pa] when it is given the modulus
    if e_star:
        return check_pressure(design, limit * e_star, e_star=e_star)
    return check_pressure(design, limit)


def _origin(result: Any) -> str:
    """Which start a DesignResult came from, in words (random starts numbered from 1)."""
    if result.fallback:
        return f"fallback multistart, random start {result.start + 1}"
    if result.method != "surrogate":
        return f"random start {result.start + 1}"
    return "zero-shot" if result.start == 0 else f"hedge random start {result.start}"


def write_design_outputs(
    folder: Path,
    result: Any,
    *,
    args: argparse.Namespace | None = None,
    pressure: PressureCheck | None = None,
) -> Path:
    """Write the four outputs of one designed cell into ``folder``; returns design.json."""
    t = result.target
    d = Design(gamma=result.gamma, h=result.h, settings=result.settings)
    extra: dict[str, Any] = {
        "target": {
            "name": t.name,
            "source": t.source,
            "p_star": t.p_star.tolist(),
            "alpha": t.alpha.tolist(),
            **t.meta,
        },
        "method": result.method,
        "physics": result.physics,
        "winning_start": _origin(result),
        "relative_error": result.error,
        "zero_shot_error": result.initial_error,
        "seconds": result.seconds,
    }
    if args is not None:
        extra["command"] = {k: v for k, v in vars(args).items() if k != "func"}
    if pressure is not None:
        extra["pressure_check"] = pressure.to_dict()
    if args is not None and args.radius and args.modulus:
        from metainterface.io.physical import physical_block
        from metainterface.io.units import parse_area, parse_force, parse_length, parse_pressure

        extra["physical"] = physical_block(
            d,
            radius=parse_length(args.radius, option="--radius"),
            e_star=parse_pressure(args.modulus, option="--modulus"),
            total_force=parse_force(args.total_force, option="--total-force")
            if args.total_force
            else None,
            area=parse_area(args.area, option="--area")
            if args.area and not args.total_force
            else None,
        )
    folder.mkdir(parents=True, exist_ok=True)
    write_columns(folder / "target.csv", {"p_star": t.p_star, "alpha": t.alpha}, target=t.name)
    sw = design_sweep_for(d, physics=result.physics, n_delta=256)
    write_columns(
        folder / "curve.csv",
        {
            "delta": sw.delta.numpy(),
            "p_star": sw.p_star[0].numpy(),
            "alpha": sw.alpha[0].numpy(),
            "stiffness": sw.stiffness[0].numpy(),
        },
        target=t.name,
        method=result.method,
    )
    from metainterface.plots import plot_design, save_figure

    save_figure(plot_design(result), folder / "design.png", target=t.name, method=result.method)
    return save_design(folder / "design.json", d, **extra)
