"""Correction of a design in BEM: output space mapping (defect correction).

The forward model m(x) is cheap and differentiable; the BEM b(x) is what the made surface
does. Near the design x_i their difference d_i = m(x_i) - b(x_i) (the defect, on the check's
loads) changes slowly with x, so the design x_{i+1} whose model curve meets the target
shifted by the defect,

    x_{i+1} = argmin_x || m(x) - (alpha_target + s d_i) ||,

has b(x_{i+1}) ~ m(x_{i+1}) - d_i ~ alpha_target: the model's error is corrected with the
BEM's own answer (output space mapping, Bandler et al., IEEE Trans. Microw. Theory Tech. 42
(1994) 2536, and Koziel, Bandler & Madsen, IEEE Trans. Microw. Theory Tech. 54 (2006) 3721;
defect correction, Stetter, Numer. Math. 29 (1978) 425). Each iteration re-refines from the
current design with the refinement's polish, then solves the new design in BEM; it is kept
only if its BEM error fell, otherwise the step s is halved (1, 1/2, 1/4, ...) from the same
design. The loop stops once the BEM error is within twice the check's own accuracy (at
least ``STOP_ERROR``): the check reads no error below that accuracy, so the most a further
step could show is the error less the accuracy, itself within what the check resolves (the
README's main job: 0.57 % -> 0.25 % +- 0.13 % in one iteration, where a second took off
0.005 points in 9 s); once a kept step lowered it by no more than that accuracy; or once
``Verify.iterations`` BEM solves are spent. Each check solves the
design at the check's loads k / K; the result's own error is read afterwards at the
interleaved loads, which no iteration fitted (``designer.verified``).

The model m of the correction (``Verify.inner``) need not be the one the design was made
with: by default it is the interacting model, whose defect is a few times smaller and moves
less with the design. With the paper's model as m, the defect at the loads where the next
asperity first touches is a few per cent of alpha and jumps from one design to the next (the
neighbours delay that contact in BEM by an amount that depends on the heights), so the
shifted target chases it and the loop stalls at 0.7-1.7 % on some random cells at 768^2
(benchmarks/results/verified.md).

The re-refinement from the current design can end in its local optimum, short of the
shifted target by a few tenths of a per cent in the model; the BEM error cannot fall below
that. With ``Verify.restart`` (default) each iteration also designs afresh against the
shifted target (the surrogate's prediction and its hedge starts, refined on the
correction's model) and keeps whichever of the two meets the shifted target better in that
model: no extra BEM solve. The fresh design costs several re-refinements (nine starts on
the interacting model), so the first iteration makes it only where the re-refined design
misses the shifted target by more than ``FRESH_GATE`` (within it the candidate already
meets its target about as closely as the correction resolves, ``STOP_ERROR``), or where the
BEM refused the previous iteration's candidate (a stall, which the fresh start is for).

"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import torch
from torch import Tensor

from metainterface.errors import MetainterfaceError
from metainterface.inverse.losses import TargetGrid, relative_error
from metainterface.inverse.offset import F0_MEET, f0_error
from metainterface.inverse.params import DTYPE, FULL, Parameterisation
from metainterface.inverse.refine import RefineSettings, polish
from metainterface.inverse.targets import Target
from metainterface.physics.cell import CellSettings, Design
from metainterface.physics.models import ForwardModel
from metainterface.physics.registry import get_model
from metainterface.verify.check import BemCheck, Verify, bem_check

#: The correction stops once the BEM error is within the check's own accuracy
#: (``BemCheck.accuracy``), below which a further step corrects the grid, not the design,
#: and never below this (0.1 %), where the accuracy was not estimated or is finer.
STOP_ERROR = 1e-3
#: The first iteration makes a fresh design only where the re-refined one misses the shifted
#: target by more than this (relative curve error in the correction's model).
FRESH_GATE = STOP_ERROR
#: Hedge starts of a fresh design (the CLI's default ``--hedge``).
RESTART_HEDGE = 8


@dataclass(frozen=True)
class Correction:
    """One correction iteration: the step s, the candidate's BEM error and model error to the
    target, whether it was kept, its wall time [s] (re-refine and BEM solve), where the
    candidate came from: ``"current"`` (re-refined from the kept design) or ``"fresh"``
    (designed afresh against the shifted target), and, for an offset law, the candidate's
    F_0 error (``inverse.offset.f0_error``; None for any other target)."""

    iteration: int
    step: float
    bem_error: float
    model_error: float
    accepted: bool
    seconds: float
    start: str = "current"
    f0_error: float | None = None

    def to_dict(self) -> dict[str, float | int | bool | str]:
        out: dict[str, float | int | bool | str] = {
            "iteration": self.iteration,
            "step": self.step,
            "bem_error": self.bem_error,
            "model_error": self.model_error,
            "accepted": self.accepted,
            "seconds": self.seconds,
            "start": self.start,
        }
        if self.f0_error is not None:
            out["f0_error"] = self.f0_error
        return out


@dataclass(frozen=True)
class Corrected:
    """What the correction hands back: the kept design, its check, every iteration, and the
    kept design's model error to the target on the refinement's grid."""

    design: Design
    check: BemCheck
    corrections: tuple[Correction, ...]
    model_error: float


def shifted_target(
    target: Target, check: BemCheck, step: float, alpha_model: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The target's alpha (M,) plus ``step`` times the defect alpha_model - alpha_bem of
    ``check``, interpolated at the target's pressures (0 at P* = 0, held beyond the last load),
    clipped at 0. ``alpha_model`` (K,): the correction's model at the check's loads, if not
    the check's own. Returns (p_star, alpha)."""
    model_alpha = check.alpha_model if alpha_model is None else alpha_model
    defect = model_alpha - check.alpha_bem
    p = np.concatenate([[0.0], check.p_star])
    # an adhesive cell has a contact at zero load (snap-in): its defect is held down to it
    d = np.concatenate([[defect[0] if check.adhesion else 0.0], defect])
    alpha = target.alpha + step * np.interp(target.p_star, p, d)
    return target.p_star, np.maximum(alpha, 0.0)


