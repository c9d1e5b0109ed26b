"""``reachability``: can a cell follow this friction law, at this E*, tau and area?"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from metainterface._threads import uses_threads
from metainterface.errors import MetainterfaceError, UnreachableError
from metainterface.inverse.targets import Target
from metainterface.physics.cell import CellSettings
from metainterface.units.friction import FrictionLaw, friction_target_in_units
from metainterface.units.reach import Reachability
from metainterface.units.reach import reachability as _reachability


@uses_threads()
def reachability(
    law: Target | FrictionLaw | str | os.PathLike[str],
    *,
    shear_strength: str | float | None = None,
    modulus: str | float | None = None,
    area: str | float | None = None,
    radius: str | float = "1mm",
    settings: CellSettings | None = None,
    work_of_adhesion: str | float | None = None,
) -> Reachability:
    """Whether cells of ``settings`` (default: the paper's) can follow a friction law.

    Parameters
    ----------
    law : Target, FrictionLaw or path
        A target (one made by ``Target.from_friction`` carries its tau, E* and area; any
        other is tested in alpha/P* terms), a FrictionLaw or a friction CSV
        (``normal_force,friction_force`` [N] or ``normal_force,friction_coefficient``).
    shear_strength, modulus, area : str or float
        tau, E* and the nominal area ('0.25MPa', '2MPa', '4cm2', or SI), for a law or CSV.
    radius : str or float
        Asperity radius R, only to check the area holds a unit cell (default '1mm').
    settings : CellSettings
        The design space (N, gamma bounds, Delta_max).
    work_of_adhesion : str or float
        w ('50mJ/m2', J/m^2) for adhesive contact (JKR asperities), with a law or CSV (a
        Target carries its own); then R sets w / (E* R) and should be the part's.

    Returns
    -------
    Reachability
        ``.reachable``, the law's ``law_mu``, the ``reachable_mu`` at its loads at this
        tau / E*, the ``load_range`` [N] on this area, and a one- or two-line ``.message``
        saying what would make the law reachable.
    """
    if settings is not None and not isinstance(settings, CellSettings):
        raise MetainterfaceError("settings must be a CellSettings")
    if isinstance(law, Target):
        if any(v is not None for v in (shear_strength, modulus, area)):
            raise MetainterfaceError(
                "a Target carries its own units; give shear_strength, modulus and area "
                "with a friction law or CSV only"
            )
        return target_reachability(law, settings)
    missing = [
        n
        for n, v in (("shear_strength", shear_strength), ("modulus", modulus), ("area", area))
        if v is None
    ]
    if missing:
        raise MetainterfaceError(
            f"a friction law needs shear_strength, modulus and area (missing {', '.join(missing)})",
            argument=missing[0],
        )
    ft = friction_target_in_units(
        law,
        shear_strength=shear_strength,
        modulus=modulus,
        radius=radius,
        area=area,
        settings=settings,
        work_of_adhesion=work_of_adhesion,
    )
    return _reachability(
        ft.law.normal_force,
        ft.law.friction_force,
        shear_strength=ft.shear_strength,
        e_star=ft.e_star,
        area=ft.area,
        settings=settings,
        adhesion=ft.adhesion,
    )


def target_reachability(target: Target, settings: CellSettings | None = None) -> Reachability:
    """The reachability of a target: in friction terms when it came from a friction law
    (its ``meta['friction']`` record), else in alpha/P* terms."""
    f: dict[str, Any] | None = target.meta.get("friction")
    if isinstance(f, dict) and {"shear_strength_pa", "e_star_pa", "area_m2"} <= set(f):
        # the full target holds the law's points (P*, alpha) in the record's units
        e_star, tau, a = f["e_star_pa"], f["shear_strength_pa"], f["area_m2"]
        return _reachability(
            np.asarray(target.p_star) * a * e_star,
            np.asarray(target.alpha) * tau * a,
            shear_strength=tau,
            e_star=e_star,
            area=a,
            settings=settings,
            adhesion=float(f.get("adhesion", 0.0) or 0.0),
        )
    return _reachability(target.p_star, target.alpha, settings=settings, units=False)


def refuse_unreachable(
    targets: list[Target], settings: CellSettings | None, force: bool
) -> dict[str, Reachability]:
    """The reachability of each friction-law target; an UnreachableError for the first one
    out of reach unless ``force``. Targets without a friction law are not refused (their
    envelope warnings stay in the notes)."""
    out = {}
    for t in targets:
        if "friction" not in t.meta:
            continue
        r = target_reachability(t, settings)
        out[t.name] = r
        if not r.reachable and not force:
            one_line = r.message.replace("\n", " ")
            raise UnreachableError(
                f"friction law {t.name}: {one_line} force=True designs the closest cell anyway.",
                reachability=r,
                target=t.name,
            )
    return out
