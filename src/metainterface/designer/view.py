"""``view``: the interactive HTML page of a design (a result, a Design, or a design folder)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from metainterface._files import strict_json
from metainterface._files.atomic import write_text
from metainterface.designer.curve_result import design_curve
from metainterface.designer.given import design_model
from metainterface.designer.results import DesignResult
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import Design
from metainterface.physics.registry import get_model

#: Files up to this size are embedded in the page (data: URIs); larger ones are linked.
EMBED_BYTES = 8_000_000
#: Most bytes embedded in one page, all files together.
EMBED_TOTAL = 24_000_000
#: Height-map points per lattice cell on the 3D surface (smooth enough, light to rotate).
SURFACE_POINTS = 40
#: Most target points sent to the page.
PAGE_POINTS = 512


def view(
    source: DesignResult | Design | str | os.PathLike[str],
    path: str | os.PathLike[str] | None = None,
) -> Path:
    """Write an interactive, self-contained HTML page of a design; returns its path.

    Parameters
    ----------
    source : DesignResult, Design, or path
        A result of :func:`design`, a :class:`Design`, a design folder (as ``design --out``
        writes it) or a design file.
    path : path
        The page to write (default: ``view.html`` in the design folder; required for a
        result or a Design).

    Returns
    -------
    Path
        The page written (atomically).

    The page shows alpha(P*) and S*(P*) against the target with hover values (and, for a
    target made from a friction law, the friction force and coefficient against the normal
    force in newtons), the unit cell as a 3D surface, the parameters, and the folder's files
    for download. plotly.js and the files (up to 8 MB each) are embedded, so the one file
    opens in a browser from disk, without a server or a network. Needs plotly
    (``pip install 'metainterface[view]'``).
    """
    from metainterface.plots.html import PageFile, design_html

    page = _collect(source, path)
    text = design_html(
        name=page["name"],
        summary=page["summary"],
        curve=page["curve"],
        target=page["target"],
        units=page["units"],
        heights=page["heights"],
        side=page["side"],
        length_unit=page["length_unit"],
        gamma=page["design"].gamma,
        h_over_delta=page["h_over_delta"],
        files=[PageFile(**f) for f in page["files"]],
        footer=page["footer"],
    )
    return write_text(page["path"], text)


def _collect(source: Any, path: str | os.PathLike[str] | None) -> dict[str, Any]:
    """Everything the page shows, from whichever source was given."""
    from metainterface import __version__

    record: dict[str, Any] = {}
    folder: Path | None = None
    if isinstance(source, DesignResult):
        design, name = source.design, source.target.name
        record = source.record()
        model = source.model
    elif isinstance(source, Design):
        design, name = source, "design"
        record = dict(source.extras)
        model = _model_of(design)
    elif isinstance(source, str | os.PathLike):
        file = Path(source)
        if file.is_dir():
            folder, file = file, file / "design.json"
        if not file.is_file():
            raise MetainterfaceError(f"view: {file} not found; give a design folder or file")
        folder = folder or file.parent
        design = Design.load(file)
        record = dict(design.extras)
        name = str(record.get("target", {}).get("name") or file.parent.name or file.stem)
        model = _model_of(design)
    else:
        raise MetainterfaceError(
            "view: source must be a DesignResult, a Design or a design folder/file path, "
            f"got {type(source).__name__}"
        )
    if path is None:
        if folder is None:
            raise MetainterfaceError("view: give path, the HTML file to write")
        path = folder / "view.html"
    path = Path(path)
    if path.suffix.lower() not in (".html", ".htm"):
        raise MetainterfaceError(f"view: path must end in .html, got {path.name!r}")

    curve = design_curve(design, model, steps=1024, resolve_engagement=True)
    target = _target(source, record)
    units = _units(source, record)
    st = design.settings
    d_max = st.delta_max
    h0 = (design.h - design.h.min()) / d_max
    heights, side, unit = _surface(design, record, float(h0.max()))
    files = _files(source, folder, path, record)
    error = record.get("relative_error")
    named = record.get("model")
    drawn = model.label
    if isinstance(named, str) and named != drawn:  # a model this session has not registered
        drawn = f"{drawn} (design.json names {named}, not registered here)"
    summary = [
        ("method", str(record.get("method", "given"))),
        ("forward model of the curves", drawn),
        *([("curve error", f"{100 * float(error):.3g} %")] if error is not None else []),
        *(
            [("coverage of the load range", f"{100 * float(record['coverage']):.3g} %")]
            if isinstance(record.get("coverage"), int | float)
            else []
        ),
        *([("FORCED", "the target is out of reach")] if record.get("forced") else []),
        ("asperities", f"{design.gamma.size} ({st.n_side} x {st.n_side})"),
        ("shape exponents γ", f"{design.gamma.min():.3f} to {design.gamma.max():.3f}"),
        ("height offsets h / Δmax", f"0 to {h0.max():.3g}"),
        ("P*max, αmax", f"{curve.p_star_max:.4g}, {curve.alpha_max:.4g}"),
    ]
    if units:
        summary.append(
            (
                "friction law",
                f"τ = {_stress(units['tau'])}, E* = {_stress(units['e_star'])}, "
                f"A = {units['area'] * 1e4:.4g} cm²",
            )
        )
    version = record.get("provenance", {}).get("version", __version__)
    return {
        "name": name,
        "path": path,
        "design": design,
        "curve": curve,
        "target": target,
        "units": units,
        "heights": heights,
        "side": side,
        "length_unit": unit,
        "h_over_delta": h0,
        "files": files,
        "summary": summary,
        "footer": f"metainterface {version}: design file format metainterface/design-v1",
    }


def _stress(pa: float) -> str:
    for unit, scale in (("GPa", 1e9), ("MPa", 1e6), ("kPa", 1e3)):
        if pa >= scale:
            return f"{pa / scale:.4g} {unit}"
    return f"{pa:.4g} Pa"


def _model_of(design: Design):
    """The model the design file recorded (adhesion included), else the default; a label
    this session cannot read (a model registered elsewhere) draws with the default."""
    try:
        return design_model(design)
    except MetainterfaceError:
        return get_model(None)


def _target(source: Any, record: dict[str, Any]):
    """(p_star, alpha, stiffness or None) of the target, at most PAGE_POINTS points."""
    from metainterface.plots.design import target_stiffness

    if isinstance(source, DesignResult):
        t = source.target
    else:
        stored = record.get("target")
        if not (isinstance(stored, dict) and "p_star" in stored and "alpha" in stored):
            return None
        from metainterface.inverse.targets import Target

        try:
            t = Target(
                p_star=stored["p_star"], alpha=stored["alpha"], name=str(stored.get("name", "t"))
            )
        except MetainterfaceError:
            return None
    keep = np.unique(np.linspace(0, t.p_star.size - 1, min(t.p_star.size, PAGE_POINTS)).astype(int))
    return t.p_star[keep], t.alpha[keep], target_stiffness(t)


def _units(source: Any, record: dict[str, Any]) -> dict | None:
    from metainterface.plots.design import friction_units

    if isinstance(source, DesignResult):
        return friction_units(source.target.meta)
    stored = record.get("target")
    return friction_units(stored) if isinstance(stored, dict) else None


def _surface(design: Design, record: dict[str, Any], h_top: float):
    """(M, M) heights / Delta_max with a floor, the cell side and its unit (mm when the
    radius is known, else units of R)."""
    from metainterface.validation.heightmap import height_map

    st = design.settings
    hm = height_map(design, grid=SURFACE_POINTS * st.n_side)
    # The cell corners lie far below anything that touches: a floor keeps the tips in view.
    z = np.maximum(hm.heights / st.delta_max, -(h_top + 3.0))
    radius_m = None
    physical = record.get("physical")
    if isinstance(physical, dict) and "radius_m" in physical:
        radius_m = float(physical["radius_m"])
    friction = record.get("target", {}).get("friction") if record else None
    if radius_m is None and isinstance(friction, dict) and "radius_m" in friction:
        radius_m = float(friction["radius_m"])
    side = st.cell_side / st.radius
    if radius_m:
        return z, side * radius_m * 1e3, "mm"
    return z, side, "R"


def _files(source: Any, folder: Path | None, page: Path, record: dict[str, Any]) -> list[dict]:
    """The files offered on the page: the folder's (small ones embedded), or, for an object
    not saved yet, its design.json made in memory."""
    if folder is None:
        design = source.design if isinstance(source, DesignResult) else source
        extra = record if isinstance(source, DesignResult) else {}
        data = (strict_json.dumps(design.to_dict(**extra), indent=2) + "\n").encode("utf-8")
        return [{"name": "design.json", "size": len(data), "data": data}]
    out, total = [], 0
    for f in sorted(folder.iterdir()):
        if not f.is_file() or f.name.startswith(".") or f.resolve() == page.resolve():
            continue
        size = f.stat().st_size
        embed = size <= EMBED_BYTES and total + size <= EMBED_TOTAL
        total += size if embed else 0
        out.append(
            {
                "name": f.name,
                "size": size,
                "data": f.read_bytes() if embed else None,
                "href": Path(os.path.relpath(f, page.parent)).as_posix(),
            }
        )
    return out
