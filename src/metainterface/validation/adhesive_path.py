"""An adhesive cell's load-controlled curve from the JKR-limit BEM (issues 38, 52).

A design made with an adhesive model has the loading curve under load control: the normal
force rises from zero, each asperity snaps in when it touches and the cell follows the
running maximum of its force (``physics.adhesion``). The BEM (``adhesive_bem``) solves the
cell by approach (displacement control: an adhesive contact has unstable branches that
load control would jump), at K approaches from touch up to a step past where the model
reaches the top load. The states a rising force reaches, those whose force is at its
running maximum and positive and clear of the model's snap-ins (``clear_of_snap_ins``),
are the BEM's load-controlled curve. Both design's check (``verify.adhesive``) and
``validate`` of an adhesive design (``adhesive_validate``) read it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel
from metainterface.validation.adhesive_bem import AdhesivePath

#: Approaches of the path per load asked for: some states of the path are not on the
#: rising-force branch (just after a snap-in the force dips below its running maximum), so
#: the path takes more samples than the loads it is asked for.
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
    the states compared.

    A state with asperity i in contact below the load the cell had just before i touched
    was met by approach only: a rising force jumps over it (the sampled running maximum
    misses that peak when no approach falls just before the touch). A state within a factor
    TOUCH_MARGIN of a snap-in reads either side of the jump. Both are left out; a state
    without i in contact well above i's snap-in load is kept: there the BEM touches later
    than the model, a disagreement a check must see.
    """
    p = p_star[:, None]
    snaps = peaks[None, :] > 0
    skipped = touching & (p < TOUCH_MARGIN * peaks[None, :])
    at_jump = ~touching & (p > peaks[None, :] / TOUCH_MARGIN) & (p < TOUCH_MARGIN * peaks[None, :])
    return ~((skipped | at_jump) & snaps).any(1)


@dataclass(frozen=True)
class RisingBranch:
    """The adhesive BEM's path of a cell and which of its states a rising force reaches.

    path: the BEM's states by approach (``adhesive_bem.AdhesivePath``); keep: (K,) bool,
    the states on the rising-force branch clear of snap-ins and at most ``top`` (the load
    asked up to); approaches: (K,) [length]; device: where it solved; seconds: wall time.
    """

    path: AdhesivePath
    keep: np.ndarray
    approaches: np.ndarray
    device: str
    seconds: float


def rising_branch(
    design: Design,
    model: ForwardModel,
    *,
    grid: int,
    samples: int,
    top: float,
    device: str = "auto",
) -> RisingBranch:
    """``design`` in the JKR-limit BEM on ``grid``^2 by ``samples`` approaches up to a step
    past the model's load ``top`` (P*), work of adhesion ``model.adhesion`` [E* R]."""
    import time

    from metainterface._device import resolve_device
    from metainterface.validation.adhesive_bem import jkr_path
    from metainterface.validation.heightmap import height_map

    if not model.adhesion:
        raise MetainterfaceError("the adhesive BEM needs a model with adhesion > 0")
    s = design.settings
    deltas = approaches(design, model, top, samples)
    dev = resolve_device(device)
    hm = height_map(design, grid)
    t0 = time.perf_counter()
    work = model.adhesion * s.e_star * s.radius  # w [E* length] in the cell's units
    path = jkr_path(hm.heights, hm.cell_side, work, deltas, device=dev, owner=hm.owner)
    seconds = time.perf_counter() - t0
    assert path.touching is not None  # owner given
    keep = (
        path.on_branch
        & clear_of_snap_ins(path.p_star, path.touching, model.touch_loads(design))
        & (path.p_star <= top * (1 + 1e-9))
    )
    return RisingBranch(path, keep, deltas, str(dev), seconds)
