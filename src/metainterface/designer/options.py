"""Option groups of :func:`~metainterface.design`: small frozen values a user builds once and
passes to every design (``mi.design(t, scale=..., robust=..., effort=...)``).

The groups are the one way to give these options. The keywords they replace (``starts=``,
``radius=``, ``sigma_h=``, ...) are still read for one release, each call that uses them
warned with a :class:`DeprecationWarning` naming the group to use; a group and one of its
own old keywords in the same call is refused, so that no value silently wins. The values
are checked where they are used, with the same one-line errors as before.
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, fields
from typing import Any

from metainterface.errors import MetainterfaceError
from metainterface.inverse.refine import HEDGE_ERROR, RefineSettings


@dataclass(frozen=True)
class Scale:
    """The user's scale: the size, the material pair and what the patch carries, in SI.

    With a scale, a design's ``design.json`` holds its dimensions in SI (the physical block),
    a stress ``max_pressure`` ('50MPa') is read against the modulus, and lengths given to
    ``z_step`` or :class:`Robust`'s ``sigma_h`` ('1um') are read in units of R.

    Attributes
    ----------
    radius : str or float or None
        R, the asperity's lateral size ('0.5mm', or m); with ``modulus`` it adds the
        design's dimensions in SI to design.json.
    modulus : str or float or None
        E* of the material pair ('2MPa', or Pa).
    total_force : str or float or None
        A total normal force the patch carries ('10N'): design.json then gives the number of
        cells for it. Needs ``radius`` and ``modulus``; not with ``area``.
    area : str or float or None
        The patch's area ('4cm2', or m^2), instead of ``total_force``.
    work_of_adhesion : str or float or None
        w of the material pair ('50mJ/m2', or J/m^2): the design's forward model is then
        adhesive (JKR, w / (E* R)); needs ``radius`` and ``modulus``.

    Examples
    --------
    >>> import metainterface as mi
    >>> pad = mi.Scale(radius="0.5mm", modulus="2MPa", area="4cm2")
    >>> pad.radius
    '0.5mm'
    """

    radius: str | float | None = None
    modulus: str | float | None = None
    total_force: str | float | None = None
    area: str | float | None = None
    work_of_adhesion: str | float | None = None


@dataclass(frozen=True)
class Robust:
    """A robust design: made for a printer's errors rather than for the nominal cell.

    Each start is refined against the mean squared error of ``samples`` perturbed copies of
    it (the same draws for every start, in the same batch); the start with the smallest rms
    error over them wins. ``result.error`` stays the nominal design's; ``result.robust``
    holds the nominal and robust statistics (those of 1024 made cells drawn independently).
    Passing ``robust=Robust(...)`` to :func:`~metainterface.design` is ``robust=True`` with
    these errors.

    Attributes
    ----------
    sigma_h : float or str
        Standard deviation of each asperity's height error: a plain number in units of R, or
        a length ('1um') with :class:`Scale`'s ``radius``; >= 0.
    sigma_gamma : float
        Standard deviation of each shape exponent's error (absolute); >= 0.
    scale_sigma : float
        Standard deviation of a common relative scale of the relief, in [0, 0.5].
    samples : int
        K, perturbed copies per start, in [1, 1024]; the cost grows about K-fold.

    At least one sigma must be > 0 (checked by :func:`~metainterface.design`).

    Examples
    --------
    >>> import metainterface as mi
    >>> printer = mi.Robust(sigma_h=0.002, sigma_gamma=0.05, samples=8)
    >>> printer.samples
    8
    """

    sigma_h: float | str = 0.0
    sigma_gamma: float = 0.0
    scale_sigma: float = 0.0
    samples: int = 16


@dataclass(frozen=True)
class Effort:
    """How hard a design searches: its starts, the surrogate and its hedge and fallback, the
    refinement and the seed.

    Attributes
    ----------
    surrogate : path or None
        The surrogate model file the surrogate method predicts with (``metainterface
        train``); None: the shipped one.
    starts : int
        Random starts of the multistart and Hertz methods, in [1, 10000].
    hedge : int
        Surrogate method: extra starts refined beside the prediction (half jittered copies of
        it, half random), in [0, 10000]; 0 is the paper's pure pipeline.
    fallback : int
        Surrogate method: a target still missed by more than 2 % (1 % with adhesion) also
        gets a multistart with this many starts, the better design kept; 0 turns it off.
    refine : bool
        Refine the starts (False: the zero-shot prediction or the best raw start).
    seed : int
        Seed of every random draw, in [0, 2**63 - 1]; the same seed gives the same designs.
    refine_settings : RefineSettings or None
        The refinement's stages, iterations and tolerances (default: the paper's 5 stages x
        5 steps x 20 iterations, then the polish); fewer make a quicker, rougher design.
    hedge_error : float
        Surrogate method: the hedge starts are refined (after the prediction's own design)
        only for targets that design misses by more than this relative curve error
        (default 5e-4, half the BEM's accuracy: a design within it gains nothing that
        matters from more starts);
        0 refines them with the prediction in one batch, for every target.

    Examples
    --------
    >>> import metainterface as mi
    >>> quick = mi.Effort(starts=8, hedge=2, fallback=0, seed=1)
    >>> quick.starts, quick.refine
    (8, True)
    """

    starts: int = 50
    hedge: int = 8
    fallback: int = 50
    refine: bool = True
    seed: int = 0
    refine_settings: RefineSettings | None = None
    hedge_error: float = HEDGE_ERROR
    surrogate: str | os.PathLike[str] | None = None


#: The old keyword of :func:`~metainterface.design` that each group's field stands for
#: (where the two names differ).
KEYWORDS: dict[type, dict[str, str]] = {Robust: {"samples": "robust_samples"}}
#: The group each old keyword now lives in, and the argument that takes the group.
OLD_KEYWORDS: dict[str, tuple[type, str]] = {
    **{
        k: (Effort, "effort")
        for k in ("starts", "hedge", "fallback", "refine", "seed", "refine_settings", "surrogate")
    },
    **{k: (Scale, "scale") for k in ("radius", "modulus", "total_force", "area")},
    **{k: (Robust, "robust") for k in ("sigma_h", "sigma_gamma", "scale_sigma", "robust_samples")},
}


def option_groups(
    old: dict[str, Any], effort: Any, scale: Any, robust: Any, caller: str = "design"
) -> tuple[dict[str, Any], dict[str, Any], dict[str, Any]]:
    """The fields of the three groups (``merge``'d), with the old keywords ``old`` read in
    for one release and warned about once per call.

    Raises MetainterfaceError on a keyword that never was one of ``caller``'s.
    """
    unknown = sorted(k for k in old if k not in OLD_KEYWORDS)
    if unknown:
        raise MetainterfaceError(
            f"{caller}() got an unexpected keyword {unknown[0]!r}", argument=unknown[0]
        )

    def pick(kind: type) -> dict[str, Any]:
        return {k: old.get(k) for k, (g, _) in OLD_KEYWORDS.items() if g is kind}

    groups = (
        merge(effort, Effort, "effort", pick(Effort)),
        merge(scale, Scale, "scale", pick(Scale)),
        merge(robust if isinstance(robust, Robust) else None, Robust, "robust", pick(Robust)),
    )
    given = {k: v for k, v in old.items() if v is not None}
    if given:
        by_group: dict[str, list[str]] = {}
        for k in given:
            kind, arg = OLD_KEYWORDS[k]
            field = {v: f for f, v in KEYWORDS.get(kind, {}).items()}.get(k, k)
            by_group.setdefault(f"{arg}=mi.{kind.__name__}", []).append(f"{field}=...")
        advice = "; ".join(f"{g}({', '.join(fs)})" for g, fs in by_group.items())
        warnings.warn(
            f"{caller}({', '.join(f'{k}=' for k in given)}) is deprecated and will be "
            f"removed: pass {advice}",
            DeprecationWarning,
            stacklevel=4,
        )

    return groups


def merge(group: Any, kind: type, argument: str, given: dict[str, Any]) -> dict[str, Any]:
    """The keywords of ``kind``'s fields: from ``group`` (an instance or None), else from the
    keywords ``given`` (None where not given), else the group's defaults.

    Raises MetainterfaceError naming ``argument`` when ``group`` is of another type, or
    when it comes with one of its own keywords.
    """
    rename = KEYWORDS.get(kind, {})
    names = {f.name: rename.get(f.name, f.name) for f in fields(kind)}
    if group is None:
        group = kind()
    else:
        if not isinstance(group, kind):
            raise MetainterfaceError(
                f"{argument} must be {kind.__name__}(...), got {type(group).__name__}",
                argument=argument,
            )
        both = [kw for kw in names.values() if given.get(kw) is not None]
        if both:
            raise MetainterfaceError(
                f"give {argument}={kind.__name__}(...) or {', '.join(both)}, not both",
                argument=argument,
            )
    return {
        kw: getattr(group, name) if given.get(kw) is None else given[kw]
        for name, kw in names.items()
    }


def as_groups(
    knobs: dict[str, Any], size: dict[str, Any], errors: dict[str, Any], robust: Any
) -> dict[str, Any]:
    """``option_groups``' fields back as the arguments ``effort``, ``scale`` and ``robust``."""
    if robust is True or isinstance(robust, Robust):
        rename = KEYWORDS[Robust]
        robust = Robust(**{f.name: errors[rename.get(f.name, f.name)] for f in fields(Robust)})
    elif any(errors[k] not in (None, 0, 0.0) for k in ("sigma_h", "sigma_gamma", "scale_sigma")):
        raise MetainterfaceError("sigma_h, sigma_gamma and scale_sigma need robust=True")
    return {"effort": Effort(**knobs), "scale": Scale(**size), "robust": robust}
