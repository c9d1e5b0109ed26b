"""The adhesive check by the disc criterion, extrapolated over three grids (issue 52).

The disc criterion (``validation.adhesive_discs``) finds each JKR edge from a family of
bonded discs; its error falls as the grid spacing, with one sign (a Hertz asperity against
JKR: +1.4 to +2.9 % at 128 points per asperity, +0.7 to +1.4 % at 256). So the check loads
the design along the same approaches on three grids, M / 4, M / 2 and M, and reads its
curve from the last two extrapolated to zero spacing at each approach (Richardson, first
order: 2 x(M) - x(M / 2), for P* and alpha alike, at the approaches where both grids have
the same asperities touching). Its own error is what the extrapolation leaves: the
difference between the curve extrapolated from (M / 2, M) and the one from (M / 4, M / 2),
read at the same loads (``adhesive.read_across_jumps``) over the target's norm there, over
2^2 - 1 = 3 (the remainder is taken to be of second order, ``RESIDUAL_ORDER``), plus the
fits' own scatter (``FIT_SCATTER``).

The three paths run at once: the coarse two on a helper thread, which then solves the
finest grid's discs that its path will need last (the radii the M / 2 path reached,
asperity by asperity in reverse order of touch), while the finest path runs here and
solves its own on demand.
"""

from __future__ import annotations

import math
import threading
import time

import numpy as np

from metainterface._threads import in_background
from metainterface.inverse.targets import Target
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel
from metainterface.validation.adhesive_discs import DiscCell, DiscCriterionError, disc_path
from metainterface.validation.adhesive_path import (
    APPROACHES_PER_LOAD,
    AdhesivePath,
    approaches,
    compared_states,
    own_snap_ins,
)
from metainterface.verify._adhesive_curve import (
    AdhesiveSolved,
    inside_target,
    model_alpha,
    path_notes,
    read_across_jumps,
)

#: Points per asperity at least of the check's coarsest grid: below it a contact spans too
#: few radii for the family's fit.
COARSEST = 32
#: The order assumed of what the first-order extrapolation leaves: the difference of two
#: extrapolations is then 2^2 - 1 = 3 times the finer one's error. On the example cell and
#: nine held-out cells (w = 4.2e-5 to 5e-4 E* R), the estimate below was 1.4-7.1 times the
#: check's difference to the same criterion a grid finer (extrapolated from 384^2 and
#: 768^2): ``benchmarks/bench_adhesive_disc_check.py``, benchmarks/results/adhesion.md.
RESIDUAL_ORDER = 2.0
#: Added to that estimate: the scatter of the fits themselves, which no grid takes away in
#: a foreseeable way (where the windows fall on the staircase of distinct radii). The
#: extrapolated alpha moves by up to 0.07 % between fitting every third radius and every
#: one (``bench_adhesive_subpixel.py --path 10 --stride``), and without it a Hertz
#: asperity at w = 5e-4 E* R reads 0.18 % off JKR where the difference of the
#: extrapolations over 3 reads 0.13 % (``bench_adhesive_disc_check.py --hertz``).
FIT_SCATTER = 1e-3


def _extrapolated(fine: AdhesivePath, coarse: AdhesivePath) -> tuple[np.ndarray, ...]:
    """(P*, alpha, valid) (K,) extrapolated to zero spacing from the paths on grids M and
    M / 2 at their common approaches (the first K of both), valid where both have the same
    asperities touching; P* of the fine path where not valid. And its touching (K, N)."""
    k = min(fine.p_star.size, coarse.p_star.size)
    assert fine.touching is not None and coarse.touching is not None
    same = (fine.touching[:k] == coarse.touching[:k]).all(1)
    same &= np.isfinite(fine.p_star[:k]) & np.isfinite(coarse.p_star[:k])
    p = np.where(same, 2 * fine.p_star[:k] - coarse.p_star[:k], fine.p_star[:k])
    a = np.where(same, 2 * fine.alpha[:k] - coarse.alpha[:k], fine.alpha[:k])
    return p, a, same, fine.touching[:k]


def _curve(fine: AdhesivePath, coarse: AdhesivePath, peaks: np.ndarray, top: float):
    """The extrapolated load-controlled curve: (P*, alpha) (K,), keep (K,) bool (both grids
    touching alike, and ``compared_states``: the model's snap-ins ``peaks`` (N,), at most
    ``top``) and its snap-ins (J, 2)."""
    p, a, same, touching = _extrapolated(fine, coarse)
    running = np.maximum.accumulate(np.where(same, p, -np.inf))
    # the snap-ins from every state, those left out read between their neighbours
    placed = np.isfinite(p)
    if not placed.any():
        raise DiscCriterionError("the disc criterion placed no state of the path")
    at = np.arange(p.size)
    snaps = own_snap_ins(np.interp(at, at[placed], p[placed]), touching)
    on_branch = same & (p >= running) & (p > 0)
    return p, a, compared_states(p, on_branch, touching, peaks, snaps, top), snaps


