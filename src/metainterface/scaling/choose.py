"""A friction law's scale in the user's units: which area, modulus or shear strength makes
it reachable (:func:`feasible_scale`), and a design with that scale chosen together with the
cell (:func:`design_scale`)."""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from metainterface._threads import uses_threads
from metainterface.designer.options import OLD_KEYWORDS, Effort, as_groups, option_groups
from metainterface.errors import MetainterfaceError, UnitSlipWarning
from metainterface.inverse.refine import RefineSettings
from metainterface.inverse.targets import Target
from metainterface.physics.cell import CellSettings
from metainterface.scaling import search as _scale
from metainterface.scaling.candidates import _candidates, _quick_scores, _ranked, score
from metainterface.scaling.finalists import checked_finalist, recorded

#: Candidate scales designed quickly before the chosen one is designed in full.
CANDIDATES = 5
#: The quick design of each candidate: a short refinement, no fallback multistart, no
#: re-seeding of idle asperities (it cost as much as the candidates' designs, and the
#: chosen scale's full design re-seeds; ``benchmarks/results/loaded.md``).
QUICK = RefineSettings(
    stages=2, steps_per_stage=3, iterations=20, polish_iterations=20, reseed=False, offset=False
)
#: With adhesion the FINALISTS best quick scores are designed in full and checked in turn
#: (``finalists.checked_finalist``): a snap-in moves a quick score more than the scales
#: differ, so the quick round's best can design in full to a worse score than its second.
#: Without it the quick round ranks as the full designs do (benchmarks/results/adhesion.md).
FINALISTS = 2
#: Options of the three scale variables, as the error messages name them.
_OPTIONS = {"area": "area", "modulus": "modulus", "shear_strength": "shear_strength"}


def _parser(var: str):
    from metainterface.units.quantities import parse_area, parse_pressure

    return parse_area if var == "area" else parse_pressure


def parse_scale(
    value: Any, var: str, option: str | None = None
) -> tuple[float | None, tuple[float, float] | None]:
    """(value, None) for a fixed scale, (None, (low, high)) for a range ('2cm2..10cm2', a
    pair) or (None, None) for 'auto' (the whole default search). SI."""
    option = option or _OPTIONS[var]
    parse = _parser(var)
    if isinstance(value, str) and value.strip().lower() == "auto":
        return None, None
    if isinstance(value, str) and ".." in value:
        parts = value.split("..")
        if len(parts) != 2:
            raise MetainterfaceError(f"{option}: a range is LOW..HIGH, e.g. 2cm2..10cm2")
        lo, hi = (parse(x.strip(), option=option) for x in parts)
    elif isinstance(value, tuple | list):
        if len(value) != 2:
            raise MetainterfaceError(f"{option}: a range is a pair (low, high), got {value!r}")
        lo, hi = (parse(x, option=option) for x in value)
    else:
        return parse(value, option=option), None
    if not lo < hi:
        raise MetainterfaceError(f"{option}: the range's low end must be below its high end")
    return None, (lo, hi)


def _law_and_scale(
    law: Any,
    shear_strength: Any,
    modulus: Any,
    radius: Any,
    area: Any,
    fit: str,
    work_of_adhesion: Any = None,
) -> tuple[Any, Any, dict[str, float], str | None, tuple[float, float] | None]:
    """(law, fit, given SI scale, the variable left free or None, its bounds); the scale
    holds ``work_of_adhesion`` [J/m^2] too (0 without adhesion)."""
    from metainterface.units.friction import prepare_law
    from metainterface.units.plausible import warn_unit_slips
    from metainterface.units.quantities import parse_length, parse_work_of_adhesion

    values = {"area": area, "modulus": modulus, "shear_strength": shear_strength}
    given: dict[str, float] = {}
    free: list[tuple[str, tuple[float, float] | None]] = []
    for var, v in values.items():
        fixed, span = parse_scale(v, var)
        if fixed is None:
            free.append((var, span))
        else:
            given[var] = fixed
    if len(free) > 1:
        raise MetainterfaceError(
            f"give a range or 'auto' for one of area, modulus, shear_strength at a time "
            f"(got {', '.join(v for v, _ in free)})"
        )
    var, span = free[0] if free else (None, None)
    if var is not None:  # the search starts from the middle of the range
        given[var] = math.sqrt(span[0] * span[1]) if span else math.nan
    work = 0.0
    if work_of_adhesion is not None:
        work = parse_work_of_adhesion(work_of_adhesion, option="work_of_adhesion")
    law, lf = prepare_law(law, fit, offset=work > 0)
    given["radius"] = parse_length(radius, option="radius")
    given["work_of_adhesion"] = work
    warn_unit_slips(
        **{k: given[k] for k in ("modulus", "shear_strength", "radius") if k != var},
        work_of_adhesion=work,
    )
    return law, lf, given, var, span


