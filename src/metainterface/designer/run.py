"""Designing: :func:`design` (a target to a checked design) and :func:`compare` (all three
methods). numpy and lists in, numpy out; every argument checked with a one-line
MetainterfaceError."""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from metainterface import _checks
from metainterface._device import resolve_device
from metainterface._files import check_output_folder, output_set
from metainterface._threads import uses_threads
from metainterface.designer.adhesion import (
    given_adhesion,
    model_for_targets,
)
from metainterface.designer.curve_result import reach_note
from metainterface.designer.finish import Finish, pressure_check, save_all
from metainterface.designer.given import _limit, _physical_options
from metainterface.designer.options import (
    OLD_KEYWORDS,
    Effort,
    Robust,
    Scale,
    as_groups,
    option_groups,
)
from metainterface.designer.results import DesignResult
from metainterface.designer.robust import _manufacturing, _printable_record, _robust_stats
from metainterface.errors import MetainterfaceError, ReachWarning
from metainterface.inverse import pipeline
from metainterface.inverse.envelope import reachability_warnings
from metainterface.inverse.refine import RefineSettings
from metainterface.inverse.targets import Target
from metainterface.inverse.verdict import refuse_unreachable
from metainterface.physics.cell import CellSettings, Design
from metainterface.physics.limits import pressure_penalty
from metainterface.physics.models import ForwardModel
from metainterface.physics.registry import get_model
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
        twice = sorted({n for n in names if names.count(n) > 1})
        said = ", ".join(f"{n!r} {names.count(n)} times" for n in twice[:5])
        more = f" and {len(twice) - 5} more names" if len(twice) > 5 else ""
        raise MetainterfaceError(
            f"target names must be distinct (each names its output), got {said}{more}"
        )
    return out, single


@uses_threads()
def design(
    targets: Target | str | Sequence[Target | str],
    *,
    method: str = "surrogate",
    model: str | ForwardModel | None = None,
    settings: CellSettings | None = None,
    effort: Effort | None = None,
    scale: Scale | None = None,
    robust: bool | Robust = False,
    max_pressure: float | str | None = None,
    z_step: float | str | None = None,
    verify: bool | Verify = True,
    force: bool = False,
    device: str = "auto",
    out: str | os.PathLike[str] | None = None,
    full_target: bool = False,
    **deprecated: Any,
) -> DesignResult | list[DesignResult]:
    """Design a unit cell whose alpha(P*) follows each target, checked in BEM.

    ``mi.design(t)`` is enough; options come in groups, built once and reused::

        mi.design(t, effort=mi.Effort(starts=8, seed=1),
                  scale=mi.Scale(radius="0.5mm", modulus="2MPa", area="4cm2"),
                  robust=mi.Robust(sigma_h="1um", samples=8), z_step="10um")

    targets: a Target, a built-in name ("bilinear", ...) or a list of them (one batch, a
    list of results back). method: "surrogate" (prediction, then refinement), "multistart"
    or "hertz" (gamma = 2). model: "independent" (default), "interacting" or a
    ForwardModel. settings: the CellSettings design space (default: the paper's cell).
    effort, scale, robust: the search (Effort), the user's scale in SI (Scale), a design
    for a printer's errors (Robust, or True). max_pressure: a peak pressure limit, p/E* in
    (0, 1] or a stress ('50MPa') with a modulus. z_step: a printer's layer height (units
    of R, or '10um' with a radius). verify: check and correct each design in BEM (True, a
    Verify, or False). force: design a law no cell can follow (else UnreachableError).
    device: "auto" (refinement on the CPU, the BEM check on CUDA when torch sees it),
    "cpu", "cuda" or "cuda:N". out: write each result's files there (several targets:
    out/<name>); full_target: also the whole target in target.csv.

    The old one-by-one keywords (starts=, radius=, sigma_h=, ...) still work for one
    release, with a DeprecationWarning naming their group.

    Returns one DesignResult per target (one, not a list, for a single target).
    """
    results, finish = designed(
        targets,
        method=method,
        model=model,
        settings=settings,
        effort=effort,
        scale=scale,
        robust=robust,
        max_pressure=max_pressure,
        z_step=z_step,
        verify=verify,
        force=force,
        device=device,
        out=out,
        full_target=full_target,
        **deprecated,
    )
    return finish(results)