def disc_check(
    design: Design,
    target: Target,
    model: ForwardModel,
    *,
    grids: tuple[int, int, int],
    loads: int,
    device: str = "auto",
    engine: str = "torch",
    known: dict[int, AdhesivePath] | None = None,
) -> tuple[AdhesiveSolved, float]:
    """``design`` in the disc criterion on ``grids`` (M / 4, M / 2, M): the curve from the
    finer two extrapolated, at the states a rising force reaches inside the target's range,
    and its own error from the coarser two. ``engine``: the one asked for (noted when it is
    not torch). ``known``: paths already solved (by grid) along the same approaches, taken
    as they are; the paths solved here are added to it. Returns (AdhesiveSolved, accuracy).
    Raises DiscCriterionError where the criterion does not apply, MetainterfaceError where
    no state lies in the target's range or a solve does not converge."""
    from metainterface._device import resolve_device

    start = time.perf_counter()
    s = design.settings
    top = min(target.p_star_max, model.model_curve(design).p_star_max)
    deltas = approaches(design, model, top, APPROACHES_PER_LOAD * loads)
    dev = resolve_device(device)
    work = model.adhesion * s.e_star * s.radius  # w [E* length] in the cell's units
    known = {} if known is None else known
    cells = [DiscCell(design, g, work, float(deltas[-1]), device=dev) for g in grids]
    stop = top * (1 + 1e-9)
    done = threading.Event()

    def path(i: int) -> AdhesivePath:
        # a state the criterion cannot place on a grid (an asperity just touched, its contact
        # a few spacings wide) is left out of the curves it enters
        if grids[i] not in known:
            known[grids[i]] = disc_path(cells[i], deltas, stop_above=stop, skip_failures=True)
        return known[grids[i]]

    def coarse_then_help() -> list[AdhesivePath]:
        paths = [path(0), path(1)]
        # the finest path's discs, last-touching asperity first, over the radii the path
        # on M / 2 reached (the finest one's lie within a spacing or two of them)
        last = paths[1]
        assert last.asperity_alpha is not None and last.touching is not None
        radius = np.sqrt(last.asperity_alpha * s.cell_side**2 / math.pi)
        first = np.array([np.argmax(t) if t.any() else -1 for t in last.touching.T])
        order = [k for k in np.argsort(-first, kind="stable") if first[k] >= 0]
        ranges = {int(k): (float(radius[first[k], k]), float(radius[-1, k])) for k in order}
        cells[2].prefill(ranges, done)
        return paths

    with in_background(coarse_then_help, name="adhesive-discs") as helper:
        try:
            finest = path(2)
        finally:
            done.set()
        coarsest, middle = helper()
    k = min(finest.p_star.size, middle.p_star.size)
    unplaced = int((~np.isfinite(finest.p_star[:k]) | ~np.isfinite(middle.p_star[:k])).sum())
    if unplaced > k // 4:
        raise DiscCriterionError(
            f"the disc criterion could not place {unplaced} of {k} states on {grids[1]}^2 "
            f"and {grids[2]}^2 (contacts a few spacings wide)"
        )
    peaks = model.touch_loads(design)
    p, a, keep, snaps = _curve(finest, middle, peaks, top)
    keep = inside_target(p, keep, target, "the adhesive check (disc criterion)")
    lp, la, lkeep, lsnaps = _curve(middle, coarsest, peaks, top)
    other = (
        read_across_jumps(p[keep], lp[lkeep], la[lkeep], lsnaps)
        if lkeep.sum() >= 2
        else np.full(int(keep.sum()), np.nan)
    )
    read = np.isfinite(other)
    norm = float(np.linalg.norm(np.interp(p[keep][read], target.p_star, target.alpha)))
    acc = (
        float(np.linalg.norm(a[keep][read] - other[read])) / norm / (2.0**RESIDUAL_ORDER - 1)
        + FIT_SCATTER
        if read.sum() >= max(2, keep.sum() / 2) and norm > 0
        else math.inf
    )
    m = [g // s.n_side for g in grids]
    notes = (
        f"adhesive BEM: the JKR limit, each edge from a family of bonded discs, "
        f"w = {model.adhesion:.3g} E* R, extrapolated to zero spacing from {grids[1]}^2 and "
        f"{grids[2]}^2 ({m[1]} and {m[2]} points an asperity); {int(keep.sum())} of "
        f"{deltas.size} approaches on the rising branch",
    )
    if unplaced:
        notes += (
            f"{unplaced} of {k} approaches left out: an asperity's contact there is too few "
            "spacings wide for the disc criterion on these grids (just after it touched)",
        )
    notes += path_notes(float(p[keep][-1]), top, engine)
    solved = AdhesiveSolved(
        p[keep],
        a[keep],
        model_alpha(design, model, p[keep]),
        str(dev),
        time.perf_counter() - start,
        notes,
        snaps,
    )
    return solved, acc
