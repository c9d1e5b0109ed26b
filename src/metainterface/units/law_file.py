"""A friction law as a lab writes it: the CSV read into newtons, and the checks a law must pass.

The file has a header and one row per load: ``normal_force,friction_force`` or
``normal_force,friction_coefficient`` (F_f = mu F_n), forces in newtons unless a header
gives a unit (``normal_force [mN]``); separators, decimal commas and comments as
:func:`metainterface._files.columns.read_table` reads them. Turning a law into a design
target is :mod:`metainterface.units.friction`'s concern.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from metainterface._files.columns import Table, read_table
from metainterface.errors import MetainterfaceError


@dataclass(frozen=True)
class FrictionLaw:
    """A friction curve in newtons, rows in strictly increasing normal force.

    normal_force, friction_force: (K,) [N]. rows: (K,) 1-based data rows of the source file
    (0 marks the origin added by ``friction_target``). source: file name for messages.
    """

    normal_force: np.ndarray
    friction_force: np.ndarray
    rows: np.ndarray
    source: str = "friction law"
    #: The file's force units, for messages in them: (label, newtons per unit) of the
    #: normal force's and the friction force's columns (``N``, 1.0 where none is given).
    normal_unit: tuple[str, float] = ("N", 1.0)
    friction_unit: tuple[str, float] = ("N", 1.0)


#: Column names of a friction CSV (each may carry a unit in its header: ``normal_force [mN]``).
FRICTION_NAMES = ("normal_force", "friction_force", "friction_coefficient")


def _unit(table: Table, name: str) -> tuple[str, float]:
    """(label, newtons per unit) of a force column, from the unit its header gives (none: N)."""
    from metainterface.units.quantities import force_unit

    unit = table.unit(name)
    where = f"{table.path}: column {name}" + ("" if unit is None else f" [{unit}]")
    label = unit.strip() if unit is not None and unit.strip() else "N"
    return label, force_unit(unit, where=where)


def in_unit(value: float, unit: tuple[str, float]) -> str:
    """A force [N] as the file writes it: ``-0.92363 mN`` for ``unit`` ("mN", 1e-3)."""
    return f"{value / unit[1]:.6g} {unit[0]}"


def read_friction_csv(
    path: str | os.PathLike[str], *, check: bool = True, pull: bool = False
) -> FrictionLaw:
    """Read a friction curve: ``normal_force,friction_force`` or ``...,friction_coefficient``.

    Forces in newtons unless the header gives a unit (``normal_force [mN]``,
    ``friction_force (kN)``, ``normal_force_uN``: any force unit pint reads); the coefficient
    dimensionless. Separators, decimal commas, comments: :func:`read_table`. Every value finite
    and >= 0 (``pull``: a negative normal force, a pull, allowed, as a sphere test down to
    pull-off has); with ``check`` also the rows as a law (normal force strictly increasing,
    friction never decreasing, no friction at zero load), else the rows as measured (any
    order, repeats).
    """
    path = Path(path)
    table = read_table(path, FRICTION_NAMES, numeric=FRICTION_NAMES)
    header = table.names
    if "friction_force" in header and "friction_coefficient" in header:
        raise MetainterfaceError(
            f"{path}: both friction_force and friction_coefficient columns; keep one "
            "(they could disagree, and one would be ignored)"
        )
    if "normal_force" not in header or not {"friction_force", "friction_coefficient"} & set(header):
        raise MetainterfaceError(
            f"{path}: missing column(s); the header must be normal_force,friction_force (N) or "
            f"normal_force,friction_coefficient (found {','.join(header) or 'nothing'})"
        )
    n_unit = _unit(table, "normal_force")
    normal = table.column("normal_force") * n_unit[1]
    if "friction_force" in header:
        f_unit = _unit(table, "friction_force")
        friction = table.column("friction_force") * f_unit[1]
    else:
        f_unit = n_unit
        unit = table.unit("friction_coefficient")
        if unit is not None:
            raise MetainterfaceError(
                f"{path}: column friction_coefficient [{unit}]: a friction coefficient is "
                f"dimensionless, write it without a unit"
            )
        mu = table.column("friction_coefficient")
        check_values(path, "friction_coefficient", mu)
        friction = mu * normal
    law = FrictionLaw(
        normal_force=normal,
        friction_force=friction,
        rows=np.arange(1, friction.size + 1),
        source=str(path),
        normal_unit=n_unit,
        friction_unit=f_unit,
    )
    if check:
        check_law(law)
    else:
        check_values(law.source, "normal_force", law.normal_force, n_unit, negative=pull)
        check_values(law.source, "friction_force", law.friction_force, f_unit)
    return law


def check_values(
    source: Any,
    name: str,
    values: np.ndarray,
    unit: tuple[str, float] | None = None,
    *,
    negative: bool = False,
) -> None:
    """A one-line error for the first value not finite or (unless ``negative``) below 0,
    in the file's ``unit`` (label, N per unit) where it has one."""
    for i, v in enumerate(values, start=1):
        if not math.isfinite(v) or (v < 0 and not negative):
            shown = f"{v:g}" if unit is None or not math.isfinite(v) else in_unit(v, unit)
            need = "finite" if negative else "finite and >= 0"
            raise MetainterfaceError(f"{source}: row {i}: {name} = {shown}; must be {need}")


def zero_load_friction(law: FrictionLaw, k: int, why: str = "") -> str:
    """The one-line error for row ``k``'s friction at zero normal force without adhesion."""
    return (
        f"{law.source}: row {law.rows[k]}: friction {law.friction_force[k]:g} N at zero "
        f"normal force{why}; with F_f = tau A_real (no adhesion) friction vanishes with the "
        f"load (give --work-of-adhesion for an adhesive contact)"
    )


def check_law(law: FrictionLaw, *, offset: bool = False) -> None:
    """Raise MetainterfaceError, naming the row, if the curve is impossible with tau > 0;
    ``offset`` (adhesion): friction at zero load is allowed."""
    fn, ff, rows, src = law.normal_force, law.friction_force, law.rows, law.source
    if fn.size < 2:
        raise MetainterfaceError(f"{src}: need at least 2 rows, got {fn.size}")
    check_values(src, "normal_force", fn)
    check_values(src, "friction_force", ff)
    for k in range(fn.size):
        if fn[k] == 0 and ff[k] > 0 and not offset:
            raise MetainterfaceError(zero_load_friction(law, k))
        if k == 0:
            continue
        if fn[k] <= fn[k - 1]:
            raise MetainterfaceError(
                f"{src}: row {rows[k]}: normal_force {fn[k]:g} N is not above row "
                f"{rows[k - 1]}'s {fn[k - 1]:g} N; rows must be in strictly increasing load"
            )
        if ff[k] < ff[k - 1] * (1 - 1e-12):
            raise MetainterfaceError(
                f"{src}: row {rows[k]}: friction {ff[k]:g} N at {fn[k]:g} N is below "
                f"{ff[k - 1]:g} N at the lower load {fn[k - 1]:g} N (row {rows[k - 1]}); with a "
                f"positive shear strength F_f = tau A_real cannot decrease as the load grows"
            )