def re_refine(
    design: Design,
    curve: tuple[np.ndarray, np.ndarray],
    model: ForwardModel,
    param: Parameterisation = FULL,
    extra_loss: Callable[[Tensor, Tensor, CellSettings], Tensor] | None = None,
    refine_settings: RefineSettings | None = None,
) -> Design:
    """``design`` refined from where it is against ``curve`` (p_star, alpha) by the
    refinement's polish (Levenberg-Marquardt on the exact contact law)."""
    rs = refine_settings or RefineSettings()
    settings = design.settings
    grid = TargetGrid.from_curves([curve], rs.grid_points)
    gamma = torch.as_tensor(design.gamma, dtype=DTYPE)[None]
    h = torch.as_tensor(design.h, dtype=DTYPE)[None]
    raw = polish(
        param.from_design(gamma, h, settings), settings, grid, rs, param, extra_loss, model
    )
    g, hh = param.to_design(raw.detach(), settings)
    return Design(gamma=g[0].numpy().copy(), h=hh[0].numpy().copy(), settings=settings)


def fresh_design(
    curve: tuple[np.ndarray, np.ndarray],
    settings: CellSettings,
    model: ForwardModel,
    extra_loss: Callable[[Tensor, Tensor, CellSettings], Tensor] | None = None,
    refine_settings: RefineSettings | None = None,
    seed: int = 0,
) -> Design | None:
    """A design made afresh for ``curve`` (p_star, alpha) on ``model``: the surrogate's
    prediction and ``RESTART_HEDGE`` seeded hedge starts, refined. None where the shifted
    curve is not a target (not increasing) or the surrogate was not trained for the cell."""
    from metainterface.inverse.pipeline import _usable_method, design

    if _usable_method("surrogate", settings, None)[1]:
        return None
    try:
        target = Target(p_star=curve[0], alpha=curve[1], name="shifted", source="correction")
    except MetainterfaceError:
        return None
    r = design(
        [target],
        "surrogate",
        settings=settings,
        seed=seed,
        refine_settings=refine_settings,
        extra_loss=extra_loss,
        model=model,
        hedge=RESTART_HEDGE,
        # a shifted curve is rarely met within Effort.hedge_error by the prediction alone:
        # its hedges are refined with it in one batch, not in a second pass after it
        hedge_error=0.0,
    )[0]
    return Design(gamma=np.asarray(r.gamma).copy(), h=np.asarray(r.h).copy(), settings=settings)


def curve_fit_error(
    design: Design,
    curve: tuple[np.ndarray, np.ndarray],
    model: ForwardModel,
    points: int | None = None,
) -> float:
    """The design's relative error to ``curve`` (p_star, alpha) on ``model``, on the
    refinement's grid (``points``, default ``RefineSettings().grid_points``)."""
    grid = TargetGrid.from_curves([curve], points or RefineSettings().grid_points)
    gamma = torch.as_tensor(design.gamma, dtype=DTYPE)[None]
    h = torch.as_tensor(design.h, dtype=DTYPE)[None]
    return float(relative_error(gamma, h, design.settings, grid, model)[0])


def model_error(
    design: Design, target: Target, model: ForwardModel, points: int | None = None
) -> float:
    """The design's model error to the target on the refinement's grid (``design``'s measure)."""
    return curve_fit_error(design, (target.p_star, target.alpha), model, points)