def _reference(law: Any, given: dict[str, float], var: str | None) -> dict[str, float]:
    """The given scale, an 'auto' variable set where the law's largest point sits at half
    the cell's largest reachable P* (area, modulus) or alpha = 0.02 (tau); with adhesion,
    the adhesive cell's P* at the given modulus (the adhesionless one for a free modulus)."""
    if var is None or math.isfinite(given[var]):
        return given
    from metainterface.inverse.envelope import reachable_envelope

    w = (
        0.0
        if var == "modulus"
        else given["work_of_adhesion"] / (given["modulus"] * given["radius"])
    )
    _, _, reach = reachable_envelope(np.zeros(1), CellSettings(), adhesion=w)
    reach = reach if reach > 0 else reachable_envelope(np.zeros(1), CellSettings())[2]
    fn, ff = float(law.normal_force.max()), float(law.friction_force.max())
    g = dict(given)
    if var == "area":
        g["area"] = fn / (0.5 * reach * g["modulus"])
    elif var == "modulus":
        g["modulus"] = fn / (0.5 * reach * g["area"])
    else:
        g["shear_strength"] = ff / (0.02 * g["area"])
    return g


@uses_threads()
def feasible_scale(
    law: str | os.PathLike[str] | Any,
    *,
    shear_strength: str | float,
    modulus: str | float,
    radius: str | float,
    area: str | float,
    settings: CellSettings | None = None,
    fit: str = "auto",
    work_of_adhesion: str | float | None = None,
) -> _scale.FeasibleScale:
    """Which area, modulus E* or shear strength tau makes a friction law reachable.

    law: a CSV ``normal_force,friction_force`` [N] (or a FrictionLaw), fitted as in
    :meth:`Target.from_friction` (``fit``). shear_strength, modulus, radius, area: the scale
    as given ('0.25MPa', '2MPa', '0.5mm', '4cm2', or SI numbers); one of area, modulus,
    shear_strength may be a range ('2cm2..10cm2') to search within. The radius moves nothing
    (P* and alpha are averages over the area); it sets how many cells tile it, and with
    adhesion w / (E* R). work_of_adhesion: w ('50mJ/m2' or J/m^2) for an adhesive contact
    (JKR asperities, as :func:`~metainterface.reachability` and
    :func:`~metainterface.design` take it): an offset F_f(0) > 0 is then accepted and the
    cells tested are adhesive ones, with the same reach test those ask.

    Returns a FeasibleScale: ``.reachable`` at the given scale, ``.ranges`` per variable
    (SI intervals that make it reachable, the other two as given), ``.best``,
    ``.summary()`` (lines in the user's units, e.g. 'reachable with an area of 6.1-9.8
    cm^2'), ``.record()``.
    """
    law, _, given, var, span = _law_and_scale(
        law, shear_strength, modulus, radius, area, fit, work_of_adhesion
    )
    return _feasible(law, given, var, span, settings)[1]


def _feasible(
    law: Any,
    given: dict,
    var: str | None,
    span: Any,
    settings: CellSettings | None,
    variables: tuple[str, ...] = _scale.VARIABLES,
) -> tuple[dict, _scale.FeasibleScale]:
    """The scale as given, completed where free (``_reference``), and the law's feasible
    scale there, ``var`` searched within ``span`` (of the ``variables`` searched)."""
    given = _reference(law, given, var)
    fs = _scale.feasible_scale(
        law.normal_force,
        law.friction_force,
        area=given["area"],
        modulus=given["modulus"],
        shear_strength=given["shear_strength"],
        radius=given["radius"],
        settings=settings,
        bounds=None if span is None else {var: span},
        work_of_adhesion=given["work_of_adhesion"],
        variables=variables,
    )
    return given, fs


