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

from dataclasses import dataclass

import numpy as np
import torch

from metainterface.errors import MetainterfaceError
from metainterface.inverse.targets import Target
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel
from metainterface.validation.adhesive_path import (  # noqa: F401  (re-exported)
    APPROACHES_PER_LOAD,
    TOUCH_MARGIN,
    approaches,
    clear_of_snap_ins,
    rising_branch,
)


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
    top = min(target.p_star_max, model.model_curve(design).p_star_max)
    branch = rising_branch(
        design, model, grid=grid, samples=APPROACHES_PER_LOAD * loads, top=top, device=device
    )
    path, deltas, seconds, dev = branch.path, branch.approaches, branch.seconds, branch.device
    keep = branch.keep & (path.p_star <= target.p_star_max * (1 + 1e-9))
    if not keep.any():
        raise MetainterfaceError(
            "the adhesive BEM reached no load inside the target's range on its rising branch "
            f"(up to P* = {float(path.p_star.max()):.3g}); check on a finer grid"
        )
    p = path.p_star[keep]
    gamma, h = design.tensors(torch.float64)
    with torch.no_grad():
        mod = model.alpha_at_loads(gamma, h, design.settings, torch.as_tensor(p)[None])[0]
    mod = mod.numpy()
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
