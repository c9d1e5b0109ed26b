"""An adhesive cell's load-controlled curve from the JKR-limit BEM (issues 38, 52).

A design made with an adhesive model has the loading curve under load control: the normal
force rises from zero, each asperity snaps in when it touches and the cell follows the
running maximum of its force (``physics.adhesion``). The BEM (``adhesive_bem``) solves the
cell by approach (displacement control: an adhesive contact has unstable branches that load
control would jump), at K approaches from touch up to a step past where the model reaches
the top load (``jkr_path``, each state warm-started from the one before, in two chains at
once: the second from the rigid overlap at ``RESTART_SHARE`` of the approaches). The states a
rising force reaches, those whose force is at its running maximum and positive and clear of
the model's snap-ins (``clear_of_snap_ins``) and of the BEM's own (``own_snap_ins``), are
the BEM's load-controlled curve. Both design's check (``verify.adhesive``) and ``validate``
of an adhesive design (``adhesive_validate``) read it.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass

import numpy as np
import torch

from metainterface._threads import in_background, stop_asked
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings, Design
from metainterface.physics.models import ForwardModel
from metainterface.validation.adhesive_bem import solve_jkr


@dataclass(frozen=True)
class AdhesivePath:
    """A cell loaded by approach (displacement control) in the JKR limit, then unloaded.

    approach: (K,) the approach of the rigid plane [length, units of R] (0: the mean gap
    of the surface's own tips-down plane); p_star, alpha: (K,) the BEM's mean pressure and
    contact fraction there; loading: (K,) bool, the samples of the rising part; on_branch:
    (K,) bool, the loading samples a rising force reaches (force at its running maximum
    and > 0: the states of the load-controlled curve the forward model gives, as far as the
    samples tell: a peak between two samples is not seen); touching: (K, N) bool, which
    asperities have a point in contact (with ``owner``, else None); asperity_alpha: (K, N)
    each asperity's contact area over the cell's (with ``owner``); p_max: (K,) the largest
    local pressure [E*]; residual: (K,) the bonded solve's relative residual; seconds: (K,)
    wall time of each state; pressure: (M, M) the last state's pressure [E*].
    """

    approach: np.ndarray
    p_star: np.ndarray
    alpha: np.ndarray
    loading: np.ndarray
    on_branch: np.ndarray
    touching: np.ndarray | None = None
    asperity_alpha: np.ndarray | None = None
    p_max: np.ndarray | None = None
    residual: np.ndarray | None = None
    seconds: np.ndarray | None = None
    pressure: np.ndarray | None = None


def jkr_path(
    heights: np.ndarray,
    side: float,
    work: float,
    approaches: np.ndarray,
    *,
    unload: np.ndarray | None = None,
    device: torch.device | str = "cpu",
    owner: np.ndarray | None = None,
    stop_above: float | None = None,
    restart: int | None = None,
) -> AdhesivePath:
    """One cell (M, M) along rising ``approaches`` (K,) [length], then falling ``unload``
    ones, each state warm-started from the one before (the contact's history matters).
    ``owner``: (M, M) the asperity index of each point (``heightmap.owner_map``), for the
    path's ``touching``. ``stop_above``: a P* at which loading stops, after the first state
    above it (the path then holds the approaches solved so far: every later state a rising
    force reaches is above it too). ``restart`` (loading only, 0 < restart < K): the
    approaches from that index on are loaded as a second chain, from the rigid overlap at
    the first of them, on another thread while the first chain runs (see
    :func:`_chains`); without ``unload``."""
    z = torch.as_tensor(np.ascontiguousarray(heights, dtype=np.float64), device=device)[None]
    up = np.asarray(approaches, dtype=np.float64)
    down = np.zeros(0) if unload is None else np.asarray(unload, dtype=np.float64)
    own = None if owner is None else torch.as_tensor(owner, device=z.device).reshape(-1)
    n_owner = 0 if owner is None else int(owner.max()) + 1
    if restart is not None and not (0 < restart < up.size and down.size == 0):
        raise ValueError(f"restart must be in (0, {up.size}) and without unload, got {restart}")
    if restart is None:
        states, _ = _chain(z, side, work, up, down, own, n_owner, stop_above)
    else:
        states = _chains(z, side, work, up, restart, own, n_owner, stop_above)
    p = np.array(states["p_star"])
    n_up = p.size - down.size
    loading = np.arange(p.size) < n_up
    top = np.maximum.accumulate(np.where(loading, p, -np.inf))
    on_branch = loading & (p >= top) & (p > 0)
    last = states["pressure"]
    return AdhesivePath(
        np.concatenate([up[:n_up], down]),
        p,
        np.array(states["alpha"]),
        loading,
        on_branch,
        np.array(states["touching"]) if own is not None else None,
        np.array(states["share"]) if own is not None else None,
        np.array(states["p_max"]),
        np.array(states["residual"]),
        np.array(states["seconds"]),
        None if last is None else last[0].cpu().numpy(),
    )


def _chain(
    z: torch.Tensor,
    side: float,
    work: float,
    up: np.ndarray,
    down: np.ndarray,
    own: torch.Tensor | None,
    n_owner: int,
    stop_above: float | None,
    cancel: threading.Event | None = None,
) -> tuple[dict, bool]:
    """The states of one chain of approaches, each from the one before (the first from
    the rigid overlap): rising ``up`` until the first state above ``stop_above``, then
    ``down``; per-state lists and the last state's pressure (1, M, M), and whether the
    loading stopped there. ``cancel``: once set (or once this thread's caller gives up on
    it, ``stop_asked``), no further state is solved (the states so far are returned, for a
    caller that drops them)."""
    z_bar = -float(z.mean())
    contact = pressure = None
    out: dict = {k: [] for k in ("p_star", "alpha", "touching", "share", "p_max", "residual")}
    out["seconds"] = []

    def solve(d: float) -> None:  # the state at approach d, from the one before
        nonlocal contact, pressure
        start = time.perf_counter()
        target = torch.tensor([z_bar - d], dtype=torch.float64, device=z.device)
        sol = solve_jkr(z, side, target, work, contact=contact, pressure=pressure)
        contact, pressure = sol.contact, sol.pressure
        out["p_star"].append(float(sol.p_star[0]))
        out["alpha"].append(float(sol.alpha[0]))
        out["p_max"].append(float(sol.pressure[0].amax()))
        out["residual"].append(float(sol.residual[0]))
        if own is not None:
            hits = torch.bincount(own[sol.contact[0].reshape(-1)], minlength=n_owner)
            out["touching"].append((hits > 0).cpu().numpy())
            out["share"].append((hits / own.numel()).cpu().numpy())
        out["seconds"].append(time.perf_counter() - start)

    def wanted() -> bool:  # neither the other chain nor the caller gave up on these states
        return not (cancel is not None and cancel.is_set()) and not stop_asked()

    stopped = False
    for d in up:
        if not wanted():
            break
        solve(d)
        if stop_above is not None and out["p_star"][-1] > stop_above:
            stopped = True  # the loading ends here; the unloading (if any) goes on
            break
    for d in down:
        if not wanted():
            break
        solve(d)
    out["pressure"] = pressure
    return out, stopped


def _chains(
    z: torch.Tensor,
    side: float,
    work: float,
    up: np.ndarray,
    restart: int,
    own: torch.Tensor | None,
    n_owner: int,
    stop_above: float | None,
) -> dict:
    """The loading states of ``up`` as two chains at once: ``up[:restart]`` on a daemon
    thread, ``up[restart:]`` here from the rigid overlap at ``up[restart]`` (each solve's
    FFTs and conjugate-gradient steps release the GIL). Where the first chain stops above
    ``stop_above`` the second is dropped: the states are those of one chain so far.

    A restarted state is a loading state as well: the contact grows from the rigid overlap
    to the first stable set instead of from the state before, and the two differ only by
    where the grid pins the edge: a fraction of a ring of boundary points, well below the
    check's own accuracy (``benchmarks/bench_adhesive_bound.py --restarts``).

    Each chain stops the other where its work is no longer needed: the first where it
    stops above ``stop_above`` (the second's states are dropped), either where it raises
    (the error is raised here at once, not after the other chain's states)."""
    cancel = threading.Event()  # set by the first chain: the second's states are not needed

    def first_chain() -> tuple[dict, bool]:
        try:
            out = _chain(z, side, work, up[:restart], up[:0], own, n_owner, stop_above)
        except BaseException:
            cancel.set()
            raise
        if out[1]:  # stopped above the load: the second chain is not needed
            cancel.set()
        return out

    # leaving the block by the second chain's error stops the first (``Background``)
    with in_background(first_chain, name="adhesive-path") as first:
        second, _ = _chain(z, side, work, up[restart:], up[:0], own, n_owner, stop_above, cancel)
        states, stopped = first()
    if stopped:
        return states
    return {k: (second[k] if k == "pressure" else states[k] + second[k]) for k in second}


#: Grid points per lattice cell side at most of an adhesive check or validation. The JKR-limit
#: criterion pins each contact edge within a share of K_c that does not shrink with the grid
#: (its thresholds are pixel-scale constants), so the BEM's error against JKR stops falling
#: beyond it and, with strong adhesion, grows, and the check's two-grid estimate no longer
#: holds: a Hertz asperity against the JKR closed form
#: (``benchmarks/bench_adhesive_convergence.py``, benchmarks/results/adhesion.md).
FINEST = 256


def check_adhesive_grid(grid: int, settings: CellSettings) -> int:
    """``check_grid`` for the adhesive BEM: also at most ``FINEST`` points per cell side.
    Returns M; raises MetainterfaceError (argument ``grid``) with the allowed range."""
    from metainterface.validation.heightmap import check_grid

    m = check_grid(grid, settings)
    n = settings.n_side
    if m > FINEST * n:
        raise MetainterfaceError(
            f"grid must be at most {FINEST * n} ({FINEST} points per asperity) for an adhesive "
            f"design, got {m}: the JKR-limit BEM is no more accurate on finer grids and its "
            "error estimate does not hold there",
            argument="grid",
        )
    return m


#: Approaches of the path per load asked for: some states of the path are not on the
#: rising-force branch (just after a snap-in the force dips below its running maximum), so
#: the path takes more samples than the loads it is asked for.
APPROACHES_PER_LOAD = 2
#: A BEM state with an asperity in contact is on the rising-force branch only at or above
#: this factor times the load the model's cell carries just before that asperity touches
#: (``ForwardModel.touch_loads``): the margin covers the BEM's own touch load lying a few
#: per cent from the model's (states within it sit at a snap-in, where alpha jumps).
TOUCH_MARGIN = 1.05
#: Where ``rising_branch`` starts its path's second chain (``jkr_path(restart=...)``), as a
#: share of the approaches: the BEM reaches the top load about four fifths of the way along
#: them (they run a step past where the model reaches it), so each chain solves about half
#: the states, and the path takes about half the time on two cores or beside busy processes.
RESTART_SHARE = 0.4


def approaches(design: Design, model: ForwardModel, top: float, k: int) -> np.ndarray:
    """(K,) rising approaches [length], uniform from one step before the first approach at
    which the model's loading force is positive to one step past the first at which it
    reaches the load ``top`` (at most Delta_max). States before the force turns positive
    are never on the rising-force branch, and an adhesive cell snaps in with a pull that it
    carries over part of its approach: spaced from 0, with strong adhesion most states fell
    there, and the lowest loads, where F_0 is, could go unchecked
    (benchmarks/results/adhesion.md)."""
    s = design.settings
    gamma, h = design.tensors(torch.float64)
    with torch.no_grad():
        sweep = model.sweep(gamma, h, s)
    delta = (sweep.delta[0] if sweep.delta.dim() == 2 else sweep.delta).numpy()
    p = sweep.p_star[0].numpy()
    reach = np.nonzero(p >= top * (1 - 1e-9))[0]
    end = float(delta[reach[0]]) if reach.size else s.delta_max
    positive = np.nonzero(p > 0)[0]
    first = min(float(delta[positive[0]]) if positive.size else 0.0, end)
    step = (end - first) / max(k - 1, 1)
    start = max(0.0, first - step)
    end = min(s.delta_max, end + step)
    return start + (end - start) * np.arange(1, k + 1) / k


def clear_of_snap_ins(p_star: np.ndarray, touching: np.ndarray, peaks: np.ndarray) -> np.ndarray:
    """(K,) bool: the BEM states (P* (K,), asperities in contact (K, N)) clear of the model's
    snap-ins (``peaks`` (N,), the model's ``touch_loads``); with the path's ``on_branch``,
    the states compared.

    A state with asperity i in contact below the load the cell had just before i touched
    was met by approach only: a rising force jumps over it (the sampled running maximum
    misses that peak when no approach falls just before the touch). A state within a factor
    TOUCH_MARGIN of a snap-in reads either side of the jump. Both are left out; a state
    without i in contact well above i's snap-in load is kept: there the BEM touches later
    than the model, a disagreement a check must see.
    """
    p = p_star[:, None]
    snaps = peaks[None, :] > 0
    skipped = touching & (p < TOUCH_MARGIN * peaks[None, :])
    at_jump = ~touching & (p > peaks[None, :] / TOUCH_MARGIN) & (p < TOUCH_MARGIN * peaks[None, :])
    return ~((skipped | at_jump) & snaps).any(1)


def own_snap_ins(p_star: np.ndarray, touching: np.ndarray) -> np.ndarray:
    """(J, 2) the BEM's own snap-in loads as far as its samples tell, [lo, hi] P* for each
    asperity that touches after the first sample, in increasing lo.

    Loaded by approach, asperity i first touches between samples k - 1 and k: a rising
    force jumps at the load the cell carries just before that touch, at least the running
    maximum before k (lo), and at most lo plus the force the untouched cell gains over one
    approach step. That gain is at most the step after the touch (k to k + 1, or the first
    later step with no new asperity touching): the cell's stiffness, dP*/d(approach), only
    grows as contacts grow, and the touched cell has more of them (hi). Where no such step
    was sampled the last rising step is repeated. ``p_star`` (K,) along uniform rising
    approaches, ``touching`` (K, N) bool.
    """
    count = touching.sum(1)
    clean = np.flatnonzero(count[1:] == count[:-1])  # steps j -> j + 1 with no new touch
    out = []
    for i in range(touching.shape[1]):
        first = np.flatnonzero(touching[:, i])
        if not first.size or first[0] == 0:
            continue
        k = int(first[0])
        low = max(0.0, float(p_star[:k].max()))
        after = clean[clean >= k]
        if after.size:
            step = float(p_star[after[0] + 1] - p_star[after[0]])
        else:
            step = float(np.max(np.diff(p_star[:k]), initial=0.0))
        out.append((low, low + max(step, 0.0)))
    return np.array(sorted(out)).reshape(-1, 2)


def at_snap_ins(p_star: np.ndarray, snap_ins: np.ndarray) -> np.ndarray:
    """(K,) bool: the loads ``p_star`` (K,) strictly between the bounds of one of the
    snap-ins ``snap_ins`` (J, 2) (``own_snap_ins``).

    A state there reads either side of a jump depending on where the samples fall: two
    grids, or the same grid with other approaches, put it on different sides, and that one
    state's jump outweighs the grid's error at all the others.
    """
    p = p_star[:, None]
    return ((p > snap_ins[None, :, 0]) & (p < snap_ins[None, :, 1])).any(1)


@dataclass(frozen=True)
class RisingBranch:
    """The adhesive BEM's path of a cell and which of its states a rising force reaches.

    path: the BEM's states by approach (``AdhesivePath``); keep: (K,) bool,
    the states on the rising-force branch clear of snap-ins and at most ``top`` (the load
    asked up to); snap_ins: (J, 2) the BEM's own snap-in loads (``own_snap_ins``);
    approaches: (K,) [length]; device: where it solved; seconds: wall time.
    """

    path: AdhesivePath
    keep: np.ndarray
    snap_ins: np.ndarray
    approaches: np.ndarray
    device: str
    seconds: float


def rising_branch(
    design: Design,
    model: ForwardModel,
    *,
    grid: int,
    samples: int,
    top: float,
    device: str = "auto",
) -> RisingBranch:
    """``design`` in the JKR-limit BEM on ``grid``^2 by ``samples`` approaches up to a step
    past the model's load ``top`` (P*), work of adhesion ``model.adhesion`` [E* R]."""
    from metainterface._device import resolve_device
    from metainterface.validation.heightmap import height_map

    if not model.adhesion:
        raise MetainterfaceError("the adhesive BEM needs a model with adhesion > 0")
    s = design.settings
    deltas = approaches(design, model, top, samples)
    dev = resolve_device(device)
    hm = height_map(design, grid)
    t0 = time.perf_counter()
    work = model.adhesion * s.e_star * s.radius  # w [E* length] in the cell's units
    # no state after the first above ``top`` is kept (a rising force's states are then all
    # above it): on the benchmark cell a quarter of the approaches were past it
    path = jkr_path(
        hm.heights,
        hm.cell_side,
        work,
        deltas,
        device=dev,
        owner=hm.owner,
        stop_above=top * (1 + 1e-9),
        restart=round(RESTART_SHARE * deltas.size) if deltas.size >= 4 else None,
    )
    deltas = path.approach
    seconds = time.perf_counter() - t0
    assert path.touching is not None  # owner given
    snaps = own_snap_ins(path.p_star, path.touching)
    keep = compared_states(
        path.p_star, path.on_branch, path.touching, model.touch_loads(design), snaps, top
    )
    return RisingBranch(path, keep, snaps, deltas, str(dev), seconds)


def compared_states(
    p_star: np.ndarray,
    on_branch: np.ndarray,
    touching: np.ndarray,
    peaks: np.ndarray,
    snap_ins: np.ndarray,
    top: float,
) -> np.ndarray:
    """(K,) bool: the states of a path (P* (K,), asperities in contact (K, N)) an adhesive
    check compares: on the rising-force branch (``on_branch`` (K,)), clear of the model's
    snap-ins (``peaks`` (N,), ``clear_of_snap_ins``) and of the path's own (``snap_ins``
    (J, 2), ``at_snap_ins``), at most the load ``top`` asked up to."""
    return (
        on_branch
        & clear_of_snap_ins(p_star, touching, peaks)
        & ~at_snap_ins(p_star, snap_ins)
        & (p_star <= top * (1 + 1e-9))
    )
