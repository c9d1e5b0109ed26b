"""Calibrate the interface: tau and w from a friction test (issue 38).

Few users know their interface shear strength tau or work of adhesion w. A friction test
gives both: of one sphere on the material (``sphere``: a JKR contact, :func:`calibrate_sphere`)
or of a made design (``design``: its cell under the adhesive model, :func:`calibrate_design`).
:func:`calibrate_csv` reads the test from a CSV for either. The result feeds
``--shear-strength`` and ``--work-of-adhesion`` of ``design``.
"""

from __future__ import annotations

import os

from metainterface.calibration.design import calibrate_design, design_friction
from metainterface.calibration.sphere import (
    Calibration,
    calibrate_sphere,
    jkr_contact_radius,
    sphere_friction,
)
from metainterface.errors import MetainterfaceError

__all__ = [
    "Calibration",
    "calibrate_csv",
    "calibrate_design",
    "calibrate_sphere",
    "design_friction",
    "jkr_contact_radius",
    "sphere_friction",
]


def calibrate_csv(
    path: str | os.PathLike[str],
    *,
    modulus: str | float,
    sphere_radius: str | float | None = None,
    design: str | os.PathLike[str] | None = None,
    area: str | float | None = None,
    radius: str | float | None = None,
    pull_off: str | float | None = None,
) -> Calibration:
    """tau and w from a friction CSV (``normal_force,friction_force`` [N], or
    ``normal_force,friction_coefficient``; units in the header), quantities with units.

    Either a sphere test (``sphere_radius``: :func:`calibrate_sphere`) or a made design's
    (``design``, a design.json: :func:`calibrate_design`), whose physical block gives R and
    the patch's nominal area (``area`` and ``radius`` give or override them) and whose
    "model" names the forward model (independent or interacting; none: independent).
    A sphere test's pull rows (negative normal force, down to pull-off) are used, and
    ``pull_off`` (the measured pull-off force, e.g. '0.92mN') constrains w. Messages give
    forces in the file's units. A test the model cannot explain is refused (one line).
    """
    from metainterface.units.law_file import read_friction_csv
    from metainterface.units.quantities import parse_area, parse_length, parse_pressure

    if (sphere_radius is None) == (design is None):
        raise MetainterfaceError(
            "calibrate a sphere test (--sphere-radius) or a made design's (--design), one of them",
            argument="--design",
        )
    e = parse_pressure(modulus, option="--modulus")
    law = read_friction_csv(path, check=False, pull=True)
    if pull_off is not None and sphere_radius is None:
        raise MetainterfaceError(
            "--pull-off is for a sphere test (--sphere-radius): a made design's pull-off "
            "depends on the path its patch came by",
            argument="--pull-off",
        )
    if sphere_radius is not None:
        if area is not None or radius is not None:
            raise MetainterfaceError(
                "--area and --radius are for a made design (--design); a sphere takes "
                "--sphere-radius",
                argument="--area" if area is not None else "--radius",
            )
        from metainterface.units.quantities import parse_force

        r = parse_length(sphere_radius, option="--sphere-radius")
        off = None if pull_off is None else parse_force(pull_off, option="--pull-off")
        return calibrate_sphere(
            law.normal_force,
            law.friction_force,
            radius=r,
            e_star=e,
            source=str(path),
            pull_off=off,
            unit=law.normal_unit,
        )
    from metainterface.physics.cell import Design

    d = Design.load(design)
    block = d.extras.get("physical") if isinstance(d.extras.get("physical"), dict) else {}
    if radius is None and "radius_m" not in block:
        raise MetainterfaceError(
            f"{design}: no physical block with the radius: give --radius", argument="--radius"
        )
    if area is None and "area_m2" not in block:
        raise MetainterfaceError(
            f"{design}: no physical block with the patch's area: give --area", argument="--area"
        )
    r = parse_length(radius, option="--radius") if radius is not None else block["radius_m"]
    a = parse_area(area, option="--area") if area is not None else block["area_m2"]
    # the forward model the design was made with (a design.json without one: the paper's)
    model = d.extras.get("model") or "independent"
    return calibrate_design(
        law.normal_force,
        law.friction_force,
        d,
        e_star=e,
        area=float(a),
        radius=float(r),
        source=str(path),
        model=model,
        unit=law.normal_unit,
    )
