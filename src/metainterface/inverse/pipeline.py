"""The design loop: targets in, unit cells out (paper sec. 4, appendix C).

Methods: ``surrogate`` (zero-shot prediction by the inverse MLP, then refinement),
``multistart`` (K random starts, refined, best kept) and ``hertz`` (gamma fixed at 2, heights
only, K starts). Several targets, and all their starts, are refined together as one batch of
independent problems.
"""

from __future__ import annotations

import os
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import replace

import torch
from torch import Tensor

from metainterface._device import resolve_device
from metainterface._names import METHOD_NAMES
from metainterface.errors import MetainterfaceError
from metainterface.inverse.designed import DesignResult
from metainterface.inverse.layers import printable
from metainterface.inverse.losses import TargetGrid, relative_error, robust_error
from metainterface.inverse.params import (
    FULL,
    HERTZ,
    Parameterisation,
)
from metainterface.inverse.perturb import Perturbation
from metainterface.inverse.refine import HEDGE_ERROR, RefineSettings, polish, refine
from metainterface.inverse.starts import (
    best_views,
    hedge_starts,
    predict,
    random_starts,
    shipped_adhesive_net,
    shipped_laws_net,
)
from metainterface.inverse.targets import Target
from metainterface.physics.cell import CellSettings
from metainterface.physics.models import ForwardModel
from metainterface.physics.registry import get_model

#: The curve error above which a refined surrogate design also gets the fallback multistart.
FALLBACK_ERROR = 0.02
#: ... with adhesion: which asperities are in contact at zero load (a count that no gradient
#: changes) sets an adhesive curve's start, so a design that reads the target well (1-2 %)
#: may still sit at the wrong count; the multistart's starts try others.
ADHESIVE_FALLBACK_ERROR = 0.01

#: Design methods and the parameterisation each refines: the surrogate's prediction and the
#: multistart in the full space, the Hertz-only baseline with gamma fixed at 2.
METHODS: dict[str, Parameterisation] = dict(zip(METHOD_NAMES, (FULL, FULL, HERTZ), strict=True))


#: Rows polished per target (the best by error after the stages), the winner picked after.
POLISH_ROWS = 3