@uses_threads()
def design_scale(
    law: str | os.PathLike[str] | Any,
    *,
    shear_strength: str | float,
    modulus: str | float,
    radius: str | float,
    area: str | float = "auto",
    settings: CellSettings | None = None,
    fit: str = "auto",
    name: str | None = None,
    candidates: int = CANDIDATES,
    work_of_adhesion: str | float | None = None,
    **options: Any,
) -> Any:
    """Design a cell for a friction law with the scale chosen together with it.

    One of area, modulus, shear_strength is 'auto' or a range ('2cm2..10cm2'; area defaults
    to 'auto'), the others fixed. The scales that make the law reachable are found
    (:func:`feasible_scale`); ``candidates`` values spread over them (or, where none is
    reachable, around the closest) are each designed with a short refinement (no
    re-seeding), in one batch, then up to three more between the best and its neighbours;
    the one with the smallest error is designed in full with ``options`` (as
    :func:`~metainterface.design`, e.g. ``method``, ``seed``, ``out``). With adhesion the
    best ``FINALISTS`` quick scores are designed in full first (without the BEM check) and
    the best of those is chosen: a snap-in makes a quick score a poor guess of the full one.

    A candidate's score (``score``) is its quick design's relative curve error plus the
    share of the law's pressure range the design does not reach by Delta_max, plus, for an
    offset law, its F_0's relative error.

    work_of_adhesion: w ('50mJ/m2' or J/m^2) for an adhesive contact: the law may have
    F_f(0) > 0, the scale search tests adhesive cells (:func:`feasible_scale`) and every
    candidate is designed with JKR asperities of w / (E* R) at its scale.

    Returns the DesignResult; ``result.target.meta["scale"]`` holds the chosen value, the
    tiling it gives (cells and cells per side), the candidates and their scores and the
    feasibility summary, and design.json records them.
    """
    from metainterface.units.friction import FrictionLaw

    source = str(law) if not isinstance(law, FrictionLaw) else law.source
    in_scale = getattr(options.get("scale"), "work_of_adhesion", None)  # mi.Scale(...)
    if in_scale is not None:
        if work_of_adhesion is not None:
            raise MetainterfaceError(
                "give the work of adhesion once: work_of_adhesion= or "
                "scale=mi.Scale(work_of_adhesion=...)",
                argument="work_of_adhesion",
            )
        work_of_adhesion = in_scale
    law, lf, given, var, span = _law_and_scale(
        law, shear_strength, modulus, radius, area, fit, work_of_adhesion
    )
    if var is None:
        raise MetainterfaceError(
            "design_scale: give area, modulus or shear_strength as 'auto' or a range "
            "(e.g. area='2cm2..10cm2'); with all three fixed use design()"
        )
    if not isinstance(candidates, int) or not 1 <= candidates <= 32:
        raise MetainterfaceError(f"candidates must be an integer in [1, 32], got {candidates!r}")
    s = settings or CellSettings()
    # with adhesion each modulus searched has an envelope of its own: only the free variable
    searched = (var,) if given["work_of_adhesion"] else _scale.VARIABLES
    given, fs = _feasible(law, given, var, span, s, searched)
    stem = name or (os.path.splitext(os.path.basename(source))[0] or "friction")
    at = _AtScale(law, lf, given, var, source, settings)
    knobs, size, made_errors = option_groups(
        {k: options.pop(k) for k in list(options) if k in OLD_KEYWORDS},
        options.pop("effort", None),
        options.pop("scale", None),
        options.get("robust"),
        "design_scale",
    )
    quick_opts = {k: v for k, v in options.items() if k in ("method", "model")}

    def quick(vals: np.ndarray) -> np.ndarray:
        return _quick_scores(at, fs, vals, stem, _quick_effort(knobs, at.adhesive), quick_opts)

    values, errors = _ranked(fs, var, _candidates(fs, var, candidates), quick)

    def full(value: float) -> tuple[Any, Any]:
        opts = {**options}
        opts.update(
            as_groups(knobs, at.size(size, value, fs), made_errors, opts.get("robust", False))
        )
        return _full_design(at, fs, value, stem, opts)

    order = np.argsort(errors, kind="stable")
    scores: dict[str, Any] = {
        "candidates": [float(v) for v in values],
        "candidate_scores": [float(e) for e in errors],
    }
    if not (at.adhesive and order.size > 1):
        r, finish = full(float(values[order[0]]))
        return finish([recorded(r, scores)])
    finals = {float(values[i]): full(float(values[i])) for i in order[:FINALISTS]}
    scores["finalists"] = list(finals)
    scores["finalist_scores"] = [score(r) for r, _ in finals.values()]
    return checked_finalist(finals, scores, var)


