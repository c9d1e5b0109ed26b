"""``mi.measure``: a scan in, the made part registered, its law predicted."""

from __future__ import annotations

import contextlib
import dataclasses
import os
from collections.abc import Sequence
from typing import Any

from metainterface._threads import uses_threads
from metainterface.errors import MetainterfaceError
from metainterface.measure.compensate import compensate as compensate_design
from metainterface.measure.compensate import process_from, solves
from metainterface.measure.predict import predict, shapes_of
from metainterface.measure.register import register
from metainterface.measure.result import Friction, MeasureResult
from metainterface.measure.scan import as_scan
from metainterface.physics.cell import Design


@uses_threads()
def measure(
    scan: Any,
    design: Design | str | os.PathLike[str],
    *,
    radius: Any,
    pixel_size: Any = None,
    size: Any = None,
    height_unit: str | None = None,
    modulus: Any = None,
    shear_strength: Any = None,
    area: Any = None,
    grid: int | None = None,
    loads: int = 8,
    model: Any = None,
    progress: bool = True,
    compensate: bool = False,
    out: str | os.PathLike[str] | None = None,
    device: Any = "auto",
    z_step: Any = None,
    work_of_adhesion: Any = None,
    also: Sequence[tuple[Any, Design | str | os.PathLike[str]]] = (),
) -> MeasureResult:
    """Measure a made part: read, level and register its scan, fit every asperity of every
    cell, and predict its friction law (BEM on the measured cell, and the forward model with
    the fitted asperities) against the design's target.

    scan: a file SurfaceTopography reads (X3P, SUR, OPD, DATX, GWY, NPY, text, ...; the
    ``measure`` extra), a (ny, nx) array (rows along y; give ``pixel_size``) or a Scan.
    design: the Design (or design file) that was printed. radius: R, e.g. "0.5mm" (a number
    is metres). size, height_unit: the scan's lateral size and height unit where its file
    has none (an array's heights are in ``height_unit``, default metres). modulus,
    shear_strength, area: E* [Pa], tau [Pa], nominal area [m^2] (all three or none), for
    friction in newtons. grid: the measured cell's BEM grid (default: twice the scan's
    resolution, 64 n to 256 n). loads: BEM loads (the error's accuracy comes from the same
    loads on a grid half as fine). progress: a bar over the BEM loads. compensate: also
    design the next print (``MeasureResult.compensation``; the same as ``.compensate()``
    later), judged in BEM on its predicted made cell and kept only if it improves.
    z_step: the printer's layer step (e.g. "1um") where known (else read from the scan's
    terraces). work_of_adhesion: an adhesive part's (e.g. "50mJ/m2", with ``modulus``):
    its cell is solved in the JKR-limit BEM, against the design's adhesive target. out: a
    folder to write measured.json, bem.csv, measured.png (and compensated.json) in
    (``MeasureResult.write``). device: where the BEM runs ("auto", "cpu", "cuda",
    "cuda:N"). also: more (scan, design) pairs of the same print (read as ``scan`` is),
    registered only, whose made asperities and shapes join this one's in the process that
    ``compensate`` models.

    Returns a :class:`MeasureResult` (``.registration``, ``.prediction``, ``.error``,
    ``.compensate()``, ``.write(folder)``). Raises MetainterfaceError in one line: unknown
    format, no lateral size, a scan smaller than one lattice cell, one that does not show
    this design's lattice.
    """
    if also and not compensate:
        raise MetainterfaceError("also gives more scans for compensate; set compensate=True")
    if not isinstance(design, Design):
        design = Design.load(design)
    read: dict[str, Any] = {}
    if size is not None:
        read["size"] = size
    if height_unit is not None:
        read["height_unit"] = height_unit
    if "size" in read and not isinstance(scan, str | os.PathLike):
        raise MetainterfaceError("size is for a scan file; an array takes pixel_size")
    s = as_scan(scan, radius=radius, pixel_size=pixel_size, **read)
    # the modulus alone serves an adhesive part's work of adhesion
    alone = work_of_adhesion is not None and shear_strength is None and area is None
    friction = None if alone else _friction(modulus, shear_strength, area)
    z = None if z_step is None else _length(z_step, "z_step") / s.radius_m
    adhesion = 0.0
    if work_of_adhesion is not None:
        from metainterface.units.quantities import parse_work_of_adhesion

        if friction is None and modulus is None:
            raise MetainterfaceError("work_of_adhesion needs the modulus (E*) too")
        e_star = friction.modulus if friction is not None else _pressure(modulus)
        w = parse_work_of_adhesion(work_of_adhesion, option="work_of_adhesion")
        adhesion = w / (e_star * s.radius_m)
    if isinstance(loads, bool) or not isinstance(loads, int) or not 2 <= loads <= 200:
        raise MetainterfaceError(f"loads must be a whole number in [2, 200], got {loads!r}")
    if out is not None:
        from metainterface._files.atomic import check_output_folder

        check_output_folder(out)  # before the work, not after
    if grid is not None:
        from metainterface.validation import check_grid

        grid = check_grid(grid, design.settings)
    reg = register(s, design)
    if reg.orientation.unit_slip:
        import warnings

        from metainterface.errors import UnitSlipWarning
        from metainterface.measure.report import height_slip

        warnings.warn(height_slip(reg.orientation.height_scale), UnitSlipWarning, stacklevel=2)
    s = reg.scan  # as registered: mirrored where the file's y axis runs the other way
    with contextlib.ExitStack() as stack:
        report = None
        if progress:
            from tqdm.auto import tqdm

            bar = stack.enter_context(tqdm(total=2 * loads, desc="BEM loads", unit="load"))
            report = bar.update
        pred = predict(
            s,
            reg,
            design,
            grid=grid,
            loads=loads,
            model=model,
            report=report,
            device=device,
            z_step=z,
            adhesion=adhesion,
        )
    result = MeasureResult(
        scan=s, design=design, registration=reg, prediction=pred, friction=friction
    )
    if compensate:
        triples = [(design, reg, pred.shapes)]
        for other_scan, other_design in also:
            d = other_design if isinstance(other_design, Design) else Design.load(other_design)
            other = as_scan(other_scan, radius=radius, pixel_size=pixel_size, **read)
            other_reg = register(other, d)
            triples.append((d, other_reg, shapes_of(other_reg.scan, other_reg, d, z_step=z)[1]))
        with contextlib.ExitStack() as stack:
            report = None
            if progress:
                from tqdm.auto import tqdm

                total = solves()
                bar = stack.enter_context(tqdm(total=total, desc="correction", unit="BEM"))
                report = bar.update
            comp = compensate_design(
                design,
                process_from(triples, z_step=z),
                model=model,
                grid=pred.grid,
                loads=loads,
                device=device,
                radius_m=s.radius_m,
                report=report,
            )
        result = dataclasses.replace(result, compensation=comp)

    if out is not None:
        result.write(out)
    return result


def _length(value: Any, name: str) -> float:
    from metainterface.units import parse_length

    return parse_length(value, option=name)


def _pressure(value: Any) -> float:
    from metainterface.units import parse_pressure

    return parse_pressure(value, option="modulus")


def _friction(modulus: Any, shear_strength: Any, area: Any) -> Friction | None:
    given = [v is not None for v in (modulus, shear_strength, area)]
    if not any(given):
        return None
    if not all(given):
        raise MetainterfaceError(
            "friction in newtons needs modulus, shear_strength and area together"
        )
    from metainterface.units import parse_area, parse_pressure

    return Friction(
        modulus=parse_pressure(modulus, option="modulus"),
        shear_strength=parse_pressure(shear_strength, option="shear_strength"),
        area=parse_area(area, option="area"),
    )
