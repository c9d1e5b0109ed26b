"""The forward model a design uses for adhesive targets (issue 38).

Adhesion is a property of the forward model (``Independent(adhesion=w)``): a friction law
converted with a work of adhesion (``Target.from_friction(work_of_adhesion=...)``) carries
w / (E* R) in ``meta["friction"]["adhesion"]``, and the design step's model takes it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from metainterface.errors import MetainterfaceError
from metainterface.inverse.envelope import target_adhesion
from metainterface.inverse.offset import extrapolated
from metainterface.physics.models import ForwardModel


def given_adhesion(
    work_of_adhesion: str | float | None, modulus: str | float | None, radius: str | float | None
) -> float:
    """w / (E* R) from ``design``'s work_of_adhesion ('50mJ/m2' or J/m^2) and its scale's
    modulus and radius (both needed: w is dimensionless only against E* R); 0 if None."""
    if work_of_adhesion is None:
        return 0.0
    from metainterface.units.plausible import warn_unit_slips
    from metainterface.units.quantities import (
        parse_length,
        parse_pressure,
        parse_work_of_adhesion,
    )

    w = parse_work_of_adhesion(work_of_adhesion, option="work_of_adhesion")
    warn_unit_slips(work_of_adhesion=w)  # '5' is 5 J/m^2: likely meant mJ/m^2
    if modulus is None or radius is None:
        raise MetainterfaceError(
            "work_of_adhesion needs the modulus and radius too (w / (E* R) sets the contact)",
            argument="work_of_adhesion",
        )
    e_star = parse_pressure(modulus, option="modulus")
    r = parse_length(radius, option="radius")
    return w / (e_star * r)


def model_for_targets(
    model: ForwardModel, targets: Sequence[Any], adhesion: float = 0.0
) -> ForwardModel:
    """``model`` with the adhesion its targets were converted with (or ``adhesion``,
    w / (E* R), given to ``design``).

    Targets designed in one batch share one model: their adhesions must agree (or be 0).
    A model given with an adhesion of its own keeps it; one that differs from a target's
    is an error (the law would be designed for another contact).
    """
    values = {round(target_adhesion(t), 15) for t in targets} | {round(adhesion, 15)}
    values -= {0.0}
    if not values:
        return model
    if len(values) > 1:
        raise MetainterfaceError(
            "targets designed together must share one work of adhesion (relative to E* R), "
            f"got {sorted(values)}; design them separately"
        )
    w = values.pop()
    if model.adhesion:
        if abs(model.adhesion - w) > 1e-9 * w:
            raise MetainterfaceError(
                f"the model's adhesion {model.adhesion:g} differs from the target's {w:g} "
                "(work of adhesion / (E* R)); give one of them",
                argument="model",
            )
        return model
    return model.with_adhesion(w)


#: The work of adhesion a friction-law design without one is checked at [J/m^2]: typical of
#: the elastomers these parts are moulded or printed in (PDMS, silicones, TPU) on glass or
#: a polished counterface, 40-70 mJ/m^2 (issue 38, item 6).
STATED_WORK_OF_ADHESION = 0.05


def adhesion_notes(
    result: Any, work_of_adhesion: float = STATED_WORK_OF_ADHESION
) -> tuple[str, ...]:
    """Notes on adhesion for a design of a friction law (none for other targets).

    With adhesion: the cell's pull-off force over the interface (how sticky it feels).
    Without: how much a work of adhesion ``work_of_adhesion`` [J/m^2] would change the
    design's friction at the law's smallest and largest loads, and at zero load, so a
    user who leaves adhesion out sees when that is unsafe.
    """
    import numpy as np
    import torch

    from metainterface.physics.jkr import ADHESION_LIMIT

    friction = (getattr(result.target, "meta", None) or {}).get("friction")
    if not isinstance(friction, dict) or "e_star_pa" not in friction:
        return ()
    e_star, radius = float(friction["e_star_pa"]), float(friction["radius_m"])
    tau, area = float(friction["shear_strength_pa"]), float(friction["area_m2"])
    design, model = result.design, result.model
    gamma, h = design.tensors(torch.float64)
    s = design.settings
    if model.adhesion:
        p_off = model.design_pull_off(design)
        notes = (
            f"adhesion: pull-off force {p_off * e_star * area:.3g} N over the interface "
            f"(P*_off = {p_off:.3g}, w = {friction.get('work_of_adhesion_j_m2', 0) * 1e3:.3g} "
            "mJ/m^2)",
        )
        return notes + _offset_note(result, gamma, h, tau * area)
    w = work_of_adhesion / (e_star * radius)
    if not 0 < w <= ADHESION_LIMIT or not model.takes_adhesion:
        return ()
    sticky = model.with_adhesion(w)
    p = np.asarray(result.target.p_star, dtype=np.float64)
    p = p[p > 0]
    if p.size == 0:
        return ()
    loads = torch.as_tensor(np.array([p[0], p[-1]]))[None]
    try:
        with torch.no_grad():
            plain = model.alpha_at_loads(gamma, h, s, loads)[0].numpy()
            adh = sticky.alpha_at_loads(gamma, h, s, loads)[0].numpy()
            zero = sticky.alpha_at_loads(gamma, h, s, loads[:, :1] * 1e-9)[0, 0].item()
    except MetainterfaceError:
        return ()
    change = adh / np.where(plain > 0, plain, np.inf) - 1
    fn = np.array([p[0], p[-1]]) * e_star * area
    return (
        f"adhesion: at w = {work_of_adhesion * 1e3:.3g} mJ/m^2 (typical of elastomers on "
        f"glass) this design's friction would be {100 * change[1]:+.3g} % at {fn[1]:.3g} N, "
        f"{100 * change[0]:+.3g} % at {fn[0]:.3g} N and {zero * tau * area:.3g} N at zero "
        "load; design with --work-of-adhesion if the part's interface adheres",
    )


def _offset_note(result: Any, gamma: Any, h: Any, scale: float) -> tuple[str, ...]:
    """The design's friction at zero load against the law's F_f(0) [N] (``scale`` = tau A):
    an offset law's F_0, which the curve error, over the whole load range, weighs as one
    point of many."""
    import numpy as np
    import torch

    t = result.target
    if not (t.p_star.size and t.p_star[0] == 0 and t.alpha[0] > 0):
        return ()
    tiny = torch.tensor([[1e-12 * float(t.p_star_max)]], dtype=torch.float64)
    try:
        with torch.no_grad():
            zero = result.model.alpha_at_loads(gamma, h, result.design.settings, tiny)
    except MetainterfaceError:
        return ()
    f_design, f_law = float(zero[0, 0]) * scale, float(t.alpha[0]) * scale
    if not np.isfinite(f_design):
        return ()
    how = ", extrapolated from its first two rows" if extrapolated(t) else ""
    note = (
        f"adhesion: friction at zero load {f_design:.3g} N, the law's {f_law:.3g} N{how} "
        f"({100 * (f_design / f_law - 1):+.3g} %)"
    )
    before = getattr(result, "bem_before", None)
    if before is not None and getattr(result, "bem", None) is not before:
        # the BEM reads no state at zero load: the correction holds its difference from the
        # model at its lowest load down to zero load, so the model's F_0 moves by it too
        note += (
            "; the design is corrected in BEM: its model curve is the law's moved by the "
            "BEM's difference from the model, at zero load the one at the BEM's lowest load"
        )
    return (note,)
