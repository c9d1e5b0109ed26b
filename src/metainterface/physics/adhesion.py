"""Adhesive asperities: JKR contact of power-law punches, and the adhesive cell (issue 38).

One asperity is a JKR contact (``physics.jkr``: delta(a), F(a), the radii a0, a_d, a_F and
the stable-branch root; w the work of adhesion in units of E* R, lengths in units of R).

The cell (rigid flat at approach Delta, asperity i compressed by x_i = Delta - h_i, or by
Delta - h_i - sum_j K_ij F_j with the lattice's interaction, ``physics.interaction``).
On each asperity's stable branch (a >= a_d) the contact radius is the largest root of
delta(a) = x_i, found by Newton's method (delta(a) is convex there) and differentiated
implicitly. Under a rising normal force (load control, the curve a user sees):

* an asperity snaps in when it touches (x_i = 0, a jumps from 0 to a0), pulling the flat;
* the flat follows the running maximum of the cell's force F(Delta): where F falls below
  it (just after a snap-in) no equilibrium is near and the cell jumps forward to where F
  regains it; alpha jumps there, at constant P*.

Unloading from Delta_max (a falling force): every asperity that touched stays attached down
to x_i = delta(a_d) (displacement-controlled detachment of that asperity), the flat follows
the running minimum of F, and the cell comes off at the least force on that branch: the
pull-off force, reported as a positive P*_off = -min F / (A_nom E*).

All functions are pure and batched: leading batch axis B, N asperities, K Delta samples;
no loops over samples or asperities (only over Newton steps).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import torch
from torch import Tensor

from metainterface.physics.cell import CellSettings
from metainterface.physics.curves import Sweep, anchor, delta_grid
from metainterface.physics.jkr import (
    detach_radius,
    flat_punch_coefficient,
    jkr_force,
    jkr_indentation,
    jkr_radius,
)
from metainterface.physics.sneddon import log_kc

#: Jacobi sweeps of the interaction (outer iterations, each a full set of JKR solves).
ITERATIONS = 4
#: Golden-section steps that refine the cell's least force between two sweep samples.
_GOLDEN_STEPS = 48
# --- the cell ---------------------------------------------------------------------------------


def per_design(w: Tensor, gamma: Tensor) -> Tensor:
    """A work of adhesion given as a tensor, as one value per design (B,) of gamma (B, N)."""
    w = w.to(dtype=gamma.dtype, device=gamma.device).reshape(-1)
    return w.expand(gamma.shape[0]) if w.numel() == 1 else w


@dataclass(frozen=True)
class AdhesiveState:
    """Each asperity of (B, N) designs at the approaches Delta (B or 1, K), layout (B, N, K).

    radius: contact radius a [length] (0 out of contact); force: F / E* [length^2];
    force_slope: dF_i/dDelta / E* [length], area_slope: d(pi a_i^2)/dDelta [length] (both
    with the interaction's tangent where there is one; detached).
    """

    radius: Tensor
    force: Tensor
    force_slope: Tensor
    area_slope: Tensor


def adhesive_state(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    w: float | Tensor,
    delta: Tensor,
    *,
    unloading: bool = False,
    kernel: Tensor | None = None,
    iterations: int = ITERATIONS,
) -> AdhesiveState:
    """The JKR state of every asperity at the approaches ``delta`` (K,) or (B, K) [length].

    gamma, h: (B, N), h anchored here (min h -> 0). w: work of adhesion [E* R], one for all
    designs or one per design (B,).
    Loading (default): asperity i is in contact where its compression x_i >= 0 (snap-in at
    touch). ``unloading``: from Delta_max down; every asperity that touched by Delta_max
    (h_i <= Delta_max) stays attached while x_i >= delta(a_d). kernel: the (N, N)
    interaction matrix K [1/length] (``interaction(settings).shift``), None for independent
    asperities; x_i = Delta - h_i - sum_j K_ij F_j / E*, by ``iterations`` Jacobi sweeps with
    each asperity's own term K_ii taken implicitly.
    """
    radius = settings.radius
    g = gamma[:, :, None]
    hh = anchor(h)[:, :, None]
    d = delta[None, None, :] if delta.dim() == 1 else delta[:, None, :]
    gap0 = d - hh  # (B, N, K)
    w_t = per_design(w, gamma)[:, None, None] if isinstance(w, Tensor) else w
    w_t = torch.as_tensor(w_t, dtype=gamma.dtype, device=gamma.device)
    # log kc once, with gamma's graph (its lgamma was most of a solve's cost, six times over)
    lkc = log_kc(g, radius)
    kc = torch.exp(lkc)
    if unloading:
        x_d = jkr_indentation(g, detach_radius(g, w_t, radius), w_t, radius)  # (B, N, 1), <= 0
        reached = hh <= settings.delta_max * (1 + 1e-12)

    def in_contact(x: Tensor) -> Tensor:
        if unloading:
            return reached & (x >= x_d)
        return x >= 0

    self_k = None
    off = None
    if kernel is not None:
        k_diag = torch.diagonal(kernel)
        self_k = k_diag[None, :, None]
        off = kernel - torch.diag_embed(k_diag)
    # The first pass solves the independent asperities; then Jacobi sweeps on
    # x_i = gap0_i - sum_{j != i} K_ij F_j (previous sweep), K_ii F_i implicit. Started from
    # the independent state, identical asperities (no relative shift) stay at it exactly.
    x = gap0
    force = torch.zeros_like(gap0)
    raw: Tensor | None = None
    sweeps = 1 + (iterations if kernel is not None else 0)
    for sweep_no in range(sweeps):
        coupled = off is not None and sweep_no > 0
        if coupled:
            x = gap0 - torch.einsum("ij,bjk->bik", off, force)
        on = in_contact(x)
        # loading: out of contact is x < 0, where no radius is needed; solving at x = 0
        # instead spares the slow Newton steps near a cusp that nothing reads
        xs = x if unloading else torch.clamp_min(x, 0.0)
        # each sweep's radii start Newton for the next: x moves little between sweeps
        raw = jkr_radius(
            g,
            xs,
            w_t,
            radius,
            self_coupling=self_k if coupled else None,
            start=raw,
            log_coefficient=lkc,
        )
        # masked with where, not a product: 0^gamma has no gradient in gamma
        force = torch.where(on, jkr_force(g, raw, w_t, radius, coefficient=kc), 0.0)
        a = torch.where(on, raw, 0.0)
    # slopes along Delta, per asperity: dx/da and dF/da on the branch
    with torch.no_grad():
        kc = kc.detach()
        s = flat_punch_coefficient(w_t, radius)
        safe = torch.where(on, a, torch.ones_like(a))
        pa = kc * safe**g
        dx_da = g * pa / safe - 0.5 * s / torch.sqrt(safe)
        df_da = 2.0 * g * pa - 3.0 * s * torch.sqrt(safe)
        if self_k is not None:
            dx_da = dx_da + self_k * df_da
        good = on & (dx_da > 0)
        inv = torch.where(good, 1.0 / torch.where(good, dx_da, 1.0), 0.0)
        f_t, a_t = df_da * inv, 2.0 * math.pi * safe * inv
        if off is not None:  # tangent t_i = dx_i/dDelta = 1 - sum_j K_ij dF_j/dDelta (Jacobi)
            t = torch.ones_like(f_t)
            for _ in range(iterations):
                t = 1.0 - torch.einsum("ij,bjk->bik", off, f_t * t)
            f_t, a_t = f_t * t, a_t * t
        f_t, a_t = f_t * on, a_t * on
    return AdhesiveState(radius=a, force=force, force_slope=f_t, area_slope=a_t)


def sweep_adhesive(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    w: float | Tensor,
    *,
    n_delta: int | None = None,
    delta: Tensor | None = None,
    kernel: Tensor | None = None,
    iterations: int = ITERATIONS,
) -> tuple[Sweep, Tensor]:
    """The loading curve of (B, N) adhesive designs under a rising normal force.

    w: work of adhesion [E* R], one for all designs or one per design (B,).
    delta: (K,) or (B, K) approaches [length] on [0, Delta_max] (default ``n_delta`` uniform
    ones). Returns the Sweep (delta; P* (B, K) the running maximum of the cell's force,
    floored at 0; alpha (B, K) the state the cell is in at that force: where the force is
    below its running maximum, the state it jumps to; S* = dP*/dalpha there, 0 where P* is
    flat; load_slope dP*/dDelta, 0 where flat, detached) and each asperity's contact area /
    A_nom, (B, K, N). Differentiable in gamma and h (and through P*'s running maximum).
    """
    if delta is None:
        delta = delta_grid(settings, n_delta, dtype=gamma.dtype, device=gamma.device)
    st = adhesive_state(gamma, h, settings, w, delta, kernel=kernel, iterations=iterations)
    a_nom = settings.nominal_area
    force, top, on_branch, f_slope, load_slope = _rising(st, a_nom)
    k = force.shape[-1]
    index = torch.arange(k, device=force.device).expand_as(force)
    # the state the cell jumps to: the first sample at or after k back on the branch
    marks = torch.where(on_branch, index, torch.full_like(index, k - 1))
    jump = torch.flip(torch.cummin(torch.flip(marks, [-1]), dim=-1).values, [-1])
    # ... between that sample and the one before it, where the force crosses the running
    # maximum: the state is interpolated linearly in the force there (exact at the samples
    # on the branch, second order in the step inside a jump)
    before = (jump - 1).clamp_min(0)
    f_j, f_b = force.gather(-1, jump), force.gather(-1, before)
    span = f_j - f_b
    weight = torch.where(
        span > 0, ((top - f_b) / torch.where(span > 0, span, 1.0)).clamp(0, 1), 1.0
    )
    per = (math.pi / a_nom) * st.radius**2  # (B, N, K)
    idx_j = jump[:, None, :].expand_as(per)
    idx_b = before[:, None, :].expand_as(per)
    per_b = per.gather(-1, idx_b)
    per_j = (per_b + weight[:, None, :] * (per.gather(-1, idx_j) - per_b)).permute(0, 2, 1)
    alpha = per_j.sum(-1)
    a_slope = st.area_slope.sum(1) / a_nom
    slope_j = f_slope.gather(-1, jump)
    area_j = a_slope.gather(-1, jump)
    flat = ~on_branch
    stiffness = torch.where(
        (area_j > 0) & ~flat, slope_j / torch.where(area_j > 0, area_j, 1.0), 0.0
    )
    return Sweep(
        delta=delta, p_star=top, alpha=alpha, stiffness=stiffness, load_slope=load_slope
    ), per_j


def _rising(st: AdhesiveState, a_nom: float) -> tuple[Tensor, Tensor, Tensor, Tensor, Tensor]:
    """The cell's force (B, K) [P*] from its asperities' state, its running maximum (floored
    at 0: P* of the rising force), whether each sample is on it, the force's slope along
    Delta, and that slope where P* rises (0 where flat; detached)."""
    force = st.force.sum(1) / a_nom  # (B, K)
    top = torch.cummax(torch.clamp_min(force, 0.0), dim=-1).values
    on_branch = force >= top
    f_slope = st.force_slope.sum(1) / a_nom
    return force, top, on_branch, f_slope, torch.where(on_branch, f_slope, 0.0).detach()


def adhesive_load(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    w: float | Tensor,
    *,
    delta: Tensor,
    kernel: Tensor | None = None,
    iterations: int = ITERATIONS,
) -> Sweep:
    """P* and its slope along Delta of :func:`sweep_adhesive` at the approaches ``delta``
    (K,) or (B, K), the same values, without the rest (alpha and S* are zeros, not to be
    used): the Newton steps of ``pressures.solve_delta`` read these alone."""
    st = adhesive_state(gamma, h, settings, w, delta, kernel=kernel, iterations=iterations)
    _, top, _, _, load_slope = _rising(st, settings.nominal_area)
    zeros = torch.zeros_like(top)
    return Sweep(delta=delta, p_star=top, alpha=zeros, stiffness=zeros, load_slope=load_slope)


def touch_grid(h: Tensor, settings: CellSettings, n_delta: int) -> Tensor:
    """(B, n_delta + N) ascending approaches [length]: ``n_delta`` uniform ones on
    [0, Delta_max] and one just short of each asperity's touch (its anchored height, at most
    Delta_max), for (B, N) heights h.

    On such a grid the load where an asperity snaps in (the running maximum just before its
    touch) is the cell's force at the touch itself, differentiable in the height; on a
    uniform grid it is the last sample's, which a height moves only in steps.
    """
    uniform = delta_grid(settings, n_delta, dtype=h.dtype, device=h.device)
    touch = (anchor(h) * (1.0 - 1e-9)).clamp_max(settings.delta_max)
    return torch.sort(torch.cat([uniform.expand(h.shape[0], -1), touch], -1), dim=-1).values


def touch_loads(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    w: float,
    *,
    kernel: Tensor | None = None,
    iterations: int = ITERATIONS,
) -> Tensor:
    """(B, N) the largest P* the cell carries, loaded by approach, before each asperity
    touches.

    Under a rising force an asperity snaps in at its touch and the cell jumps on to where the
    force regains the load it had just before (its running maximum): every state of the
    load-controlled curve with asperity i in contact carries at least the i-th of these
    loads (0 for the first to touch). A state met by approach with i in contact below it
    lies on a branch a rising force jumps over. Between touches the force rises, so its
    running maximum up to a touch is the largest of the loads just before each earlier
    touch. Touch at Delta = h_i (the interaction's shift of it is left out).
    """
    hh = anchor(h)
    delta = hh * (1.0 - 1e-9)  # (B, N) approaches just short of each touch
    st = adhesive_state(gamma, h, settings, w, delta, kernel=kernel, iterations=iterations)
    before = torch.clamp_min(st.force.sum(1) / settings.nominal_area, 0.0)  # (B, N)
    order = torch.argsort(hh, dim=-1)
    peak = torch.cummax(before.gather(-1, order), dim=-1).values
    return torch.empty_like(peak).scatter_(-1, order, peak)


def _unloading_grid(
    gamma: Tensor, h: Tensor, settings: CellSettings, w: float, n_delta: int
) -> Tensor:
    """(B, K) approaches from Delta_max down to just below the last detachment."""
    g = gamma
    w_t = torch.as_tensor(w, dtype=gamma.dtype, device=gamma.device)
    x_d = jkr_indentation(g, detach_radius(g, w_t, settings.radius), w_t, settings.radius)
    hh = anchor(h)
    reached = hh <= settings.delta_max * (1 + 1e-12)
    low = torch.where(reached, hh + x_d, torch.full_like(hh, math.inf)).amin(-1)
    low = low - 1e-3 * (settings.delta_max - low)
    s = torch.linspace(0.0, 1.0, n_delta, dtype=gamma.dtype, device=gamma.device)
    return settings.delta_max + (low[:, None] - settings.delta_max) * s[None]


def unloading_adhesive(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    w: float,
    *,
    n_delta: int = 1025,
    delta: Tensor | None = None,
    kernel: Tensor | None = None,
    iterations: int = ITERATIONS,
) -> Sweep:
    """The unloading curve from Delta_max under a falling normal force.

    delta: (B, K) descending approaches [length] (default: ``n_delta`` from Delta_max to
    below the last detachment). P* (B, K): the running minimum of the cell's force (the
    flat follows it down; it may be negative, a pull); alpha (B, K) the contact fraction of
    that state (of the sample itself: where the force is above its running minimum the
    cell has jumped, see ``pull_off``). S* is left NaN.
    """
    with torch.no_grad():
        if delta is None:
            delta = _unloading_grid(gamma, h, settings, w, n_delta)
    st = adhesive_state(
        gamma, h, settings, w, delta, unloading=True, kernel=kernel, iterations=iterations
    )
    a_nom = settings.nominal_area
    force = st.force.sum(1) / a_nom
    low = torch.cummin(force, dim=-1).values
    alpha = (math.pi / a_nom) * (st.radius**2).sum(1)
    return Sweep(
        delta=delta,
        p_star=low,
        alpha=alpha,
        stiffness=torch.full_like(low, math.nan),
        load_slope=(st.force_slope.sum(1) / a_nom).detach(),
    )


def pull_off(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    w: float,
    *,
    n_delta: int = 1025,
    kernel: Tensor | None = None,
    iterations: int = ITERATIONS,
) -> Tensor:
    """The cell's pull-off pressure P*_off = -min F / (A_nom E*) >= 0 (B,), after loading
    to Delta_max: the largest pull the unloading branch holds under load control.

    The least force is searched on an ``n_delta`` sweep, refined by golden section between
    the samples beside it, and compared with the force just before each asperity's own
    detachment (x_i = delta(a_d), where it is least on that asperity's part of the
    branch). Differentiable in gamma and h at the minimising approach (the envelope
    gradient where the minimum is a stationary point).
    """

    def force_at(dl: Tensor) -> Tensor:
        st = adhesive_state(
            gamma, h, settings, w, dl, unloading=True, kernel=kernel, iterations=iterations
        )
        return st.force.sum(1) / settings.nominal_area

    with torch.no_grad():
        grid = _unloading_grid(gamma, h, settings, w, n_delta)  # (B, K) descending
        f = force_at(grid)
        k = int(f.shape[-1])
        i = f.argmin(-1, keepdim=True)
        hi = grid.gather(-1, (i - 1).clamp_min(0))
        lo = grid.gather(-1, (i + 1).clamp_max(k - 1))
        best_d, best_f = grid.gather(-1, i), f.gather(-1, i)
        ratio = (math.sqrt(5.0) - 1.0) / 2.0
        x1 = hi - ratio * (hi - lo)
        x2 = lo + ratio * (hi - lo)
        f1, f2 = force_at(x1), force_at(x2)
        for _ in range(_GOLDEN_STEPS):
            left = f1 < f2  # x1 < x2: the minimum lies in [lo, x2], else in [x1, hi]
            hi = torch.where(left, x2, hi)
            lo = torch.where(left, lo, x1)
            new_x = torch.where(left, hi - ratio * (hi - lo), lo + ratio * (hi - lo))
            new_f = force_at(new_x)
            x1, f1, x2, f2 = (
                torch.where(left, new_x, x2),
                torch.where(left, new_f, f2),
                torch.where(left, x1, new_x),
                torch.where(left, f1, new_f),
            )
            for xc, fc in ((x1, f1), (x2, f2)):
                better = fc < best_f
                best_d = torch.where(better, xc, best_d)
                best_f = torch.where(better, fc, best_f)
        # just before each reached asperity detaches: Delta = h_i + delta(a_d,i)
        w_t = torch.as_tensor(w, dtype=gamma.dtype, device=gamma.device)
        x_d = jkr_indentation(
            gamma, detach_radius(gamma, w_t, settings.radius), w_t, settings.radius
        )
        nudge = 1e-12 * settings.delta_max  # on the attached side of the cusp
        cusp = (anchor(h) + x_d + nudge).clamp_max(settings.delta_max)  # (B, N)
        fc = force_at(cusp)
        if kernel is None:  # exactly at the cusp the asperity is attached: the left limit
            cand = torch.cat([best_d, cusp], dim=-1)
            cand_f = torch.cat([best_f, fc], dim=-1)
        else:  # with the interaction the cusp moves: the searched minimum only
            cand, cand_f = best_d, best_f
        where = cand.gather(-1, cand_f.argmin(-1, keepdim=True))
    return -force_at(where)[:, 0]


@dataclass(frozen=True)
class PathLoad:
    """An adhesive model's load for ``pressures.solve_delta``: the sweep at the Deltas
    asked (``load(delta=...)``), and ``knots(n_delta)``, the Deltas of its first brackets:
    uniform ones and one just short of each asperity's touch (:func:`touch_grid`).

    The force drops where an asperity touches and snaps in; under a rising force the cell
    passes that drop at the touch's force. The running maximum along a few Deltas misses a
    touch that falls between two of them, and a Newton step could land past it, on the
    force's recovery, in a state the rising force jumps over; with a knot at every touch no
    bracket holds one, and the force rises across each.
    """

    load: Callable[..., Sweep]
    h: Tensor
    settings: CellSettings

    def __call__(self, *, delta: Tensor) -> Sweep:
        return self.load(delta=delta)

    def knots(self, n_delta: int | None) -> Tensor:
        """(B, K + N) ascending Deltas [length]: ``n_delta`` uniform (default
        settings.n_steps) and the touches."""
        k = n_delta if n_delta is not None else self.settings.n_steps
        return touch_grid(self.h, self.settings, k)
