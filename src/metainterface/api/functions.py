"""The public functions: design, compare, curve, export, physical. numpy and lists in,
numpy out; every argument checked with a one-line MetainterfaceError."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from metainterface import _checks
from metainterface._device import resolve_device
from metainterface._files import check_output_file, check_output_folder, output_set
from metainterface.api.reach import refuse_unreachable
from metainterface.api.results import (
    CURVE_STEPS,
    Curve,
    DesignResult,
    design_curve,
    idle_notes,
    reach_note,
)
from metainterface.errors import MetainterfaceError
from metainterface.inverse import pipeline
from metainterface.inverse.perturb import Perturbation
from metainterface.inverse.refine import RefineSettings
from metainterface.inverse.targets import Target
from metainterface.physical.dimensions import physical_block
from metainterface.physical.units import (
    parse_area,
    parse_force,
    parse_length,
    parse_pressure,
    parse_pressure_limit,
)
from metainterface.physics.cell import CellSettings, Design
from metainterface.physics.limits import PressureCheck, check_pressure, pressure_penalty
from metainterface.physics.models import ForwardModel, get_model
from metainterface.verify.check import Verify, as_verify

#: Upper bounds that keep a request within this machine's memory and a sane run time.
MAX_STARTS = 10_000
MAX_STEPS = 1_000_000
MAX_SEED = _checks.MAX_SEED
#: Physical inputs in SI, with their units for messages: beyond these a number is a typo.
PHYSICAL_RANGES = {
    "radius": (1e-9, 10.0, "m"),
    "modulus": (1e-3, 1e13, "Pa"),
    "total_force": (1e-12, 1e12, "N"),
    "area": (1e-18, 1e6, "m^2"),
}
#: Softplus steepness kappa_s [1/R]: below this the relaxed bracket is no longer a contact.
SMOOTH_RANGE = (1.0, 1e15)


def _physical(name: str, value: float) -> float:
    low, high, unit = PHYSICAL_RANGES[name]
    if not low <= value <= high:
        raise MetainterfaceError(
            f"{name} must be between {low:g} and {high:g} {unit}, got {value:g} {unit}",
            argument=name,
        )
    return value


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


def _limit(max_pressure: float | str | None, modulus: str | float | None) -> float | None:
    if max_pressure is None:
        return None
    e_star = None if modulus is None else parse_pressure(modulus, option="modulus")
    return parse_pressure_limit(
        max_pressure, e_star=e_star, option="max_pressure", modulus_option="modulus"
    )


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


#: Made cells drawn to report a robust design's error distribution (independent of the
#: K copies it was refined against).
ROBUST_REPORT_SAMPLES = 1024
MAX_ROBUST_SAMPLES = 1024


def _manufacturing(
    robust: Any,
    sigma_h: Any,
    sigma_gamma: Any,
    scale_sigma: Any,
    robust_samples: Any,
    z_step: Any,
    radius: Any,
    settings: CellSettings | None,
    seed: int,
) -> tuple[Perturbation | None, float | None, float | None]:
    """The perturbation of a robust design and the layer step [units of R], checked."""
    from metainterface.api.tolerance import layer_step, length_in_r

    if not isinstance(robust, bool):
        raise MetainterfaceError(f"robust must be True or False, got {robust!r}")
    radius_m = None if radius is None else parse_length(radius, option="radius")
    cell = settings or CellSettings()
    step = None if z_step is None else layer_step(z_step, radius_m, cell.delta_max)
    if not robust:
        if any(v not in (0, 0.0) for v in (sigma_h, sigma_gamma, scale_sigma)):
            raise MetainterfaceError("sigma_h, sigma_gamma and scale_sigma need robust=True")
        return None, step, radius_m
    s_h = length_in_r(sigma_h, radius_m, option="sigma_h", radius_option="radius")
    s_g = _checks.number("sigma_gamma", sigma_gamma, low=0.0)
    s_s = _checks.number("scale_sigma", scale_sigma, low=0.0, high=0.5)
    if s_h == s_g == s_s == 0.0:
        raise MetainterfaceError("robust=True needs sigma_h, sigma_gamma or scale_sigma > 0")
    k = _checks.whole("robust_samples", robust_samples, low=1, high=MAX_ROBUST_SAMPLES)
    perturb = Perturbation.draw(
        cell.n_asperities, k, seed, sigma_h=s_h, sigma_gamma=s_g, scale_sigma=s_s
    )
    return perturb, step, radius_m


def _robust_stats(
    r: DesignResult, perturb: Perturbation, seed: int, device: Any = None
) -> DesignResult:
    """The result with ``robust``: its nominal error and the distribution of the error of
    made cells (independent draws), beside the rms error it was refined against."""
    from metainterface.inverse.tolerance import spread

    d = r.design
    check = Perturbation.draw(
        d.n_asperities,
        ROBUST_REPORT_SAMPLES,
        seed + 1,
        sigma_h=perturb.sigma_h,
        sigma_gamma=perturb.sigma_gamma,
        scale_sigma=perturb.scale_sigma,
    )
    s = spread(
        d.gamma,
        d.h,
        d.settings,
        r.model,
        check,
        target=(r.target.p_star, r.target.alpha),
        linear=False,
        device=device,
    )
    stats = {
        "sigma_h": perturb.sigma_h,
        "sigma_gamma": perturb.sigma_gamma,
        "scale_sigma": perturb.scale_sigma,
        "robust_samples": perturb.samples,
        "error_nominal": r.error,
        "error_rms_refined": r.robust_error_refined,
        "error_median": float(np.median(s.errors)),
        "error_p95": float(np.quantile(s.errors, 0.95)),
        "check_samples": ROBUST_REPORT_SAMPLES,
        "check_seed": seed + 1,
    }
    return replace(r, robust=stats)


def _printable_record(r: DesignResult, radius_m: float | None) -> DesignResult:
    q = dict(r.printable or {})
    if radius_m is not None:
        q["z_step_m"] = q["z_step"] * radius_m
    q["z_step_units"] = "R"
    return replace(r, printable=q)


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
    from metainterface.api.verified import verified

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


def _physical_options(radius: Any, modulus: Any, total_force: Any, area: Any) -> dict | None:
    """Parsed SI options of the physical block, or None without radius and modulus."""
    if radius is None or modulus is None:
        if total_force is not None or area is not None:
            raise MetainterfaceError("total_force and area need radius and modulus too")
        return None
    if total_force is not None and area is not None:
        raise MetainterfaceError("give total_force or area, not both")
    return {
        "radius": _physical("radius", parse_length(radius, option="radius")),
        "e_star": _physical("modulus", parse_pressure(modulus, option="modulus")),
        "total_force": None
        if total_force is None
        else _physical("total_force", parse_force(total_force, option="total_force")),
        "area": None if area is None else _physical("area", parse_area(area, option="area")),
    }


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


def _as_design(
    design: Design | str | os.PathLike[str] | None,
    gamma: Any,
    h: Any,
    settings: CellSettings | None,
) -> Design:
    """A Design from a Design, a design file, or gamma and h lists."""
    if design is not None:
        if gamma is not None or h is not None:
            raise MetainterfaceError("give a design or gamma and h, not both")
        if isinstance(design, Design):
            return design
        if isinstance(design, str | os.PathLike):
            return Design.load(design)
        raise MetainterfaceError(
            f"design must be a Design or a design file path, got {type(design).__name__}"
        )
    if gamma is None or h is None:
        raise MetainterfaceError("give a design, or both gamma and h")
    if settings is not None and not isinstance(settings, CellSettings):
        raise MetainterfaceError("settings must be a CellSettings")
    gamma, h = _checks.vector("gamma", gamma), _checks.vector("h", h)
    if settings is not None and gamma.size != settings.n_asperities:
        raise MetainterfaceError(
            f"gamma has {gamma.size} values but settings.n_asperities is {settings.n_asperities}",
            argument="gamma",
        )
    return Design(gamma=gamma, h=h, settings=settings or CellSettings())


def curve(
    design: Design | str | os.PathLike[str] | None = None,
    *,
    gamma: Sequence[float] | np.ndarray | None = None,
    h: Sequence[float] | np.ndarray | None = None,
    settings: CellSettings | None = None,
    model: str | ForwardModel | None = None,
    steps: int = CURVE_STEPS,
    smooth: float | None = None,
    device: str = "auto",
) -> Curve:
    """The alpha(P*) and S*(P*) curve of a design along Delta in [0, Delta_max].

    Parameters
    ----------
    design : Design or path
        The design, or a design file; or give ``gamma`` and ``h`` instead.
    gamma, h : list or array, shape (N,)
        Shape exponents and height offsets [units of R], N a perfect square.
    settings : CellSettings
        The cell of ``gamma`` and ``h`` (default: the paper's).
    model : str or ForwardModel
        The forward model (default ``"independent"``).
    steps : int
        Delta samples, in [2, 1000000].
    smooth : float
        Softplus steepness kappa_s [1/R] instead of the exact bracket, in [1, 1e15].
    device : str
        Where the sweep runs: ``"auto"``, ``"cpu"``, ``"cuda"`` or ``"cuda:N"``.

    Returns
    -------
    Curve
        numpy ``delta``, ``p_star``, ``alpha``, ``stiffness`` (steps,).
    """
    d = _as_design(design, gamma, h, settings)
    steps = _checks.whole("steps", steps, low=2, high=MAX_STEPS)
    if smooth is not None:
        smooth = _checks.number("smooth", smooth, low=SMOOTH_RANGE[0], high=SMOOTH_RANGE[1])
    dev = resolve_device(device)
    return design_curve(d, model, steps=steps, smooth=smooth, device=dev)


def export(
    design: Design | str | os.PathLike[str],
    path: str | os.PathLike[str],
    *,
    radius: str | float,
    tiles: tuple[int, int] | str = (1, 1),
    format: str | None = None,
    resolution: float | None = None,
    base: str | float = "1mm",
    z_step: str | float | None = None,
    flank_step: int = 4,
    force: bool = False,
) -> dict[str, Any]:
    """Write the design's surface for manufacture: STL (mm), 16-bit PNG/TIFF or NPY (m).

    Parameters
    ----------
    design : Design or path
    path : path
        Output file; its suffix picks the format unless ``format`` is given. A sidecar
        ``path.json`` records the height scale, grid and provenance.
    radius : str or float
        Asperity radius R ('0.5mm', or metres).
    tiles : (nx, ny), 'NXxNY' or 'auto'
        Cells along x and y; 'auto': the tiling design.json's physical block gives for the
        area or total force designed for (a design.json path written with them, e.g. by
        ``design_scale`` or ``metainterface design --area auto``).
    format : {"stl", "png", "tiff", "npy"}
    resolution : float
        Grid points per mm (default 64 per asperity pitch).
    base : str or float
        STL base plate thickness under the surface (default 1 mm).
    z_step : str or float
        A printer's layer height ('1um', or a plain number in units of R), at most
        Delta_max: the asperities' height offsets are snapped to its multiples (a design
        made with ``design(..., z_step=...)`` already sits on them; the sidecar records the
        largest shift).
    flank_step : int
        STL only: the flanks between the asperities' contact zones are meshed on every
        flank_step-th grid line (default 4; 1 meshes every line), in [1, 64].
    force : bool
        Write a file over 100 MB; without it such an export raises an error that states
        the size and how to make it smaller, and writes nothing.

    Returns
    -------
    dict
        The sidecar record (size, grid, triangles, ...).
    """
    from metainterface.io.export import export_design

    check_output_file(path)
    d = _as_design(design, None, None, None)
    if isinstance(tiles, str) and tiles.strip().lower() == "auto":
        tiles = _designed_tiles(design)
    if resolution is not None:
        resolution = _checks.number("resolution", resolution, low=0.0, low_open=True)
    radius_m = parse_length(radius, option="radius")
    _physical("radius", radius_m)
    source = str(design) if isinstance(design, str | os.PathLike) else None
    step = None
    if z_step is not None:
        from metainterface.api.tolerance import layer_step

        step = layer_step(z_step, radius_m, d.settings.delta_max)
    flank_step = _checks.whole("flank_step", flank_step, low=1, high=64)
    if not isinstance(force, bool):
        raise MetainterfaceError(f"force must be True or False, got {force!r}")
    notes = (*idle_notes(d), *_cells_note(d, tiles))
    record = export_design(
        d,
        path,
        z_step=step,
        radius=radius_m,
        tiles=tiles,
        fmt=format,
        resolution=resolution,
        base=_checks.number("base", parse_length(base, option="base"), low=1e-6, high=1.0),
        source=source,
        flank_step=flank_step,
        force=force,
    )
    return {**record, "notes": list(notes)} if notes else record


def _cells_note(d: Design, tiles: Any) -> tuple[str, ...]:
    """A note when the export's cells are fewer than the design file's physical block says
    the interface holds."""
    from metainterface.io.export import parse_tiles

    block = d.extras.get("physical")
    if not isinstance(block, dict) or "tiles_per_side" not in block:
        return ()
    nx, ny = parse_tiles(tiles)
    per_side = block["tiles_per_side"]
    if nx >= per_side and ny >= per_side:
        return ()
    return (
        f"this export is {nx}x{ny} unit cells (one cell: {block['cell_side_m'] * 1e3:.4g} mm "
        f"square, {d.n_asperities} asperities); the design's physical block covers its area "
        f"with {block['n_cells']:.3g} cells: --tiles {per_side}x{per_side} for the whole patch",
    )
def _designed_tiles(design: Any) -> tuple[int, int]:
    """(n, n) from the physical block of a design.json (tiles='auto')."""
    import json

    block = None
    if isinstance(design, str | os.PathLike):
        try:
            block = json.loads(Path(design).read_text()).get("physical")
        except (OSError, ValueError, AttributeError):
            block = None
    if not isinstance(block, dict) or "tiles_per_side" not in block:
        raise MetainterfaceError(
            "tiles='auto' needs a design.json whose physical block has the tiling (designed "
            "with radius, modulus and an area or total force); give tiles as (nx, ny)",
            argument="tiles",
        )
    n = int(block["tiles_per_side"])
    return n, n


def physical(
    design: Design,
    *,
    radius: str | float,
    modulus: str | float,
    total_force: str | float | None = None,
    area: str | float | None = None,
) -> dict[str, Any]:
    """The design in SI units for an asperity radius and a modulus (paper sec. 2.3): the
    pressure at P*_max, heights, cell side and, for a total force or an area, the number of
    unit cells. Keys end in their unit (_m, _m2, _pa, _n)."""
    opts = _physical_options(radius, modulus, total_force, area)
    assert opts is not None
    return physical_block(_as_design(design, None, None, None), **opts)


def pressure_check(
    design: Design, max_pressure: float | str, *, modulus: str | float | None = None
) -> PressureCheck:
    """Each asperity's peak contact pressure at Delta_max against a limit (p/E*, or a stress
    with ``modulus``): which asperities would yield."""
    limit = _limit(max_pressure, modulus)
    assert limit is not None
    d = _as_design(design, None, None, None)
    if modulus is None:
        return check_pressure(d, limit)
    e_star = parse_pressure(modulus, option="modulus")
    return check_pressure(d, limit * e_star, e_star=e_star)
