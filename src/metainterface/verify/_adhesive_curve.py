"""The adhesive check's curve as the point-by-point and the disc checks return it, the steps
both take to compare a path with the target and the model, and how one such curve is read
at another's loads (``verify.adhesive``, ``verify.adhesive_discs``)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import torch

from metainterface.errors import MetainterfaceError
from metainterface.inverse.targets import Target
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel
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


def inside_target(p_star: np.ndarray, keep: np.ndarray, target: Target, what: str) -> np.ndarray:
    """(K,) bool: the states ``keep`` whose load ``p_star`` (K,) lies inside the target's
    range (below its first row np.interp would hold the target at that row's alpha, an error
    the target does not state). Raises MetainterfaceError, naming ``what`` solved the path,
    where none does."""
    inside = (p_star >= target.p_star[0] * (1 - 1e-9)) & (p_star <= target.p_star_max * (1 + 1e-9))
    keep = keep & inside
    if not keep.any():
        raise MetainterfaceError(
            f"{what} reached no load inside the target's range on its rising branch (up to "
            f"P* = {float(np.nanmax(p_star, initial=0.0)):.3g}); check on a finer grid"
        )
    return keep


def model_alpha(design: Design, model: ForwardModel, p_star: np.ndarray) -> np.ndarray:
    """(K,) the model's contact fraction of ``design`` at the loads ``p_star`` (K,)."""
    gamma, h = design.tensors(torch.float64)
    with torch.no_grad():
        alpha = model.alpha_at_loads(gamma, h, design.settings, torch.as_tensor(p_star)[None])
    return alpha[0].numpy()


def path_notes(p_last: float, top: float, engine: str) -> tuple[str, ...]:
    """The notes both checks add: the engine asked for where it is not torch (only torch
    has a JKR-limit solver), and a rising branch that stops well short of ``top``."""
    notes: tuple[str, ...] = ()
    if engine != "torch":
        notes += (f"the adhesive check runs in the torch engine, not {engine}",)
    if p_last < top * (1 - 0.25):
        notes += (
            f"the adhesive BEM's rising branch reaches P* = {p_last:.4g} in the target's "
            f"range, short of {top:.4g}: the check stops there",
        )
    return notes