def design(
    targets: Sequence[Target],
    method: str = "surrogate",
    *,
    refine_designs: bool = True,
    settings: CellSettings | None = None,
    model_path: str | os.PathLike[str] | None = None,
    starts: int = 50,
    seed: int = 0,
    refine_settings: RefineSettings | None = None,
    extra_loss: Callable[[Tensor, Tensor, CellSettings], Tensor] | None = None,
    model: str | ForwardModel | None = None,
    hedge: int = 0,
    fallback: int = 0,
    fallback_error: float | None = None,
    hedge_error: float = HEDGE_ERROR,
    perturb: Perturbation | None = None,
    z_step: float | None = None,
    device: str | torch.device = "cpu",
) -> list[DesignResult]:
    """Design one cell per target with ``method``; returns one result per target.

    ``hedge`` (surrogate method only): also refine that many starts beside the zero-shot
    prediction (:func:`hedge_starts`: jittered copies of it, which find better neighbouring
    optima, and random starts, a guard for targets far from the training distribution such
    as exactly linear laws) and keep the best, at the cost of a larger batch. 0 is the
    paper's pipeline. The hedges run after it, and only for the targets whose refined
    zero-shot design misses them by more than ``hedge_error`` (relative curve error, the
    robust one with ``perturb``): a design within it has nothing to gain that matters.
    ``hedge_error`` 0 refines the hedges with the zero-shot row in one batch, cheaper where
    every target needs them (a scale search's candidates).

    ``fallback`` (surrogate method only): a target whose refined design still misses it by
    more than ``fallback_error`` (relative curve error; None: ``FALLBACK_ERROR``, or
    ``ADHESIVE_FALLBACK_ERROR`` for a model with adhesion) is far from anything the
    surrogate learned; it also gets a ``fallback``-start multistart (same seed, settings and
    refinement) and keeps the better design (``DesignResult.fallback`` says which). Targets
    the surrogate meets cost nothing extra. 0 (the default) is the paper's pipeline.

    ``model`` is the forward model the refinement optimises and the error is measured with
    (a name in ``physics.registry.MODELS`` or a ForwardModel); the surrogate was trained on
    the independent one.

    ``settings`` is the cell (N, gamma bounds, Delta_max). The surrogate method uses the
    shipped model where it was trained for that cell; for another cell it warns and runs
    the multistart instead (``DesignResult.notes`` says so).

    ``perturb`` (robust design): every start is refined against the mean loss of its K
    perturbed copies (:class:`~metainterface.inverse.perturb.Perturbation`, the same K
    draws for every start and step), in the same batch as the starts; the winner is the
    start with the smallest rms error over the copies (``robust_error``), and ``error``
    stays the nominal design's.

    ``z_step`` (printable heights, units of R): each winner's heights are snapped to
    multiples of it (anchored at 0), then its gammas re-refined with the heights fixed
    (:class:`~metainterface.inverse.params.FixedHeights`, the polish on the exact law);
    ``quantisation`` records the error before the snap, after it and after the re-refine.

    ``device`` ("auto", "cpu", "cuda", "cuda:N"): where the refinement runs, every target's
    starts in one batch. The starts, the surrogate's prediction and the perturbations are
    made on the CPU whatever the device (the same seed, the same starts everywhere); the
    results are numpy.
    """
    model = get_model(model)
    if fallback_error is None:
        fallback_error = ADHESIVE_FALLBACK_ERROR if model.adhesion else FALLBACK_ERROR
    dev = resolve_device(device)
    common = dict(
        refine_designs=refine_designs,
        settings=settings,
        model_path=model_path,
        starts=starts,
        seed=seed,
        refine_settings=refine_settings,
        extra_loss=extra_loss,
        model=model,
        perturb=perturb,
        device=dev,
    )
    method, notes = _usable_method(method, settings, model_path)
    if notes:
        warnings.warn(notes[0], stacklevel=2)
        hedge = fallback = 0
    zero_shot = None
    if method == "surrogate" and hedge > 0:  # made once, for the design and its hedges
        points = (refine_settings or RefineSettings()).grid_points
        zero_shot = _zero_shot(targets, model_path, model, points)
    gate = zero_shot is not None and hedge_error > 0
    # hedge_error 0: the zero-shot row and the hedges in one batch (where all need them)
    results = _design(targets, method, hedge=0 if gate else hedge, zero_shot=zero_shot, **common)
    if gate:
        results = _hedged(results, targets, hedge, hedge_error, zero_shot, common)
    if notes:
        results = [replace(r, notes=notes) for r in results]
    missed = [i for i, r in enumerate(results) if r.error > fallback_error]
    if method == "surrogate" and fallback > 0 and missed:
        t0 = time.perf_counter()
        common.update(settings=results[0].settings, starts=fallback)
        alt = _design([targets[i] for i in missed], "multistart", hedge=0, **common)
        extra = (time.perf_counter() - t0) / len(missed)
        for i, a in zip(missed, alt, strict=True):
            r = results[i]
            if _score(a) < _score(r):
                r = replace(
                    r,
                    gamma=a.gamma,
                    h=a.h,
                    error=a.error,
                    robust_error=a.robust_error,
                    start=a.start,
                    fallback=True,
                )
            results[i] = replace(r, seconds=r.seconds + extra)
    rs = refine_settings or RefineSettings()
    if refine_designs and perturb is None and rs.reseed:  # idle asperities put to use
        from metainterface.inverse.reseed import reseed

        results = reseed(results, rs, extra_loss, model, seed)
    if refine_designs and perturb is None and rs.offset and model.adhesion:  # a law's F_0
        from metainterface.inverse.offset import offset_polish

        results = offset_polish(results, rs, extra_loss, model)
    if z_step is not None:
        results = printable(
            results, z_step, refine_settings or RefineSettings(), extra_loss, model, perturb, dev
        )
    return results


def _hedged(
    results: list[DesignResult],
    targets: Sequence[Target],
    hedge: int,
    hedge_error: float,
    zero_shot: tuple[Tensor, Tensor, list[str]],
    common: dict,
) -> list[DesignResult]:
    """The results with the ``hedge`` starts refined for the targets that the zero-shot
    design missed by more than ``hedge_error`` (by :func:`_score`), in one batch; each of
    those keeps the better of its zero-shot and its best hedge design (``start`` 1..hedge
    when a hedge wins). ``zero_shot``: the targets' zero-shot designs (:func:`_zero_shot`),
    which the jittered hedge starts copy."""
    missed = [i for i, r in enumerate(results) if _score(r) > hedge_error]
    if not missed:
        return results
    gamma0, h0, labels = zero_shot
    rows = torch.tensor(missed)
    alt = _design(
        [targets[i] for i in missed],
        "surrogate",
        hedge=hedge,
        hedges_only=True,
        zero_shot=(gamma0[rows], h0[rows], [labels[i] for i in missed]),
        **common,
    )
    out = list(results)
    for i, a in zip(missed, alt, strict=True):
        r = results[i]
        if _score(a) < _score(r):
            r = replace(
                r, gamma=a.gamma, h=a.h, error=a.error, robust_error=a.robust_error, start=a.start
            )
        out[i] = replace(r, seconds=r.seconds + a.seconds)
    return out


