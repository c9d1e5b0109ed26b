"""The adhesive check's curve as the point-by-point and the disc checks return it, and how
one such curve is read at another's loads (``verify.adhesive``, ``verify.adhesive_discs``)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from metainterface.validation.adhesive_path import at_snap_ins


@dataclass(frozen=True)
class AdhesiveSolved:
    """The adhesive check's BEM path at the states a rising force reaches inside the
    target's range: p_star, alpha_bem, alpha_model (K,); device, wall time [s], notes;
    snap_ins (J, 2): the BEM's own snap-in loads, [lo, hi] P*, where it jumps."""

    p_star: np.ndarray
    alpha_bem: np.ndarray
    alpha_model: np.ndarray
    device: str
    seconds: float
    notes: tuple[str, ...]
    snap_ins: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))


def read_across_jumps(
    x: np.ndarray, xp: np.ndarray, fp: np.ndarray, jumps: np.ndarray
) -> np.ndarray:
    """(K,) a load-controlled curve (states ``xp``, ``fp`` (S,), sorted) read at loads ``x``
    (K,): linear within each piece between its ``jumps`` ((J, 2): each snap-in's load
    between lo and hi) and extrapolated from the piece's end states up to its jumps (one
    state: its value), never across a jump (a straight line there would read a snap-in as
    a slope); NaN within a jump's bounds (the curve may read either side there), outside
    ``xp``'s range and in a piece without states."""
    out = np.full(x.shape, np.nan)
    cuts = np.sort(0.5 * (jumps[:, 0] + jumps[:, 1]))
    piece_x = np.searchsorted(cuts, x)
    piece_p = np.searchsorted(cuts, xp)
    within = (x >= xp[0]) & (x <= xp[-1]) & ~at_snap_ins(x, jumps)
    for j in np.unique(piece_x[within]):
        at = within & (piece_x == j)
        xs, ys = xp[piece_p == j], fp[piece_p == j]
        if xs.size == 1:
            out[at] = ys[0]
        elif xs.size > 1:
            k = np.clip(np.searchsorted(xs, x[at]), 1, xs.size - 1)
            out[at] = ys[k - 1] + (ys[k] - ys[k - 1]) * (x[at] - xs[k - 1]) / (xs[k] - xs[k - 1])
    return out
