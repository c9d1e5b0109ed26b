"""``design``'s last step: each result checked in BEM and, where it pays, corrected there."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import torch
from torch import Tensor

from metainterface.designer.results import DesignResult
from metainterface.inverse.params import DTYPE, FixedHeights, Parameterisation
from metainterface.inverse.pipeline import METHODS
from metainterface.inverse.refine import RefineSettings
from metainterface.physics.cell import CellSettings
from metainterface.physics.registry import get_model
from metainterface.verify import Verify, bem_check, correct
from metainterface.verify.bemcheck import BemCheck


def verified(
    r: DesignResult,
    settings: Verify,
    *,
    extra_loss: Callable[[Tensor, Tensor, CellSettings], Tensor] | None = None,
    refine_settings: RefineSettings | None = None,
    z_step: float | None = None,
    robust: bool = False,
    check: BemCheck | None = None,
) -> DesignResult:
    """``r`` with its BEM check (``bem``) and, if ``settings`` asks for it, corrected: then
    ``design`` and ``error`` are the corrected design's, ``bem_before`` the first check,
    ``corrections`` every iteration, and ``bem`` the corrected design's check at the
    interleaved loads the correction did not fit (its error there is the one it reports;
    the error at the fitted loads is the last kept iteration's). ``check``: the design's
    check already solved with ``settings`` (whatever they say of the correction), not
    solved again."""
    if check is None:
        check = bem_check(r.design, r.target, settings, r.model)
    if not settings.wants_correction(check):
        return replace(r, bem=check)
    if robust:  # the correction re-refines the nominal design: it would undo the robustness
        note = "robust design: not corrected in BEM (the correction refines the nominal cell)"
        return replace(r, bem=check, notes=(*r.notes, note))
    out = correct(
        r.design,
        r.target,
        check,
        settings,
        r.model,
        param=_parameterisation(r, z_step),
        extra_loss=extra_loss,
        refine_settings=refine_settings,
    )
    if out.check is check:  # nothing kept: the design stays as it was
        return replace(r, bem=check, bem_before=check, corrections=out.corrections)
    held_out = out.check
    if not get_model(r.model).adhesion:  # the adhesive check reads the states its path reaches
        held_out = bem_check(out.design, r.target, settings, r.model, held_out=True)
    return replace(
        r,
        design=out.design,
        error=out.model_error,
        bem=held_out,
        bem_before=check,
        corrections=out.corrections,
    )


def _parameterisation(r: DesignResult, z_step: float | None) -> Parameterisation:
    """What the design was refined in: gamma = 2 for the Hertz baseline, the heights fixed
    on a printer's layers."""
    if z_step is not None:
        return FixedHeights(h=torch.as_tensor(r.design.h, dtype=DTYPE)[None])
    return METHODS[r.method]