def _score(r: DesignResult) -> float:
    """What picks the better of two designs: the robust error when designing for it."""
    return r.error if r.robust_error is None else r.robust_error


def _design(
    targets: Sequence[Target],
    method: str,
    *,
    refine_designs: bool,
    settings: CellSettings | None,
    model_path: str | os.PathLike[str] | None,
    starts: int,
    seed: int,
    refine_settings: RefineSettings | None,
    extra_loss: Callable[[Tensor, Tensor, CellSettings], Tensor] | None,
    model: ForwardModel,
    hedge: int,
    perturb: Perturbation | None = None,
    device: torch.device | None = None,
    hedges_only: bool = False,
    zero_shot: tuple[Tensor, Tensor, list[str]] | None = None,
) -> list[DesignResult]:
    """One batch of starts per target, refined, the best kept. The surrogate's rows per
    target: its zero-shot design and ``hedge`` hedge starts, or (``hedges_only``) the hedge
    starts alone, numbered 1..hedge in ``start`` as they would be beside the zero-shot row
    (whose refinement the caller has). ``zero_shot``: the surrogate's designs of the
    targets as :func:`_zero_shot` makes them, if the caller has them."""
    dev = device or torch.device("cpu")
    if method not in METHODS:
        raise MetainterfaceError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}")
    if starts < 1:
        raise MetainterfaceError(f"starts must be >= 1, got {starts}")
    if not targets:
        raise MetainterfaceError("no target given")
    refine_settings = refine_settings or RefineSettings()
    t0 = time.perf_counter()
    if method == "surrogate":
        from metainterface.surrogate.checkpoint import default_model_path, design_model

        settings = design_model(model_path or default_model_path())[1]
        if zero_shot is None:
            zero_shot = _zero_shot(targets, model_path, model, refine_settings.grid_points)
        gamma0, h0, zero_shot_from = zero_shot
        per_target = 1 + max(hedge, 0)
        if hedge > 0 and hedges_only:  # rows per target: [hedge starts]
            g_r, h_r = hedge_starts(gamma0, h0, hedge, settings, seed)
            gamma0, h0, per_target = g_r.flatten(0, 1), h_r.flatten(0, 1), hedge
        elif hedge > 0:  # rows per target: [zero-shot, hedge starts]
            g_r, h_r = hedge_starts(gamma0, h0, hedge, settings, seed)
            gamma0 = torch.cat([gamma0[:, None], g_r], 1).flatten(0, 1)
            h0 = torch.cat([h0[:, None], h_r], 1).flatten(0, 1)
    else:
        zero_shot_from = [""] * len(targets)
        settings = settings or CellSettings()
        per_target = starts
        gamma0, h0 = random_starts(starts, len(targets), settings, seed, METHODS[method])
    grid = TargetGrid.from_curves(
        [(t.p_star, t.alpha) for t in targets], refine_settings.grid_points
    ).to(dev)
    # made on the CPU (seeded generators, the network), refined on the device
    gamma0, h0 = gamma0.to(dev), h0.to(dev)
    if perturb is not None:
        perturb = perturb.to(dev)
    rows = grid.rows(torch.arange(len(targets), device=dev).repeat_interleave(per_target))
    # the error of the starts as given (the refinement starts a little inside the bounds)
    param = METHODS[method]
    err0 = relative_error(gamma0, h0, settings, rows, model)
    raw0 = param.from_design(gamma0, h0, settings)
    raw = raw0
    if refine_designs:
        raw = refine(raw, settings, rows, refine_settings, param, extra_loss, model, perturb)
    gamma, h = param.to_design(raw.detach(), settings)
    err = relative_error(gamma, h, settings, rows, model)
    if perturb is None:
        # The refinement's loss forgives a design that stops short of the target (weight 0.1
        # there); the reported error charges it, so a start can beat its refinement: keep it.
        worse = err0 < err
        gamma = torch.where(worse[:, None], gamma0, gamma)
        h = torch.where(worse[:, None], h0, h)
        raw = torch.where(worse[:, None], raw0, raw.detach())
        err = torch.where(worse, err0, err)

    def score(g: Tensor, hh: Tensor, grid: TargetGrid, nominal: Tensor) -> Tensor:
        # what ranks the starts: the nominal error, or the robust one when designing for it
        return nominal if perturb is None else robust_error(g, hh, settings, grid, perturb, model)

    rank = score(gamma, h, rows, err)
    offset = torch.arange(len(targets), device=dev)[:, None] * per_target
    if refine_designs and refine_settings.polish_iterations > 0:
        # The early stops cut the search short on every row; the best few of each target get
        # to finish (rows close before the polish can swap places after it).
        top = min(POLISH_ROWS, per_target)
        kept_rows = rank.view(len(targets), per_target).topk(top, largest=False).indices + offset
        kept_rows = kept_rows.reshape(-1)
        kept = rows.rows(kept_rows)
        raw_w = polish(
            raw[kept_rows], settings, kept, refine_settings, param, extra_loss, model, perturb
        )
        g_w, h_w = param.to_design(raw_w, settings)
        err_w = relative_error(g_w, h_w, settings, kept, model)
        rank_w = score(g_w, h_w, kept, err_w)
        better = rank_w < rank[kept_rows]
        gamma[kept_rows] = torch.where(better[:, None], g_w, gamma[kept_rows])
        h[kept_rows] = torch.where(better[:, None], h_w, h[kept_rows])
        err[kept_rows] = torch.where(better, err_w, err[kept_rows])
        rank[kept_rows] = torch.where(better, rank_w, rank[kept_rows])
    winner = rank.view(len(targets), per_target).argmin(-1)
    best = winner + offset[:, 0]
    err0 = err0.view(len(targets), per_target)
    # the zero-shot error of the surrogate is its own row's; baselines report their best start
    first = err0[:, 0] if method == "surrogate" else err0.min(-1).values
    # one copy to the host for all targets, not one per result (it waits for the device)
    gamma, h, err, rank = gamma.detach().cpu(), h.detach().cpu(), err.cpu(), rank.cpu()
    winner, best, first = winner.cpu(), best.cpu(), first.cpu()
    seconds = (time.perf_counter() - t0) / len(targets)
    return [
        DesignResult(
            target=t,
            method=method,
            gamma=gamma[b].detach().numpy().copy(),
            h=h[b].detach().numpy().copy(),
            error=float(err[b]),
            seconds=seconds,
            initial_error=float(first[i]),
            settings=settings,
            model=model,
            start=int(winner[i]) + int(hedges_only),
            robust_error=None if perturb is None else float(rank[b]),
            zero_shot_from=zero_shot_from[i],
        )
        for i, (t, b) in enumerate(zip(targets, best.tolist(), strict=True))
    ]


