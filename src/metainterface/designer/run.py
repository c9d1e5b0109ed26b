"""Designing: :func:`design` (a target to a checked design) and :func:`compare` (all three
methods). numpy and lists in, numpy out; every argument checked with a one-line
MetainterfaceError."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from metainterface import _checks
from metainterface._device import resolve_device
from metainterface._files import check_output_folder, output_set
from metainterface.designer.curves import reach_note
from metainterface.designer.given import _limit, _physical_options
from metainterface.designer.results import DesignResult
from metainterface.designer.robust import _manufacturing, _printable_record, _robust_stats
from metainterface.errors import MetainterfaceError
from metainterface.inverse import pipeline
from metainterface.inverse.perturb import Perturbation
from metainterface.inverse.reach import refuse_unreachable
from metainterface.inverse.refine import RefineSettings
from metainterface.inverse.targets import Target
from metainterface.physical.dimensions import physical_block
from metainterface.physical.units import (
    parse_pressure,
)
from metainterface.physics.cell import CellSettings, Design
from metainterface.physics.limits import PressureCheck, check_pressure, pressure_penalty
from metainterface.physics.models import ForwardModel, get_model
from metainterface.verify.check import Verify, as_verify

#: Upper bounds that keep a request within this machine's memory and a sane run time.
MAX_STARTS = 10_000
MAX_SEED = _checks.MAX_SEED


#: Memory of one start per asperity during refinement (about twice what the multistart
#: uses, so that a refusal is never wrong).
BYTES_PER_START = 16 * 2**10
#: Weight of the pressure-limit penalty added to the refinement's loss.
PRESSURE_WEIGHT = 10.0


def _targets(targets: Target | str | Sequence[Target | str]) -> tuple[list[Target], bool]:
    """The targets as a list, and whether one was given alone (then one result back)."""
    single = isinstance(targets, Target | str)
    items = [targets] if single else list(targets)  # type: ignore[arg-type]
    if not items:
        raise MetainterfaceError("targets: give at least one target")
    out = []
    for t in items:
        if isinstance(t, str):
            t = Target.builtin(t)
        if not isinstance(t, Target):
            raise MetainterfaceError(
                f"targets must be Target objects or built-in names ({', '.join(Target.builtins())})"
                f", got {type(t).__name__}"
            )
        out.append(t)
    names = [t.name for t in out]
    if len(set(names)) != len(names):
        raise MetainterfaceError(f"target names must be distinct, got {', '.join(names)}")
    return out, single


def design(
    targets: Target | str | Sequence[Target | str],
    *,
    method: str = "surrogate",
    starts: int = 50,
    hedge: int = 8,
    fallback: int = 50,
    seed: int = 0,
    model: str | ForwardModel | None = None,
    settings: CellSettings | None = None,
    surrogate: str | os.PathLike[str] | None = None,
    refine: bool = True,
    max_pressure: float | str | None = None,
    modulus: str | float | None = None,
    out: str | os.PathLike[str] | None = None,
    radius: str | float | None = None,
    total_force: str | float | None = None,
    area: str | float | None = None,
    meta: dict[str, Any] | None = None,
    refine_settings: RefineSettings | None = None,
    full_target: bool = False,
    robust: bool = False,
    sigma_h: float | str = 0.0,
    sigma_gamma: float = 0.0,
    scale_sigma: float = 0.0,
    robust_samples: int = 16,
    z_step: float | str | None = None,
    device: str = "auto",
    force: bool = False,
    verify: bool | Verify = True,
) -> DesignResult | list[DesignResult]:
    """Design a unit cell whose alpha(P*) follows each target, checked in BEM.

    Parameters
    ----------
    targets : Target, str or list of them
        A target, a built-in name (``"saturating"``, ``"bilinear"``, ``"linear"``), or a list;
        a list gives a list of results, designed in one batch.
    method : {"surrogate", "multistart", "hertz"}
        Zero-shot prediction by the surrogate then refinement (default), ``starts`` random
        starts refined and the best kept, or the Hertz-only baseline (gamma = 2, heights only).
    starts : int
        Random starts of the multistart and Hertz methods, in [1, 10000].
    hedge : int
        Surrogate method: extra starts refined beside the prediction (half jittered copies of
        it, half random), in [0, 10000]; 0 is the paper's pure pipeline.
    fallback : int
        Surrogate method: a target still missed by more than 2 % also gets a multistart with
        this many starts, the better design kept; 0 turns it off.
    seed : int
        Seed of every random draw, in [0, 2**63 - 1]; the same seed gives the same designs.
    model : str or ForwardModel
        The forward model refined and measured with: ``"independent"`` (the paper's,
        default), ``"interacting"``, or an instance such as ``Interacting(curvature=True)``.
    settings : CellSettings
        The design space (N, gamma bounds, Delta_max). The shipped surrogate covers the
        paper's cell; for another one the multistart runs instead (``result.notes``).
    surrogate : path
        A surrogate model file (``metainterface train``), default the shipped one.
    refine : bool
        Refine the starts (False: the zero-shot prediction or the best raw start).
    max_pressure : float or str
        A peak contact pressure limit: p/E* in (0, 1], or a stress ('50MPa') with
        ``modulus``. Adds a penalty to the refinement and a check to each result.
    modulus : str or float
        E* of the material pair ('2MPa', or Pa), for ``max_pressure`` and the SI block.
    out : path
        Write each result's files here (one target: into ``out``; several: ``out/<name>``).
    radius, total_force, area : str or float
        With ``modulus``, ``radius`` R ('0.5mm') adds the design's dimensions in SI to
        design.json, and the number of cells for a total force ('10N') or an area ('4cm2').
    meta : dict
        Extra JSON-ready keys stored in each design.json (e.g. the command line).
    refine_settings : RefineSettings
        The refinement's stages, iterations and tolerances (default: the paper's 5 stages x
        5 steps x 20 iterations, then the polish); fewer make a quicker, rougher design.
    full_target : bool
        With ``out``: also write the whole target to target.csv (design.json keeps it
        decimated to at most 256 points, with its size and hash).
    robust : bool
        Design for manufacturing errors: each start is refined against the mean squared
        error of ``robust_samples`` perturbed copies of it (the same draws for every start,
        in the same batch), the start with the smallest rms error over them wins.
        ``result.error`` (and design.json's ``relative_error``) stays the nominal design's;
        ``result.robust`` holds the nominal and robust statistics.
    sigma_h, sigma_gamma, scale_sigma : float or str
        The errors designed for, as in :func:`tolerance`: sigma_h a plain number in units
        of R or a length ('1um') with ``radius``; sigma_gamma absolute; scale_sigma relative.
    robust_samples : int
        K, perturbed copies per start, in [1, 1024]; the cost grows about K-fold.
    z_step : float or str
        A printer's layer height: the designed heights are snapped to its multiples and the
        gammas re-refined with the heights fixed. A plain number in units of R, or a length
        ('1um') with ``radius``; at most Delta_max. ``result.printable`` reports the error
        before the snap, after it and after the re-refine.
    device : str
        Where the refinement (and the BEM check, with ``verify=True``) runs: ``"auto"``
        (CUDA when torch sees it, else the CPU), ``"cpu"``, ``"cuda"`` or ``"cuda:N"``.
        Every target's starts go in one batch; the starts are drawn on the CPU, so a seed
        gives the same starts on every device.
    force : bool
        Design a friction-law target that no cell can follow anyway (see
        :func:`~metainterface.reachability`): the closest cell, marked ``result.forced``.
        Without it such a target raises :class:`~metainterface.UnreachableError` first.
    verify : bool or Verify
        Check each design in the boundary element method and report its error to the
        target there (``result.bem_error``, ``result.bem``), correcting it in BEM where the
        BEM adds to the model's error (default True: ``Verify()``, 10 loads on a 384^2 grid
        for the paper's cell); a ``Verify`` sets the grid, loads, correction and threshold;
        False skips the check.

    Returns
    -------
    DesignResult or list of DesignResult
        One per target, in order.
    """
    items, single = _targets(targets)
    if not isinstance(force, bool):
        raise MetainterfaceError(f"force must be True or False, got {force!r}")
    if settings is not None and not isinstance(settings, CellSettings):
        raise MetainterfaceError("settings must be a CellSettings")
    reach = refuse_unreachable(items, settings, force)  # before any work or file
    if out is not None:  # before any work: a bad folder should not cost a design run
        check_output_folder(out)
    _checks.choice("method", method, pipeline.METHODS)
    starts = _checks.whole("starts", starts, low=1, high=MAX_STARTS)
    hedge = _checks.whole("hedge", hedge, low=0, high=MAX_STARTS)
    fallback = _checks.whole("fallback", fallback, low=0, high=MAX_STARTS)
    seed = _checks.whole("seed", seed, low=0, high=MAX_SEED)
    n = (settings or CellSettings()).n_asperities
    dev = resolve_device(device)
    _affordable_rows(method, starts, hedge, fallback, len(items), n, dev)
    if refine_settings is not None and not isinstance(refine_settings, RefineSettings):
        raise MetainterfaceError("refine_settings must be a RefineSettings")
    if not isinstance(refine, bool):
        raise MetainterfaceError(f"refine must be True or False, got {refine!r}")
    if not isinstance(full_target, bool):
        raise MetainterfaceError(f"full_target must be True or False, got {full_target!r}")
    fm = get_model(model)
    checks = as_verify(verify, device)
    if checks is not None:  # a bad grid or device fails now, not after the design
        checks.ready(settings or CellSettings())
    limit = _limit(max_pressure, modulus)
    extra_loss = None
    if limit is not None:

        def extra_loss(gamma, h, cell, limit=limit):
            return PRESSURE_WEIGHT * pressure_penalty(gamma, h, cell, limit)

    physical = _physical_options(radius, modulus, total_force, area)
    perturb, step, radius_m = _manufacturing(
        robust, sigma_h, sigma_gamma, scale_sigma, robust_samples, z_step, radius, settings, seed
    )
    raw = pipeline.design(
        items,
        method,
        refine_designs=refine,
        settings=settings,
        model_path=surrogate,
        starts=starts,
        seed=seed,
        extra_loss=extra_loss,
        model=fm,
        refine_settings=refine_settings,
        hedge=hedge if method == "surrogate" else 0,
        fallback=fallback if method == "surrogate" else 0,
        perturb=perturb,
        z_step=step,
        device=dev,
    )
    results = [_public(r, limit, modulus) for r in raw]
    results = [_forced(r, reach.get(r.target.name)) for r in results]
    if perturb is not None:
        results = [_robust_stats(r, perturb, seed, dev) for r in results]
    if step is not None:
        results = [_printable_record(r, radius_m) for r in results]
    if checks is not None:
        results = _verify_all(
            results, checks, extra_loss, refine_settings, step, perturb, limit, modulus
        )
    if out is not None:
        out = Path(out)
        folders = [out] if single else [out / r.target.name for r in results]
        _save_all(results, folders, physical, meta, full_target)
    return results[0] if single else results


def _affordable_rows(
    method: str, starts: int, hedge: int, fallback: int, targets: int, n: int, device: Any
) -> None:
    """Refuse a design whose largest batch would not fit in memory (the GPU's on CUDA).

    The rows refined together: ``starts`` per target by multistart and Hertz; by the
    surrogate, 1 + ``hedge`` per target, then ``fallback`` per target for the targets it
    missed, in a batch of its own after the first is freed (so the larger of the two, not
    their sum)."""
    per_target = starts if method != "surrogate" else max(1 + hedge, fallback)
    nbytes = per_target * targets * n * BYTES_PER_START
    what = f" for {targets} targets" if targets > 1 else ""
    if device.type != "cuda":
        _checks.affordable("starts", starts, nbytes, what=what)
        return
    import torch

    total = torch.cuda.get_device_properties(device).total_memory
    if nbytes > _checks.MEMORY_SHARE * total:
        raise MetainterfaceError(
            f"starts = {starts} would need about {nbytes / 2**30:.1f} GiB on {device}{what}, "
            f"more than half its {total / 2**30:.1f} GiB; design fewer targets per call",
            argument="starts",
        )


def _verify_all(
    results: list[DesignResult],
    checks: Verify,
    extra_loss: Any,
    refine_settings: RefineSettings | None,
    step: float | None,
    perturb: Perturbation | None,
    limit: float | None,
    modulus: Any,
) -> list[DesignResult]:
    """Each result checked (and where asked, corrected) in BEM; a corrected design gets its
    pressure check again."""
    from metainterface.designer.verified import verified

    out = []
    for r in results:
        v = verified(
            r,
            checks,
            extra_loss=extra_loss,
            refine_settings=refine_settings,
            z_step=step,
            robust=perturb is not None,
        )
        if v.design is not r.design and r.pressure is not None:
            v = replace(v, pressure=_pressure(v.design, limit, modulus))
        out.append(v)
    return out


def _pressure(d: Design, limit: float | None, modulus: Any) -> PressureCheck | None:
    if limit is None:
        return None
    e_star = None if modulus is None else parse_pressure(modulus, option="modulus")
    return check_pressure(d, limit if e_star is None else limit * e_star, e_star=e_star)


def _public(r: pipeline.DesignResult, limit: float | None, modulus: Any) -> DesignResult:
    d = Design(gamma=r.gamma, h=r.h, settings=r.settings)
    notes = (*r.notes, *pipeline.reachability_warnings(r.target, r.settings))
    pressure = _pressure(d, limit, modulus)
    out = DesignResult(
        target=r.target,
        design=d,
        error=r.error,
        initial_error=r.initial_error,
        method=r.method,
        seconds=r.seconds,
        model=r.model,
        start=r.start,
        fallback=r.fallback,
        notes=notes,
        pressure=pressure,
        printable=r.quantisation,
        robust_error_refined=r.robust_error,
    )
    more = reach_note(out.coverage, out.idle, d.n_asperities)
    return replace(out, notes=(*notes, *more)) if more else out


def _forced(r: DesignResult, reach: Any) -> DesignResult:
    """The result marked as forced when its friction law is out of reach."""
    if reach is None or reach.reachable:
        return r
    note = "FORCED: the friction law is out of reach, this is the closest cell; " + (
        reach.message.replace("\n", " ")
    )
    return replace(r, forced=True, notes=(note, *r.notes))


def _save_all(
    results: list[DesignResult],
    folders: list[Path],
    physical: dict | None,
    meta: dict[str, Any] | None,
    full_target: bool = False,
) -> None:
    with output_set():  # every result's files, or none
        for r, folder in zip(results, folders, strict=True):
            extra = {"command": meta} if meta else {}
            if physical is not None:
                extra["physical"] = physical_block(r.design, **physical)
            r.save(folder, full_target=full_target, **extra)


def compare(
    targets: Target | str | Sequence[Target | str],
    *,
    out: str | os.PathLike[str] | None = None,
    **options: Any,
) -> dict[str, list[DesignResult]]:
    """Design every target with all three methods (paper fig. 5): {method: [results]}.

    ``options`` are those of :func:`design`; with ``out``, each method's files go to
    ``out/<target>/<method>/`` and the comparison figure to ``out/<target>/compare.png``
    (one target: ``out/<method>/`` and ``out/compare.png``).
    """
    items, single = _targets(targets)
    if out is not None:
        check_output_folder(out)
    if "method" in options:
        raise MetainterfaceError("compare runs every method; leave method out")
    meta = options.pop("meta", None)
    full_target = options.pop("full_target", False)
    physical = _physical_options(
        options.pop("radius", None),
        options.get("modulus"),
        options.pop("total_force", None),
        options.pop("area", None),
    )
    by_method = {
        m: design(items, method=m, **options)  # type: ignore[misc]
        for m in pipeline.METHODS
    }
    if out is not None:
        from metainterface.plots import plot_comparison, save_figure

        out = Path(out)
        with output_set():  # all methods' files and figures, or none
            for i, t in enumerate(items):
                per = [by_method[m][i] for m in pipeline.METHODS]
                base = out if single else out / t.name
                _save_all(per, [base / r.method for r in per], physical, meta, full_target)
                fig = plot_comparison([per], [[r.curve() for r in per]])
                save_figure(fig, base / "compare.png", command="compare")
    return by_method  # type: ignore[return-value]
