"""The scale search's finalists with adhesion: which of the scales designed in full is kept.

A snap-in makes a candidate's quick design a poor guess of its full one, so with adhesion
the best quick scores are designed in full (``choose.FINALISTS``); and the model's score of
a full design can prefer one that misses in BEM (``benchmarks/results/adhesion.md``), so the
finalists are checked in turn before one is kept (:func:`checked_finalist`)."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from metainterface.scaling import search as _scale
from metainterface.scaling.candidates import score


def checked_finalist(finals: dict[float, tuple[Any, Any]], scores: dict[str, Any], var: str) -> Any:
    """Of the finalists (value of ``var``: its design before the BEM check and the
    ``designer.finish.Finish`` of its ``designed`` call), the one kept, checked and
    written, with the search's record (``scores`` and the finalists' checks).

    They are checked in turn (not corrected), the best model score
    (``scores["finalist_scores"]``) first, and the first that meets (its BEM check, F_0)
    is kept; where none does, the one whose score plus BEM error is least. The kept one is
    then finished as asked: corrected where its check calls for it, from that check. None
    is designed again, and only the kept one is written."""
    model_score = dict(zip(finals, scores["finalist_scores"], strict=True))
    checked: dict[float, Any] = {}
    kept = None
    for v in sorted(finals, key=model_score.__getitem__):
        r, finish = finals[v]
        checked[v] = finish.check([r], correct=False)[0]
        if meets(checked[v]):
            kept = v
            break
    if kept is None:
        kept = min(checked, key=lambda v: score(checked[v]) + (checked[v].bem_error or 0.0))
    r, finish = finals[kept]
    first = checked[kept].bem
    if first is not None and finish.verify is not None and finish.verify.wants_correction(first):
        r = finish.check([r], first=[first])[0]  # the check as asked, from the one solved
    else:
        r = checked[kept]
    if len(checked) > 1:  # the model's best missed: say what each finalist did
        fmt = _scale.fmt_area if var == "area" else _scale.fmt_pressure
        said = ", ".join(
            f"{fmt(v)} (model {_percent(model_score[v])}, BEM {_percent(c.bem_error)}, "
            f"F_0 {_percent(c.f0_error)})"
            for v, c in checked.items()
        )
        r = replace(
            r, notes=(*r.notes, f"scale: the finalists as checked: {said}; kept {fmt(kept)}")
        )
    scores = {
        **scores,
        "finalists_checked": list(checked),
        "finalist_bem_errors": [c.bem_error for c in checked.values()],
    }
    return finish.save([recorded(r, scores)])


def meets(result: Any) -> bool:
    """Whether a checked design meets what was asked: its BEM check (where it ran) and
    F_0 (an offset law's)."""
    return (result.bem is None or bool(result.bem_ok)) and result.f0_met is not False


def recorded(result: Any, scores: dict[str, Any]) -> Any:
    """The result with the search's candidates and scores in its target's meta ("scale")."""
    t = result.target
    scale = {**t.meta["scale"], **scores}
    # the record's keys in the order design.json has always shown them
    first = ("variable", "value", "searched", *scores, "n_cells", "tiles_per_side")
    scale = {k: scale[k] for k in first} | scale
    return replace(result, target=replace(t, meta={**t.meta, "scale": scale}))


def _percent(value: float | None) -> str:
    return "-" if value is None else f"{100 * value:.3g} %"