def alpha_at(design: Design, model: ForwardModel, p_star: np.ndarray) -> np.ndarray:
    """(K,) the design's alpha on ``model`` at the loads ``p_star`` (held beyond its reach)."""
    curve = model.model_curve(design)
    return np.interp(p_star, curve.p_star, curve.alpha)


def with_adhesion(inner: ForwardModel, model: ForwardModel) -> ForwardModel:
    """The correction's model ``inner`` with the adhesion of the design's ``model`` (an
    adhesive design is corrected on an adhesive model); ``model`` itself where ``inner``
    takes no adhesion."""
    if not model.adhesion or inner.adhesion == model.adhesion:
        return inner
    return inner.with_adhesion(model.adhesion) if inner.takes_adhesion else model


def stop_error(check: BemCheck) -> float:
    """What the check resolves: its own accuracy, at least ``STOP_ERROR``. The correction
    stops once its BEM error is within twice that (``settled``) or a kept step gained no
    more than that."""
    return max(STOP_ERROR, check.accuracy or 0.0)


def settled(check: BemCheck) -> bool:
    """Whether a further correction step cannot show a gain: the most it could take off is
    the BEM error less the check's accuracy (its floor), and that is within the accuracy."""
    return check.bem_error - stop_error(check) <= stop_error(check)


def correct(
    design: Design,
    target: Target,
    check: BemCheck,
    settings: Verify | None = None,
    model: str | ForwardModel | None = None,
    *,
    param: Parameterisation = FULL,
    extra_loss: Callable[[Tensor, Tensor, CellSettings], Tensor] | None = None,
    refine_settings: RefineSettings | None = None,
) -> Corrected:
    """Correct ``design`` (whose BEM check is ``check``) towards ``target`` in BEM.

    Spends at most ``settings.iterations`` BEM solves; param, extra_loss and refine_settings
    are those the design was refined with (the Hertz baseline keeps gamma = 2, a design on a
    printer's layers keeps its heights; neither is designed afresh). model: the one the design
    was made with (``check``'s, and the one the returned checks and model errors are on);
    the re-refinement runs on ``settings.inner`` (None: this one), with the adhesion of
    ``model`` where it has one (an adhesive design is checked in the JKR-limit BEM).
    """
    settings = settings or Verify()
    fm = get_model(model)
    inner = fm if settings.inner is None else with_adhesion(get_model(settings.inner), fm)

    def inner_alpha(d: Design, c: BemCheck) -> np.ndarray | None:
        return None if inner == fm else alpha_at(d, inner, c.p_star)

    def f0_miss(d: Design) -> float | None:
        return f0_error(target, d.gamma, d.h, d.settings, fm)

    # An offset law's F_0 is part of what a design meets (issue 52): the BEM's states start
    # above zero load, so a correction towards them alone moved a held-out law's F_0 from
    # 0.42 % to 33.5 % (benchmarks/results/adhesion.md). A candidate is kept only with its
    # F_0 within F0_MEET, or no further off than the design handed in.
    start_f0 = f0_miss(design)
    f0_limit = None if start_f0 is None else max(F0_MEET, start_f0)
    best, best_check = design, check
    best_inner = inner_alpha(best, best_check)
    step = 1.0
    done: list[Correction] = []
    for i in range(settings.iterations):
        if settled(best_check):
            break
        t0 = time.perf_counter()
        curve = shifted_target(target, best_check, step, best_inner)
        candidate = re_refine(best, curve, inner, param, extra_loss, refine_settings)
        start = "current"
        if settings.restart and param is FULL:
            fit = curve_fit_error(candidate, curve, inner)
            fresh = None
            if fit > FRESH_GATE or (done and not done[-1].accepted):
                fresh = fresh_design(curve, best.settings, inner, extra_loss, refine_settings, i)
            if fresh is not None and curve_fit_error(fresh, curve, inner) < fit:
                candidate, start = fresh, "fresh"
        cand_check = bem_check(candidate, target, settings, fm)
        cand_f0 = f0_miss(candidate)
        accepted = cand_check.bem_error < best_check.bem_error and (
            f0_limit is None or (cand_f0 is not None and cand_f0 <= f0_limit)
        )
        done.append(
            Correction(
                iteration=i + 1,
                step=step,
                bem_error=cand_check.bem_error,
                model_error=model_error(candidate, target, fm),
                accepted=accepted,
                seconds=time.perf_counter() - t0,
                start=start,
                f0_error=cand_f0,
            )
        )
        if accepted:
            gain = best_check.bem_error - cand_check.bem_error
            best, best_check = candidate, cand_check
            best_inner = inner_alpha(best, best_check)
            if gain <= stop_error(cand_check):
                break  # it moved the error by less than the check resolves: the next would too
        else:
            step /= 2
    return Corrected(
        design=best,
        check=best_check,
        corrections=tuple(done),
        model_error=model_error(best, target, fm),
    )
