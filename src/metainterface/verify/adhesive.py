"""The BEM check of an adhesive design (issue 38): the JKR-limit BEM under a rising force.

A design made with an adhesive model (``Independent(adhesion=w)``, ``Interacting(adhesion=w)``,
or a friction law with a work of adhesion) has the loading curve under load control: the
normal force rises from zero, each asperity snaps in when it touches and the cell follows
the running maximum of its force (``physics.adhesion``). Its check solves the same cell in
the adhesive torch BEM in the JKR limit (``validation.adhesive_bem``, Pohrt-Popov
criterion) by approach, at K approaches from touch up to a step past where the model
reaches the check's top load (displacement control: an adhesive contact has unstable
branches that load control would jump). The states a rising force reaches, those whose
force is at its running maximum and positive, and, with each asperity in contact, at least
the load the cell carried just before that asperity touched (a peak the samples may miss),
are the BEM's load-controlled curve; they are the check's loads, and the BEM, the model
and the target (interpolated) are compared there with the adhesionless check's measure,

    bem_error = ||alpha_bem - alpha_target||_2 / ||alpha_target||_2,

over the states inside the target's range. Only the torch engine has a JKR-limit solver:
the check runs there whatever ``Verify.engine`` says (a note says so).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import torch

from metainterface.errors import MetainterfaceError
from metainterface.inverse.targets import Target
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel

#: Approaches of the path per load asked for (``Verify.loads``): some states of the path
#: are not on the rising-force branch (just after a snap-in the force dips below its running
#: maximum), so the path takes more samples than the loads it is asked for.
APPROACHES_PER_LOAD = 2
#: A BEM state with an asperity in contact is on the rising-force branch only at or above
#: this factor times the load the model's cell carries just before that asperity touches
#: (``ForwardModel.touch_loads``): the margin covers the BEM's own touch load lying a few
#: per cent from the model's (states within it sit at a snap-in, where alpha jumps).
TOUCH_MARGIN = 1.05


def approaches(design: Design, model: ForwardModel, top: float, k: int) -> np.ndarray:
    """(K,) rising approaches [length]: uniform from 0 to one step past the first approach
    at which the model's loading curve reaches the load ``top`` (at most Delta_max)."""
    s = design.settings
    gamma, h = design.tensors(torch.float64)
    with torch.no_grad():
        sweep = model.sweep(gamma, h, s)
    delta = (sweep.delta[0] if sweep.delta.dim() == 2 else sweep.delta).numpy()
    reach = np.nonzero(sweep.p_star[0].numpy() >= top * (1 - 1e-9))[0]
    end = float(delta[reach[0]]) if reach.size else s.delta_max
    end = min(s.delta_max, end * (1 + 1.0 / k))
    return end * np.arange(1, k + 1) / k


def clear_of_snap_ins(p_star: np.ndarray, touching: np.ndarray, peaks: np.ndarray) -> np.ndarray:
    """(K,) bool: the BEM states (P* (K,), asperities in contact (K, N)) clear of the model's
    snap-ins (``peaks`` (N,), the model's ``touch_loads``); with the path's ``on_branch``,
    the states the check compares.

    A state with asperity i in contact below the load the cell had just before i touched
    was met by approach only: a rising force jumps over it (the sampled running maximum
    misses that peak when no approach falls just before the touch). A state within a factor
    TOUCH_MARGIN of a snap-in reads either side of the jump. Both are left out; a state
    without i in contact well above i's snap-in load is kept: there the BEM touches later
    than the model, a disagreement the check must see.
    """
    p = p_star[:, None]
    snaps = peaks[None, :] > 0
    skipped = touching & (p < TOUCH_MARGIN * peaks[None, :])
    at_jump = ~touching & (p > peaks[None, :] / TOUCH_MARGIN) & (p < TOUCH_MARGIN * peaks[None, :])
    return ~((skipped | at_jump) & snaps).any(1)


@dataclass(frozen=True)
class AdhesiveSolved:
    """The adhesive check's BEM path at the states a rising force reaches inside the
    target's range: p_star, alpha_bem, alpha_model (K,); device, wall time [s], notes."""

    p_star: np.ndarray
    alpha_bem: np.ndarray
    alpha_model: np.ndarray
    device: str
    seconds: float
    notes: tuple[str, ...]


def solve_adhesive(
    design: Design,
    target: Target,
    model: ForwardModel,
    *,
    grid: int,
    loads: int,
    device: str = "auto",
    engine: str = "torch",
) -> AdhesiveSolved:
    """``design`` (made with the adhesive ``model``) in the JKR-limit BEM on ``grid``^2 by
    ``APPROACHES_PER_LOAD * loads`` approaches; ``engine``: the one asked for (noted when it
    is not torch). Raises MetainterfaceError where no state of the path lies in the
    target's range."""
    from metainterface._device import resolve_device
    from metainterface.validation.adhesive_bem import jkr_path
    from metainterface.validation.heightmap import height_map

    if not model.adhesion:
        raise MetainterfaceError("the adhesive check needs a model with adhesion > 0")
    s = design.settings
    top = min(target.p_star_max, model.model_curve(design).p_star_max)
    deltas = approaches(design, model, top, APPROACHES_PER_LOAD * loads)
    dev = resolve_device(device)
    hm = height_map(design, grid)
    t0 = time.perf_counter()
    work = model.adhesion * s.e_star * s.radius  # w [E* length] in the cell's units
    path = jkr_path(hm.heights, hm.cell_side, work, deltas, device=dev, owner=hm.owner)
    seconds = time.perf_counter() - t0
    keep = (
        path.on_branch
        & clear_of_snap_ins(path.p_star, path.touching, model.touch_loads(design))
        & (path.p_star <= target.p_star_max * (1 + 1e-9))
    )
    if not keep.any():
        raise MetainterfaceError(
            "the adhesive BEM reached no load inside the target's range on its rising branch "
            f"(up to P* = {float(path.p_star.max()):.3g}); check on a finer grid"
        )
    p = path.p_star[keep]
    gamma, h = design.tensors(torch.float64)
    with torch.no_grad():
        mod = model.alpha_at_loads(gamma, h, s, torch.as_tensor(p)[None])[0].numpy()
    notes = [
        f"adhesive BEM: the JKR limit (Pohrt-Popov criterion) under a rising force, "
        f"w = {model.adhesion:.3g} E* R, {int(keep.sum())} of {deltas.size} approaches on "
        "the rising branch"
    ]
    if engine != "torch":
        notes.append(f"the adhesive check runs in the torch engine, not {engine}")
    if p[-1] < top * (1 - 0.25):
        notes.append(
            f"the adhesive BEM's rising branch reaches P* = {p[-1]:.4g} in the target's "
            f"range, short of {top:.4g}: the check stops there"
        )
    return AdhesiveSolved(p, path.alpha[keep], mod, str(dev), seconds, tuple(notes))