@dataclass(frozen=True)
class _AtScale:
    """A law and its scale as given, the free variable ``var`` aside: the target and the
    physical size at a value of it."""

    law: Any
    fitted: Any
    given: dict
    var: str
    source: str
    settings: CellSettings | None

    @property
    def adhesive(self) -> bool:
        return bool(self.given["work_of_adhesion"])

    def scale(self, value: float) -> dict[str, Any]:
        """The scale with ``var`` = ``value``, the others as given (SI)."""
        return {**self.given, self.var: float(value)}

    def target(self, value: float, label: str) -> Target:
        """The law as a target with ``var`` = ``value`` (the work of adhesion as w / (E* R)
        at that scale, in its meta)."""
        from metainterface.units.friction import fit_record, friction_target

        at = self.scale(value)
        ft = friction_target(
            self.law,
            shear_strength=at["shear_strength"],
            e_star=at["modulus"],
            radius=at["radius"],
            area=at["area"],
            settings=self.settings,
            fit="never",
            work_of_adhesion=at["work_of_adhesion"],
        )
        record = ft.record()
        if self.fitted is not None:
            record["fit"] = fit_record(self.fitted)
        return Target(
            p_star=ft.p_star, alpha=ft.alpha, name=label, source=self.source,
            meta={"friction": record},
        )  # fmt: skip

    def size(self, size: dict[str, Any], value: float, fs: _scale.FeasibleScale) -> dict:
        """The design's physical size options at ``value`` (the target carries w)."""
        at = self.scale(value)
        out = {**size, "modulus": at["modulus"], "radius": at["radius"], "work_of_adhesion": None}
        if out["total_force"] is None:
            out["area"] = at["area"]
        return out


def _quick_effort(knobs: dict[str, Any], adhesive: bool) -> Effort:
    """The candidates' quick design: a short refinement (``QUICK``), no fallback; an offset
    law's F_0 polished in it too."""
    return Effort(
        hedge=knobs["hedge"],
        seed=knobs["seed"],
        surrogate=knobs["surrogate"],
        fallback=0,
        refine_settings=replace(QUICK, offset=True) if adhesive else QUICK,
        # a candidate's design is rarely within Effort.hedge_error: its hedges are refined
        # with its prediction in one batch, not after it
        hedge_error=0.0,
    )


def _full_design(
    at: _AtScale,
    fs: _scale.FeasibleScale,
    value: float,
    stem: str,
    options: dict[str, Any],
) -> tuple[Any, Any]:
    """The full design at ``value`` of the scale variable before its BEM check, and what
    checks and writes it (``designer.run.designed``); the search's record in the target's
    meta ("scale"), its scores added by ``finalists.recorded``."""
    from metainterface.designer.run import designed

    n_cells, per_side = fs.tiles(at.scale(value)["area"])
    t = at.target(value, stem)
    record = {"variable": at.var, "value": value, "searched": list(fs.bounds[at.var])}
    record.update(n_cells=n_cells, tiles_per_side=per_side)
    t = replace(t, meta={**t.meta, "scale": {**record, "feasibility": fs.record()}})
    with warnings.catch_warnings():  # a unit slip was said once, above
        warnings.simplefilter("ignore", UnitSlipWarning)
        results, finish = designed(t, settings=at.settings, **options)
    return results[0], finish


def scale_line(result: Any) -> str | None:
    """One line on the scale a design chose, in the user's units, or None. The range is
    the feasibility line's (printed before it), not repeated here: one range on screen."""
    sc = result.target.meta.get("scale") if isinstance(result.target.meta, dict) else None
    if not sc:
        return None
    fmt = _scale.fmt_area if sc["variable"] == "area" else _scale.fmt_pressure
    what = {"area": "area", "modulus": "E*", "shear_strength": "tau"}[sc["variable"]]
    n, side = sc["n_cells"], sc["tiles_per_side"]
    f0 = getattr(result, "f0_error", None)
    met = "" if f0 is None or f0 <= 0.02 else ", UNMET: above 2 %"
    return (
        f"{result.target.name}: chose {what} = {fmt(sc['value'])} ({len(sc['candidates'])} "
        f"candidates), {n:.4g} cells ({side}x{side} tiles), error {100 * result.error:.3g} %"
        + ("" if f0 is None else f", F_0 off by {100 * f0:.3g} %{met}")
    )