def _zero_shot(
    targets: Sequence[Target],
    model_path: str | os.PathLike[str] | None,
    model: ForwardModel,
    points: int,
) -> tuple[Tensor, Tensor, list[str]]:
    """The surrogate's zero-shot designs gamma0, h0 (T, N) of the targets, each the best of
    its views and the shipped networks' readings (the friction-law network's, the adhesive
    network's for a model with adhesion; :func:`best_views`, on ``points`` pressures), and
    where each comes from."""
    from metainterface.surrogate.checkpoint import default_model_path, design_model

    net, settings, _ = design_model(model_path or default_model_path())
    if net.adhesion_input and not model.adhesion:
        raise MetainterfaceError(
            f"the surrogate {model_path} reads a work of adhesion (an adhesive network): "
            "design with a model that has adhesion (model=Independent(adhesion=w), "
            "--work-of-adhesion) or give an adhesionless surrogate",
            argument="surrogate",
        )
    gamma0, h0 = predict(net, targets, settings, adhesion=model.adhesion)
    laws_net = shipped_laws_net(model_path, settings, targets)
    adhesive_net = shipped_adhesive_net(model_path, settings, model)
    return best_views(net, targets, gamma0, h0, settings, model, points, laws_net, adhesive_net)


def _usable_method(
    method: str,
    settings: CellSettings | None,
    model_path: str | os.PathLike[str] | None,
) -> tuple[str, tuple[str, ...]]:
    """The method to run: the surrogate only for the cell it was trained for, else the
    multistart, with a note saying why."""
    if method != "surrogate" or settings is None:
        return method, ()
    from metainterface.surrogate.checkpoint import default_model_path, design_model

    path = model_path or default_model_path()
    _, trained, _ = design_model(path)
    if settings.with_(n_steps=trained.n_steps) == trained:
        return method, ()
    mine = {k: v for k, v in settings.to_dict().items() if trained.to_dict()[k] != v}
    note = (
        f"the surrogate ({path}) was trained for another cell (yours differs in "
        f"{', '.join(f'{k}={v:g}' for k, v in mine.items())}); designing by multistart instead "
        "(train a surrogate for this cell to use one)"
    )
    return "multistart", (note,)