def designed(
    targets: Target | str | Sequence[Target | str],
    *,
    method: str = "surrogate",
    model: str | ForwardModel | None = None,
    settings: CellSettings | None = None,
    effort: Effort | None = None,
    scale: Scale | None = None,
    robust: bool | Robust = False,
    max_pressure: float | str | None = None,
    z_step: float | str | None = None,
    verify: bool | Verify = True,
    force: bool = False,
    device: str = "auto",
    out: str | os.PathLike[str] | None = None,
    full_target: bool = False,
    **deprecated: Any,
) -> tuple[list[DesignResult], Finish]:
    """:func:`design` in two steps: the designs before their BEM check, and the
    :class:`Finish` that checks (and corrects) them, notes their adhesion and writes them,
    as ``design`` with these arguments would; ``finish(results)`` returns what ``design``
    returns. The scale search designs its finalists with the first, checks them in turn
    and writes only the one it keeps."""
    knobs, size, errors = option_groups(deprecated, effort, scale, robust)
    starts, hedge, fallback, refine, seed = (
        knobs["starts"],
        knobs["hedge"],
        knobs["fallback"],
        knobs["refine"],
        knobs["seed"],
    )
    refine_settings, hedge_error = knobs["refine_settings"], knobs["hedge_error"]
    surrogate = knobs["surrogate"]
    radius, modulus, total_force, area = (
        size["radius"],
        size["modulus"],
        size["total_force"],
        size["area"],
    )
    robust = True if isinstance(robust, Robust) else robust
    items, single = _targets(targets)
    if not isinstance(force, bool):
        raise MetainterfaceError(f"force must be True or False, got {force!r}")
    if settings is not None and not isinstance(settings, CellSettings):
        raise MetainterfaceError("settings must be a CellSettings")
    fm = model_for_targets(
        get_model(model), items, given_adhesion(size["work_of_adhesion"], modulus, radius)
    )
    reach = refuse_unreachable(items, settings, force)  # before any work or file
    _say_reach(items, settings or CellSettings(), reach, fm.adhesion)
    if out is not None:  # before any work: a bad folder should not cost a design run
        check_output_folder(out)
    _checks.choice("method", method, pipeline.METHODS)
    starts = _checks.whole("starts", starts, low=1, high=MAX_STARTS)
    hedge = _checks.whole("hedge", hedge, low=0, high=MAX_STARTS)
    fallback = _checks.whole("fallback", fallback, low=0, high=MAX_STARTS)
    seed = _checks.whole("seed", seed, low=0, high=MAX_SEED)
    if isinstance(hedge_error, bool) or not (
        isinstance(hedge_error, int | float) and 0 <= hedge_error < float("inf")
    ):
        raise MetainterfaceError(
            f"hedge_error must be a number >= 0, got {hedge_error!r}", argument="effort"
        )
    n = (settings or CellSettings()).n_asperities
    dev = resolve_device(device, small=True)
    if refine_settings is not None and not isinstance(refine_settings, RefineSettings):
        raise MetainterfaceError("refine_settings must be a RefineSettings")
    if not isinstance(refine, bool):
        raise MetainterfaceError(f"refine must be True or False, got {refine!r}")
    if not isinstance(full_target, bool):
        raise MetainterfaceError(f"full_target must be True or False, got {full_target!r}")
    checks = as_verify(verify, device)
    if checks is not None:  # a bad grid or device fails now, not after the design
        checks.ready(settings or CellSettings(), adhesive=bool(fm.adhesion))
    limit = _limit(max_pressure, modulus)
    extra_loss = None
    if limit is not None:

        def extra_loss(gamma, h, cell, limit=limit):
            return PRESSURE_WEIGHT * pressure_penalty(gamma, h, cell, limit)

    physical = _physical_options(radius, modulus, total_force, area)
    perturb, step, radius_m = _manufacturing(
        robust,
        errors["sigma_h"],
        errors["sigma_gamma"],
        errors["scale_sigma"],
        errors["robust_samples"],
        z_step,
        radius,
        settings,
        seed,
    )
    # robust design refines every start on its perturbed copies too
    copies = 1 if perturb is None else 1 + perturb.z.shape[0]
    affordable_rows(method, starts, hedge, fallback, len(items), n, dev, copies)
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
        hedge_error=float(hedge_error),
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

    finish = Finish(
        verify=checks,
        extra_loss=extra_loss,
        refine_settings=refine_settings,
        z_step=step,
        perturb=perturb,
        limit=limit,
        modulus=modulus,
        out=out,
        single=single,
        physical=physical,
        full_target=full_target,
    )
    return results, finish


