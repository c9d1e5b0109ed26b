"""What to do with a design you have: its alpha(P*) curve, its dimensions in SI, its
pressure check and its STL. numpy and lists in, numpy out; every argument checked with a
one-line MetainterfaceError."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from metainterface import _checks
from metainterface._device import resolve_device
from metainterface._files import check_output_file
from metainterface._threads import uses_threads
from metainterface.designer.curve_result import CURVE_STEPS, Curve, design_curve, idle_notes
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings, Design
from metainterface.physics.limits import PressureCheck, check_pressure
from metainterface.physics.models import ForwardModel
from metainterface.physics.registry import get_model
from metainterface.units.dimensions import physical_block
from metainterface.units.plausible import warn_unit_slips
from metainterface.units.quantities import (
    parse_area,
    parse_force,
    parse_length,
    parse_pressure,
    parse_pressure_limit,
)
from metainterface.units.recorded import recorded

#: Most points of a curve (a sane run time).
MAX_STEPS = 1_000_000
#: Physical inputs in SI, with their units for messages: beyond these a number is a typo.
PHYSICAL_RANGES = {
    "radius": (1e-9, 10.0, "m"),
    "modulus": (1e-3, 1e13, "Pa"),
    "total_force": (1e-12, 1e12, "N"),
    "area": (1e-18, 1e6, "m^2"),
}
#: Softplus steepness kappa_s [1/R]: below this the relaxed bracket is no longer a contact.
SMOOTH_RANGE = (1.0, 1e15)


def _physical(name: str, value: float) -> float:
    low, high, unit = PHYSICAL_RANGES[name]
    if not low <= value <= high:
        raise MetainterfaceError(
            f"{name} must be between {low:g} and {high:g} {unit}, got {value:g} {unit}",
            argument=name,
        )
    return value


def _limit(max_pressure: float | str | None, modulus: str | float | None) -> float | None:
    if max_pressure is None:
        return None
    e_star = None if modulus is None else parse_pressure(modulus, option="modulus")
    return parse_pressure_limit(
        max_pressure, e_star=e_star, option="max_pressure", modulus_option="modulus"
    )


def _physical_options(radius: Any, modulus: Any, total_force: Any, area: Any) -> dict | None:
    """Parsed SI options of the physical block, or None without radius and modulus."""
    if radius is None or modulus is None:
        if total_force is not None or area is not None:
            raise MetainterfaceError("total_force and area need radius and modulus too")
        return None
    if total_force is not None and area is not None:
        raise MetainterfaceError("give total_force or area, not both")
    r = _physical("radius", parse_length(radius, option="radius"))
    e_star = _physical("modulus", parse_pressure(modulus, option="modulus"))
    warn_unit_slips(modulus=e_star, radius=r)
    return {
        "radius": r,
        "e_star": e_star,
        "total_force": None
        if total_force is None
        else _physical("total_force", parse_force(total_force, option="total_force")),
        "area": None if area is None else _physical("area", parse_area(area, option="area")),
    }


def as_design(
    design: Design | str | os.PathLike[str] | None,
    gamma: Any,
    h: Any,
    settings: CellSettings | None,
) -> Design:
    """A Design from a Design, a design file, or gamma and h lists."""
    if design is not None:
        if gamma is not None or h is not None:
            raise MetainterfaceError("give a design or gamma and h, not both")
        if isinstance(design, Design):
            return design
        if isinstance(design, str | os.PathLike):
            return Design.load(design)
        raise MetainterfaceError(
            f"design must be a Design or a design file path, got {type(design).__name__}"
        )
    if gamma is None or h is None:
        raise MetainterfaceError("give a design, or both gamma and h")
    if settings is not None and not isinstance(settings, CellSettings):
        raise MetainterfaceError("settings must be a CellSettings")
    gamma, h = _checks.vector("gamma", gamma), _checks.vector("h", h)
    if settings is not None and gamma.size != settings.n_asperities:
        raise MetainterfaceError(
            f"gamma has {gamma.size} values but settings.n_asperities is {settings.n_asperities}",
            argument="gamma",
        )
    return Design(gamma=gamma, h=h, settings=settings or CellSettings())


@uses_threads()
def curve(
    design: Design | str | os.PathLike[str] | None = None,
    *,
    gamma: Sequence[float] | np.ndarray | None = None,
    h: Sequence[float] | np.ndarray | None = None,
    settings: CellSettings | None = None,
    model: str | ForwardModel | None = None,
    steps: int = CURVE_STEPS,
    smooth: float | None = None,
    device: str = "auto",
) -> Curve:
    """The alpha(P*) and S*(P*) curve of a design along Delta in [0, Delta_max].

    Parameters
    ----------
    design : Design or path
        The design, or a design file; or give ``gamma`` and ``h`` instead.
    gamma, h : list or array, shape (N,)
        Shape exponents and height offsets [units of R], N a perfect square.
    settings : CellSettings
        The cell of ``gamma`` and ``h`` (default: the paper's).
    model : str or ForwardModel
        The forward model (default: the one a design file recorded, adhesion included,
        else ``"independent"``).
    steps : int
        Delta samples, in [2, 1000000].
    smooth : float
        Softplus steepness kappa_s [1/R] instead of the exact bracket, in [1, 1e15].
    device : str
        Where the sweep runs: ``"auto"``, ``"cpu"``, ``"cuda"`` or ``"cuda:N"``.

    Returns
    -------
    Curve
        numpy ``delta``, ``p_star``, ``alpha``, ``stiffness`` (steps,).
    """
    d = as_design(design, gamma, h, settings)
    steps = _checks.whole("steps", steps, low=2, high=MAX_STEPS)
    if smooth is not None:
        smooth = _checks.number("smooth", smooth, low=SMOOTH_RANGE[0], high=SMOOTH_RANGE[1])
    dev = resolve_device(device, small=True)
    return design_curve(d, design_model(d, model), steps=steps, smooth=smooth, device=dev)


@uses_threads()
def export(
    design: Design | str | os.PathLike[str],
    path: str | os.PathLike[str],
    *,
    radius: str | float | None = None,
    tiles: tuple[int, int] | str = (1, 1),
    format: str | None = None,
    resolution: float | None = None,
    base: str | float = "1mm",
    z_step: str | float | None = None,
    flank_step: int = 4,
    force: bool = False,
) -> dict[str, Any]:
    """Write the design's surface for manufacture: STL (mm), 16-bit PNG/TIFF or NPY (m).

    Parameters
    ----------
    design : Design or path
    path : path
        Output file; its suffix picks the format unless ``format`` is given. A sidecar
        ``path.json`` records the height scale, grid and provenance.
    radius : str or float
        Asperity radius R ('0.5mm', or metres); default: the one the design file records
        (its physical block, or the friction law it was designed for).
    tiles : (nx, ny), 'NXxNY' or 'auto'
        Cells along x and y; 'auto': the tiling design.json's physical block gives for the
        area or total force designed for (a design.json path written with them, e.g. by
        ``design_scale`` or ``metainterface design --area auto``).
    format : {"stl", "png", "tiff", "npy"}
    resolution : float
        Grid points per mm (default 64 per asperity pitch).
    base : str or float
        STL base plate thickness under the surface (default 1 mm).
    z_step : str or float
        A printer's layer height ('1um', or a plain number in units of R), at most
        Delta_max: the asperities' height offsets are snapped to its multiples (a design
        made with ``design(..., z_step=...)`` already sits on them; the sidecar records the
        largest shift).
    flank_step : int
        STL only: the flanks between the asperities' contact zones are meshed on every
        flank_step-th grid line (default 4; 1 meshes every line), in [1, 64].
    force : bool
        Write a file over 100 MB; without it such an export raises an error that states
        the size and how to make it smaller, and writes nothing.

    Returns
    -------
    dict
        The sidecar record (size, grid, triangles, ...).
    """
    from metainterface.io.export import export_design

    check_output_file(path)
    d = as_design(design, None, None, None)
    if isinstance(tiles, str) and tiles.strip().lower() == "auto":
        tiles = _designed_tiles(design)
    if resolution is not None:
        resolution = _checks.number("resolution", resolution, low=0.0, low_open=True)
    made_for = recorded(d, "radius_m")
    if radius is None and made_for is None:
        raise MetainterfaceError(
            "radius is needed: the design file records no asperity radius (no physical or "
            "friction-law block); give one, e.g. '0.5mm'",
            argument="radius",
        )
    radius_m = made_for if radius is None else parse_length(radius, option="radius")
    _physical("radius", radius_m)
    warn_unit_slips(radius=radius_m)
    scale_note = ()
    if made_for is not None and abs(radius_m / made_for - 1) > 1e-9:
        scale_note = (
            f"radius {radius_m * 1e3:.4g} mm is not the {made_for * 1e3:.4g} mm the design file "
            "records: the part is scaled by R (its forces at a given pressure by R^2), so it "
            "is not the part designed for",
        )
    source = str(design) if isinstance(design, str | os.PathLike) else None
    step = None
    if z_step is not None:
        from metainterface.units.printer import layer_step

        step = layer_step(z_step, radius_m, d.settings.delta_max)
    flank_step = _checks.whole("flank_step", flank_step, low=1, high=64)
    if not isinstance(force, bool):
        raise MetainterfaceError(f"force must be True or False, got {force!r}")
    notes = (*idle_notes(d), *_cells_note(d, tiles), *scale_note)
    record = export_design(
        d,
        path,
        z_step=step,
        radius=radius_m,
        tiles=tiles,
        fmt=format,
        resolution=resolution,
        base=_checks.number("base", parse_length(base, option="base"), low=1e-6, high=1.0),
        source=source,
        flank_step=flank_step,
        force=force,
    )
    return {**record, "notes": list(notes)} if notes else record


def _cells_note(d: Design, tiles: Any) -> tuple[str, ...]:
    """A note when the export's cells are fewer than the design file's physical block says
    the interface holds."""
    from metainterface.io.export import parse_tiles

    block = d.extras.get("physical")
    if not isinstance(block, dict) or "tiles_per_side" not in block:
        return ()
    nx, ny = parse_tiles(tiles)
    per_side = block["tiles_per_side"]
    if nx >= per_side and ny >= per_side:
        return ()
    return (
        f"this export is {nx}x{ny} unit cells (one cell: {block['cell_side_m'] * 1e3:.4g} mm "
        f"square, {d.n_asperities} asperities); the design's physical block covers its area "
        f"with {block['n_cells']:.3g} cells: --tiles {per_side}x{per_side} for the whole patch",
    )


def _designed_tiles(design: Any) -> tuple[int, int]:
    """(n, n) from the physical block of a design.json (tiles='auto')."""
    import json

    block = None
    if isinstance(design, str | os.PathLike):
        try:
            block = json.loads(Path(design).read_text()).get("physical")
        except (OSError, ValueError, AttributeError):
            block = None
    if not isinstance(block, dict) or "tiles_per_side" not in block:
        raise MetainterfaceError(
            "tiles='auto' needs a design.json whose physical block has the tiling (designed "
            "with radius, modulus and an area or total force); give tiles as (nx, ny)",
            argument="tiles",
        )
    n = int(block["tiles_per_side"])
    return n, n


@uses_threads()
def physical(
    design: Design,
    *,
    radius: str | float,
    modulus: str | float,
    total_force: str | float | None = None,
    area: str | float | None = None,
) -> dict[str, Any]:
    """The design in SI units for an asperity radius and a modulus (paper sec. 2.3): the
    pressure at P*_max, heights, cell side and, for a total force or an area, the number of
    unit cells. Keys end in their unit (_m, _m2, _pa, _n)."""
    opts = _physical_options(radius, modulus, total_force, area)
    assert opts is not None
    return physical_block(as_design(design, None, None, None), **opts)


@uses_threads()
def pressure_check(
    design: Design, max_pressure: float | str, *, modulus: str | float | None = None
) -> PressureCheck:
    """Each asperity's peak contact pressure at Delta_max against a limit (p/E*, or a stress
    with ``modulus``): which asperities would yield."""
    limit = _limit(max_pressure, modulus)
    assert limit is not None
    d = as_design(design, None, None, None)
    if modulus is None:
        return check_pressure(d, limit)
    e_star = parse_pressure(modulus, option="modulus")
    return check_pressure(d, limit * e_star, e_star=e_star)


def design_model(design: Design, model: str | ForwardModel | None = None) -> ForwardModel:
    """The model to evaluate ``design`` with: ``model`` if given, else the one its file
    recorded (design.json's "model": an adhesive design keeps its adhesion), else the
    default."""
    if model is not None:
        return get_model(model)
    label = design.extras.get("model")
    if isinstance(label, str):
        return get_model(label)
    return get_model(None)
