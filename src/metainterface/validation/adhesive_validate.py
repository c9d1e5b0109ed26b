"""Validate an adhesive design: the JKR-limit BEM against the adhesive model (issue 52).

``validate`` of a design with adhesion (its model, given or recorded in design.json, has
``adhesion`` > 0) solves the cell in the adhesive BEM by approach and keeps the states a
rising force reaches (``adhesive_path.rising_branch``: the loading curve under load
control, which the adhesive model gives), then compares the contact fraction with the
model at those loads: a ValidationResult like the adhesionless one's, its P* the states'
(not the loads asked for: a path by approach lands where the contact takes it). The
adhesion is the JKR limit (Pohrt-Popov criterion): the interaction range of PDMS on glass,
nanometres, is far below a grid spacing of a check (``adhesive_bem``; Maugis-Dugdale,
``solve_maugis``, needs the range resolved by several points, which a cell of millimetre
asperities never is at these grids).
"""

from __future__ import annotations

import torch

from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel
from metainterface.validation.adhesive_bem import MAX_ITER, TOLERANCE
from metainterface.validation.adhesive_path import (
    APPROACHES_PER_LOAD,
    check_adhesive_grid,
    rising_branch,
)
from metainterface.validation.heightmap import default_grid, height_map
from metainterface.validation.result import ValidationResult


def validate_adhesive(
    design: Design,
    model: ForwardModel,
    *,
    grid: int | None = None,
    loads: int = 20,
    p_max: float | None = None,
    name: str = "design",
    device: str = "auto",
) -> ValidationResult:
    """The JKR-limit BEM of ``design`` against the adhesive ``model`` (adhesion > 0).

    grid: M points per side (default 256 n, as the adhesionless validation; at most
    ``adhesive_path.FINEST`` n, where the BEM's error stops falling); loads: the
    path takes ``APPROACHES_PER_LOAD * loads`` approaches up to a step past the model's
    load ``p_max`` (default P* at Delta_max); the states on the rising-force branch are the
    result's loads. Raises MetainterfaceError where none is.
    """
    from metainterface import _checks

    if not model.adhesion:
        raise MetainterfaceError("validate_adhesive needs a model with adhesion > 0")
    k = _checks.whole("loads", loads, low=1, high=10_000)
    grid = (
        default_grid(design.settings)
        if grid is None
        else check_adhesive_grid(grid, design.settings)
    )
    curve = model.model_curve(design)
    top = curve.p_star_max if p_max is None else min(float(p_max), curve.p_star_max)
    branch = rising_branch(
        design, model, grid=grid, samples=APPROACHES_PER_LOAD * k, top=top, device=device
    )
    path, keep = branch.path, branch.keep
    if not keep.any():
        raise MetainterfaceError(
            "the adhesive BEM reached no state on its rising-force branch up to "
            f"P* = {top:.4g} (its largest: {float(path.p_star.max()):.3g}); try a finer grid "
            "or more loads"
        )
    p = path.p_star[keep]
    gamma, h = design.tensors(torch.float64)
    with torch.no_grad():
        model_alpha = model.alpha_at_loads(gamma, h, design.settings, torch.as_tensor(p)[None])
    per = None
    assert path.asperity_alpha is not None and path.p_max is not None
    assert path.residual is not None and path.seconds is not None and path.pressure is not None
    return ValidationResult(
        name=name,
        design=design,
        grid=grid,
        model=model,
        tolerance=TOLERANCE,
        max_iter=MAX_ITER,
        p_star=p,
        alpha_bem=path.alpha[keep],
        alpha_model=model_alpha[0].numpy(),
        alpha_bem_pixels=path.alpha[keep],
        p_max=path.p_max[keep],
        asperity_alpha_bem=path.asperity_alpha[keep],
        asperity_alpha_model=per,
        residual=path.residual[keep],
        seconds=path.seconds[keep],
        pressure=path.pressure,
        heights=height_map(design, grid),
        curve=curve,
        engine="torch",
    )


def is_adhesive(design: Design, model: ForwardModel | None) -> ForwardModel | None:
    """The adhesive model to validate ``design`` against: ``model`` where it has adhesion;
    with no model given, the one design.json records where that has adhesion; else None."""
    if model is not None:
        return model if model.adhesion else None
    label = design.extras.get("model")
    if not isinstance(label, str):
        return None
    from metainterface.physics.registry import get_model

    try:
        made = get_model(label)
    except MetainterfaceError:  # a model of another registry: not ours to judge
        return None
    return made if made.adhesion else None


__all__ = ["is_adhesive", "validate_adhesive"]
