"""Dimensionalisation of a design (paper sec. 2.3): the ``physical`` block of design.json.

The core is scale-free (lengths in units of R, pressures in units of E*). Fixing the asperity
radius R [m] and the equivalent modulus E* [Pa] of the material pair gives

    pressure          P = P* E*            (at the design's P*_max, Delta = Delta_max)
    heights, offsets  h_i R, Delta_max R   [m]
    cell side         L R, a_max R         [m]
    unit cells        N_cells = F_total / (P L^2)   for a total normal force F_total [N],
                      or N_cells = A / L^2 for a given nominal interface area A [m^2].

All values are in SI; the function is pure (no I/O).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import Design
from metainterface.physics.curves import design_sweep


def _positive(name: str, value: float | None) -> float | None:
    if value is None:
        return None
    value = float(value)
    if not (math.isfinite(value) and value > 0):
        raise MetainterfaceError(f"{name} must be finite and > 0, got {value!r}")
    return value


#: Most unit cells an interface may hold (a square metre of 1 um cells is 1e12).
MAX_CELLS = 1e15


def physical_block(
    design: Design,
    *,
    radius: float,
    e_star: float,
    total_force: float | None = None,
    area: float | None = None,
) -> dict[str, Any]:
    """The design in SI units, as a JSON-ready dict.

    radius: R [m]; e_star: E* [Pa]; total_force: F_total [N] the tiled interface must carry at
    the design's largest pressure (N_cells = F_total / (P L^2), paper sec. 2.3); area: the
    nominal area of the whole interface [m^2] instead (N_cells = A / L^2, e.g. the --area of a
    friction-law target). Give at most one of total_force and area.
    Keys end in their unit (_m, _m2, _pa, _n); lists follow the design's asperity order.
    """
    r_m = _positive("radius", radius)
    e_pa = _positive("modulus E*", e_star)
    f_n = _positive("total force", total_force)
    a_m2 = _positive("area", area)
    if f_n is not None and a_m2 is not None:
        raise MetainterfaceError("give a total force or an interface area, not both")
    s = design.settings
    scale = r_m / s.radius  # metres per core length unit
    sw = design_sweep(design)
    p_star_max = float(sw.p_star[0, -1])
    pressure = p_star_max * e_pa
    side = s.cell_side * scale
    h0 = design.h - design.h.min()
    out: dict[str, Any] = {
        "radius_m": r_m,
        "e_star_pa": e_pa,
        "p_star_max": p_star_max,
        "alpha_max": float(sw.alpha[0, -1]),
        "pressure_max_pa": pressure,
        "delta_max_m": s.delta_max * scale,
        "gamma": [float(g) for g in design.gamma],
        "height_offsets_m": [float(v) for v in h0 * scale],
        "profile": "z_i(r) = -(h_i + R/2 (r/R)^gamma_i), r from the asperity's centre [m]",
        "asperity_base_radius_m": r_m,
        "asperity_pitch_m": side / s.n_side,
        "a_max_m": s.a_max * scale,
        "cell_side_m": side,
        "cell_area_m2": side**2,
    }
    if f_n is not None:
        n_cells = f_n / (pressure * side**2)
        out.update(total_force_n=f_n, n_cells=n_cells, interface_area_m2=n_cells * side**2)
    elif a_m2 is not None:
        out.update(area_m2=a_m2, n_cells=a_m2 / side**2, force_at_pressure_max_n=pressure * a_m2)
    if "n_cells" in out:
        n_cells = out["n_cells"]
        if not (math.isfinite(n_cells) and 1.0 <= n_cells <= MAX_CELLS):
            what = "total_force" if f_n is not None else "area"
            raise MetainterfaceError(
                f"{what} gives {n_cells:.3g} unit cells of side {side:.3g} m; it must give "
                f"between 1 and {MAX_CELLS:g}",
                argument=what,
            )
        out["tiles_per_side"] = int(np.ceil(math.sqrt(n_cells) - 1e-9))
    return out