def affordable_rows(
    method: str,
    starts: int,
    hedge: int,
    fallback: int,
    targets: int,
    n: int,
    device: Any,
    copies: int = 1,
) -> None:
    """Refuse a design whose largest batch would not fit in memory (the GPU's on CUDA).

    The rows refined together: ``starts`` per target by multistart and Hertz; by the
    surrogate, 1 + ``hedge`` per target, then ``fallback`` per target for the targets it
    missed, in a batch of its own after the first is freed (so the larger of the two, not
    their sum); each with ``copies`` curves (a robust design's nominal one and its perturbed
    copies)."""
    per_target = starts if method != "surrogate" else max(1 + hedge, fallback)
    nbytes = per_target * targets * n * copies * BYTES_PER_START
    what = f" for {targets} targets" if targets > 1 else ""
    if copies > 1:
        what += f" with {copies - 1} robust samples each"
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


def _say_reach(
    items: list[Target], settings: CellSettings, reach: dict[str, Any], adhesion: float
) -> None:
    """One ReachWarning per target the reach test finds partly out of reach, before the
    work starts (a friction law out of reach got here only with force=True); adhesion:
    w / (E* R) of the model's cells."""
    for t in items:
        lines = reachability_warnings(t, settings, adhesion)
        if t.name in reach and not reach[t.name].reachable:
            lines = [f"friction law {t.name}: " + reach[t.name].message.replace("\n", " ")]
        if lines:
            warnings.warn(
                "; ".join(line.rstrip(". ") for line in lines) + "; designing the closest cell",
                ReachWarning,
                stacklevel=4,
            )


def _public(r: pipeline.DesignResult, limit: float | None, modulus: Any) -> DesignResult:
    d = Design(gamma=r.gamma, h=r.h, settings=r.settings)
    notes = (*r.notes, *reachability_warnings(r.target, r.settings, r.model.adhesion))
    pressure = pressure_check(d, limit, modulus)
    out = DesignResult(
        target=r.target,
        design=d,
        error=r.error,
        initial_error=r.initial_error,
        method=r.method,
        seconds=r.seconds,
        model=r.model,
        start=r.start,
        zero_shot_from=r.zero_shot_from,
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


@uses_threads()
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
    full_target = options.pop("full_target", False)
    old = {k: options.pop(k) for k in list(options) if k in OLD_KEYWORDS}
    groups = option_groups(
        old,
        options.pop("effort", None),
        options.pop("scale", None),
        options.get("robust"),
        "compare",
    )
    options.update(as_groups(*groups, options.get("robust", False)))
    size = groups[1]
    physical = _physical_options(size["radius"], size["modulus"], size["total_force"], size["area"])
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
                save_all(per, [base / r.method for r in per], physical, full_target)
                fig = plot_comparison([per], [[r.curve() for r in per]])
                save_figure(fig, base / "compare.png", command="compare")
    return by_method  # type: ignore[return-value]
