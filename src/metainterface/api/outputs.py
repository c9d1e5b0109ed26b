"""What a design writes: design.json, target.csv, curve.csv, design.png in one folder."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from metainterface._files import write_columns
from metainterface.plots import plot_design, save_figure

if TYPE_CHECKING:
    from metainterface.api.results import DesignResult


def write_design_outputs(folder: Path, result: DesignResult, **extra: Any) -> Path:
    """Write the four outputs of one designed cell into ``folder``; returns design.json.

    ``extra`` keys (the command line, a pressure check, the physical block) are stored in
    design.json beside the design and how it was made.
    """
    t = result.target
    folder.mkdir(parents=True, exist_ok=True)
    write_columns(folder / "target.csv", {"p_star": t.p_star, "alpha": t.alpha}, target=t.name)
    curve = result.curve()
    write_columns(folder / "curve.csv", curve.columns(), target=t.name, method=result.method)
    save_figure(
        plot_design(result, curve), folder / "design.png", target=t.name, method=result.method
    )
    return result.design.save(folder / "design.json", **result.record(), **extra)
