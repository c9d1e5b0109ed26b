"""What a design writes: design.json, curve.csv, design.png (and target.csv, and
friction_fit.png for a fitted friction law) in one folder."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from metainterface._files import write_columns
from metainterface.plots import plot_design, save_figure

if TYPE_CHECKING:
    from metainterface.designer.results import DesignResult


def write_design_outputs(
    folder: Path, result: DesignResult, *, full_target: bool = False, **extra: Any
) -> Path:
    """Write the outputs of one designed cell into ``folder``; returns design.json.

    design.json holds the target once, decimated for figures; ``full_target`` writes the
    whole target to target.csv beside it. ``extra`` keys (the command line, a pressure
    check, the physical block) are stored in design.json beside the design.
    """
    t = result.target
    folder.mkdir(parents=True, exist_ok=True)
    record = result.record()
    if full_target:
        write_columns(
            folder / "target.csv",
            {"p_star": t.p_star, "alpha": t.alpha},
            target=t.name,
            sha256=record["target"]["sha256"],
        )
    curve = result.curve()
    write_columns(folder / "curve.csv", curve.columns(), target=t.name, method=result.method)
    save_figure(
        plot_design(result, result.figure_curve()),
        folder / "design.png",
        target=t.name,
        method=result.method,
    )
    friction = t.meta.get("friction") if isinstance(t.meta, dict) else None
    if isinstance(friction, dict) and "fit" in friction:  # the measured rows were fitted
        from metainterface.plots.lawfit import plot_friction_fit

        fig = plot_friction_fit(friction, t.name)
        save_figure(fig, folder / "friction_fit.png", target=t.name)
    return result.design.save(folder / "design.json", **record, **extra)
