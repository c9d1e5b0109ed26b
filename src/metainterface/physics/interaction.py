"""Elastic interaction between the asperities of a periodic cell (beyond the paper, issue 9).

The paper's model (``curves.sweep``) compresses asperity i by <Delta - h_i>_+ as if it stood
alone (its section 5 names the interaction as future work). In the tiled cell the loads of
all asperities also deform the surface around tip i through the periodic Boussinesq field
of the lattice: a blunt asperity about to engage next to loaded ones touches later, and
its area, which grows like delta^(2/gamma) with an infinite slope at contact, is very
sensitive to that. Here the neighbours' field around tip i, to second order in the
distance r from the tip and averaged over the angle, is

    u_i(r) = w_i + b_i r^2,   w_i = sum_j K_ij F_j / E*,   b_i = sum_j C_ij F_j / E*,

and asperity i is a Sneddon contact (sneddon.py) of the profile c_i r^gamma_i + b_i r^2
under the compression Delta - h_i - w_i. By linearity of Sneddon's integrals in the
profile, with d = kappa c a^gamma the power-law part,

    Delta - h_i - w_i = d_i + 2 b_i a_i^2,   F_i / E* = 2 gamma/(gamma + 1) d_i a_i + 8/3 b_i a_i^3,

solved self-consistently at every Delta; alpha = pi sum a_i^2 / A_nom, P* = sum F_i / (A_nom E*).
By default b = 0 (the tip shift only; see "Which terms" below).

The kernels (per geometry, computed once, float64). The periodic displacement of a half-space
under a unit point load on each site of the lattice L Z^2 is (1 / (pi E* L)) g(x / L), g the
sum of 1/r over the images, made finite by removing its cell mean (the k = 0 mode: the
infinite uniform sink of a uniform load on a half-space, a shift absorbed by Delta); Ewald
sum in ``periodic_kernel``. At a load point its own 1/r is its Sneddon field and is left
out: g there is the regularised limit, -3.9002649 on the square lattice (the 2D Madelung
constant). K_ij = g(x_i - x_j) / (pi L), self-images on the diagonal. C is the angular mean
of the field's Hessian, Laplacian / 4, with Laplacian(1/r) = 1/r^3 in the plane:
C_ij = c(x_i - x_j) / (4 pi L^3), c = sum of |x + m|^-3 (``periodic_curvature``; 9.0336
at the own images). C needs no mean removal: a uniform load does not curve the surface.

The mean of w. A uniform shift of all tips is a change of Delta. The field of the mean load
F_bar = P* A_nom E* / N on every site is such a shift; only the deviations F_j - F_bar move
asperities relative to each other, so K's row mean is removed: K has zero row and column
sums, sum_i w_i = 0, and Delta is the approach measured from the mean interaction
displacement of the sites. alpha(P*) does not depend on this choice. It makes w vanish for
identical asperities (by symmetry) and for N = 1 (K = 0), so Delta keeps the meaning it has
in the paper's model, and the first asperity still touches at Delta = 0.

What is left out, and why. Loads sit at least a pitch p = 4 a_max apart, a <= a_max, so
spreading load j over its contact disc changes its field at tip i by a relative
<r'^2>/(4 p^2) < 1 % (a correction to a correction), and the anisotropic second-order part
of the field changes the area only at second order; terms of order (a/p)^4 are dropped.

Which terms (``curvature``). The tip shift w is the interaction that matters: it moves
engagements, where the paper's model errs most. The curvature term b is the next one: it
lowers alpha at given P* for blunt asperities near Delta_max and regularises a blunt
asperity's contact near engagement (locally a sphere of radius 1/(2 b)). It is physically
right and shows in BEM checks of blunt cells, but it makes cells of Hertzian asperities
slightly worse, it costs more, and without it identical asperities give exactly the paper's
model. So the default is the tip shift only (``CURVATURE``); ``curvature=True`` adds b, for
blunt-dominated designs, finer checks or the manufactured part itself. The models reach
different P* at Delta_max, so compare them at equal P* (``ForwardModel.alpha_at_loads``).
The measured errors of both variants against Tamaas are in benchmarks/results/interaction.md.

The solve. A fixed number of Newton sweeps in d (``ITERATIONS``), each taking the self-image
term and the asperity's own curvature term implicitly (diagonal Newton) and the neighbours
explicitly; the coupling left is |K_ij| dF_j/ddelta_j <= ~0.04 per pair, so two sweeps leave
alpha well below the BEM's own error from the converged solution
(benchmarks/bench_interaction.py), at a cost that stays a small multiple of the paper's
model. The sweeps are unrolled, so autograd differentiates through them. S* = dP*/dalpha
uses the tangent d/dDelta of the equations above at the final state (with the engagement
factor of the last sweep), by the same Jacobi scheme. Inside, tensors are laid out (N, B, K)
(N asperities, B designs, K Delta samples): elementwise passes run along K, the kernels are
one matrix product per sweep and the sums over asperities add contiguous slabs.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import torch
from torch import Tensor

from metainterface.physics.cell import CellSettings
from metainterface.physics.curves import Sweep, _contact_floor, anchor, delta_grid
from metainterface.physics.sneddon import engagement, indentation, log_kc

#: Newton sweeps of the forward solve (and Jacobi sweeps of its tangent).
ITERATIONS = 2
#: Whether the neighbours' curvature term is in the model by default: no (see the docstring,
#: "Which terms"): it helps blunt cells, costs more, and makes identical asperities differ
#: from the paper's model.
CURVATURE = False


def erfc(x: np.ndarray) -> np.ndarray:
    """The complementary error function of an array, by torch, which is loaded already
    (scipy.special costs a few tenths of a second to import, for this one function)."""
    return torch.special.erfc(torch.as_tensor(x, dtype=torch.float64)).numpy()


# Ewald splitting on the unit cell: beta = sqrt(pi) balances the two sums; 6 shells of
# images and of wave vectors on each side reach float64 round-off at any point.
_BETA = math.sqrt(math.pi)
_SHELLS = 6


def _ewald_terms(
    x: np.ndarray, y: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Image distances (1 at the load point), load-point mask, wave numbers, cosines."""
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    m = np.arange(-_SHELLS, _SHELLS + 1, dtype=np.float64)
    mx, my = (v.ravel() for v in np.meshgrid(m, m, indexing="ij"))
    xf, yf = x - np.round(x), y - np.round(y)  # centre the image sum on the point
    r = np.hypot(xf[..., None] + mx, yf[..., None] + my)
    at_load = r < 1e-12
    safe = np.where(at_load, 1.0, r)
    k = 2.0 * math.pi * np.hypot(mx, my)
    nz = k > 0
    cos = np.cos(2.0 * math.pi * (xf[..., None] * mx[nz] + yf[..., None] * my[nz]))
    return safe, at_load, k[nz], cos


def periodic_kernel(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """g(x, y): sum over the unit lattice's images of 1/r, minus its cell mean.

    x, y: arrays of one shape, in units of the cell side L (periodic). A unit point load on
    every site displaces the half-space by g(x / L, y / L) / (pi E* L). At the sites the load's
    own 1/r is removed (regularised value, -3.9002649 at 0). Ewald sum, float64.
    """
    r, at_load, k, cos = _ewald_terms(x, y)
    beta = _BETA
    real = np.where(at_load, -2.0 * beta / math.sqrt(math.pi), erfc(beta * r) / r).sum(-1)
    recip = ((2.0 * math.pi / k) * erfc(k / (2.0 * beta)) * cos).sum(-1)
    return real + recip - 2.0 * math.sqrt(math.pi) / beta  # real part's cell mean removed


def periodic_curvature(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """c(x, y) = Laplacian of g: sum over the images of 1/r^3 (own 1/r^3 removed at sites).

    Same conventions as ``periodic_kernel`` (9.0336217 at 0); positive everywhere.
    """
    r, at_load, k, cos = _ewald_terms(x, y)
    beta, rp = _BETA, math.sqrt(math.pi)
    gauss = np.exp(-((beta * r) ** 2))
    # Laplacian of erfc(beta r)/r in the plane; its regular part at r = 0 is 8 beta^3 / 3 sqrt(pi)
    lap = erfc(beta * r) / r**3 + (2.0 * beta / rp) * gauss / r**2 + (4.0 * beta**3 / rp) * gauss
    real = np.where(at_load, 8.0 * beta**3 / (3.0 * rp), lap).sum(-1)
    recip = (-2.0 * math.pi * k * erfc(k / (2.0 * beta)) * cos).sum(-1)
    return real + recip


@functools.lru_cache(maxsize=16)
def _lattice_values(n_side: int) -> tuple[np.ndarray, np.ndarray]:
    """(N, N) g and c at the site offsets of the n x n lattice (site k at (k % n, k // n) / n)."""
    k = np.arange(n_side * n_side)
    x, y = (k % n_side) / n_side, (k // n_side) / n_side
    dx, dy = x[:, None] - x[None, :], y[:, None] - y[None, :]
    out = []
    for f in (periodic_kernel, periodic_curvature):
        v = f(dx, dy)
        v = 0.5 * (v + v.T)  # symmetric to round-off already; make it exact
        v.setflags(write=False)
        out.append(v)
    return out[0], out[1]


@dataclass(frozen=True, eq=False)
class Interaction:
    """The two (N, N) interaction matrices of a lattice, symmetric and circulant.

    shift: K [1/length], w_i = sum_j K_ij F_j / E*, zero row and column sums.
    curvature: C [1/length^3], b_i = sum_j C_ij F_j / E*, positive; None to leave the
    neighbours' curvature out (tip shift only).
    """

    shift: Tensor
    curvature: Tensor | None

    def stacked(self, dtype: torch.dtype, device: torch.device) -> tuple[Tensor, Tensor, Tensor]:
        """[K; C] and [K - diag K; C] ((2N or N), N) and diag K (N, 1, 1), cached per dtype."""
        key = (dtype, torch.device(device))
        cache = self.__dict__.setdefault("_stacked", {})
        if key not in cache:
            with torch.inference_mode(False):  # plain tensors: usable under autograd later
                k = self.shift.to(dtype=dtype, device=device)
                diag = torch.diagonal(k)
                blocks, off = [k], [k - torch.diag_embed(diag)]
                if self.curvature is not None:
                    c = self.curvature.to(dtype=dtype, device=device)
                    blocks.append(c)
                    off.append(c)
                cache[key] = (torch.cat(blocks), torch.cat(off), diag[:, None, None].clone())
        return cache[key]

    def scaled(self, factor: float) -> Interaction:
        """Both matrices times ``factor`` (0 gives the independent model)."""
        c = None if self.curvature is None else self.curvature * factor
        return Interaction(self.shift * factor, c)

    def without_curvature(self) -> Interaction:
        """The tip shift only."""
        return Interaction(self.shift, None)


def interaction(
    settings: CellSettings,
    *,
    pitch: float | None = None,
    dtype: torch.dtype = torch.float64,
    device: torch.device | str | None = None,
    curvature: bool = True,
) -> Interaction:
    """The lattice's interaction matrices (see the module docstring); cached, read-only.

    pitch: site spacing p [length], default L / n = 4 a_max; K scales as 1/p, C as 1/p^3.
    curvature: False leaves C out (tip shift only).
    """
    pitch = settings.cell_side / settings.n_side if pitch is None else float(pitch)
    dev = torch.device(device or "cpu")
    return _interaction(settings.n_side, pitch, dtype, dev, bool(curvature))


@functools.lru_cache(maxsize=64)
def _interaction(
    n: int, pitch: float, dtype: torch.dtype, device: torch.device, curvature: bool
) -> Interaction:
    side = n * pitch
    g, c = _lattice_values(n)
    k = (g - g.mean(axis=1, keepdims=True)) / (math.pi * side)
    c = c / (4.0 * math.pi * side**3)
    with torch.inference_mode(False):  # plain tensors, also when first called in inference
        as_t = functools.partial(torch.as_tensor, dtype=dtype, device=device)
        return Interaction(shift=as_t(k), curvature=as_t(c) if curvature else None)


def sweep_interacting(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    *,
    smooth: float | None = None,
    n_delta: int | None = None,
    delta: Tensor | None = None,
    kernel: Interaction | None = None,
    iterations: int = ITERATIONS,
    curvature: bool = CURVATURE,
) -> Sweep:
    """The cell response along Delta with elastic interaction; the contract of ``sweep``.

    gamma, h: (B, N) [h in units of R], anchored (min h -> 0). smooth: softplus steepness
    [1/R], None for the exact bracket. n_delta / delta: the (K,) or (B, K) sweep, as in
    ``sweep``.
    curvature: add the neighbours' curvature term b (default ``CURVATURE``: off, the tip
    shift only; see the module docstring). kernel: explicit matrices instead
    (``interaction(...)``, whose curvature may be None; ``.scaled(0)`` gives ``sweep``
    exactly); overrides ``curvature``.
    iterations: Newton sweeps, each one power-law evaluation of the (N, B, K) state.
    Returns delta and P*, alpha, S* = dP*/dalpha, (B, K), differentiable throughout, and
    dP*/dDelta (B, K, detached).
    """
    return _solve(gamma, h, settings, smooth, n_delta, delta, kernel, iterations, curvature)[0]


def load_area_interacting(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    *,
    smooth: float | None = None,
    n_delta: int | None = None,
    delta: Tensor | None = None,
    kernel: Interaction | None = None,
    iterations: int = ITERATIONS,
    curvature: bool = CURVATURE,
) -> tuple[Tensor, Tensor, Tensor]:
    """delta (K,), P* and alpha (B, K) of ``sweep_interacting`` without S* (cheaper)."""
    sw, _ = _solve(
        gamma, h, settings, smooth, n_delta, delta, kernel, iterations, curvature, tangent=False
    )
    return sw.delta, sw.p_star, sw.alpha


def asperity_sweep_interacting(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    *,
    smooth: float | None = None,
    n_delta: int | None = None,
    delta: Tensor | None = None,
    kernel: Interaction | None = None,
    iterations: int = ITERATIONS,
    curvature: bool = CURVATURE,
) -> tuple[Sweep, Tensor]:
    """``sweep_interacting`` and each asperity's contact area / A_nom, (B, K, N)."""
    sw, per = _solve(
        gamma, h, settings, smooth, n_delta, delta, kernel, iterations, curvature, per_asperity=True
    )
    assert per is not None
    return sw, per


def _solve(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    smooth: float | None,
    n_delta: int | None,
    delta: Tensor | None,
    kernel: Interaction | None,
    iterations: int,
    curvature: bool,
    *,
    per_asperity: bool = False,
    tangent: bool = True,
) -> tuple[Sweep, Tensor | None]:
    dtype, dev = gamma.dtype, gamma.device
    if delta is None:
        delta = delta_grid(settings, n_delta, dtype=dtype, device=dev)
    if kernel is None:
        kernel = interaction(settings, dtype=dtype, device=dev, curvature=curvature)
    both, off_and_c, k_diag = kernel.stacked(dtype, dev)
    curv = kernel.curvature is not None
    k2 = 2.0 * k_diag
    n = gamma.shape[-1]
    floor = _contact_floor(dtype)
    exact = smooth is None
    # Layout (N, B, K): elementwise passes run along K, the kernels are one matrix product
    # over the leading axis and the sums over asperities add contiguous slabs.
    gam = gamma.T[:, :, None]  # (N, B, 1)
    inv_g = 1.0 / gam
    lkc = log_kc(gam, settings.radius)
    f_coef = 2.0 * gam / (gam + 1.0)
    g4 = 4.0 * inv_g
    one = torch.ones((), dtype=dtype, device=dev)

    def apply(mat: Tensor, x: Tensor) -> list[Tensor]:
        """(M N, N) matrix on the asperity axis of x (N, B, K): its M (N, B, K) blocks."""
        out = mat @ x.reshape(n, -1)
        return list(out.view(out.shape[0], *x.shape[1:]).split(n))

    lkc_g = lkc * inv_g

    def contact(
        d: Tensor, b: Tensor | None, squares: bool = True
    ) -> tuple[Tensor, Tensor | None, Tensor, Tensor]:
        """Radius a (0 at d = 0), a^2 (None if not ``squares`` and b is None), max(d, floor)
        and F / E* of compressions d >= 0."""
        safe = torch.clamp_min(d, floor)
        # a = (d / kappa c)^(1/gamma); exp-log rather than pow: as fast forward, and its
        # backward needs no second power evaluation
        a = torch.exp(torch.addcmul(-lkc_g, torch.log(safe), inv_g)) * torch.sign(d)
        if b is None:
            return a, (a * a if squares else None), safe, (f_coef * d) * a
        a2 = a * a
        return a, a2, safe, torch.addcmul(f_coef * d, b, a2, value=8.0 / 3.0) * a

    def target(gap: Tensor) -> tuple[Tensor, Tensor]:
        """<gap>_+ (or softplus) and its derivative."""
        tgt = indentation(gap, smooth)
        return tgt, (torch.sign(tgt) if exact else engagement(gap, smooth))

    sweep_axis = delta[None, None, :] if delta.dim() == 1 else delta[None]  # (K,) or (B, K)
    gap0 = sweep_axis - anchor(h).T[:, :, None]  # (N, B, K)
    d = indentation(gap0, smooth)
    b = None
    eng = target(gap0)[1] if iterations < 1 else None
    for _ in range(iterations):
        a, a2, safe, force = contact(d, b, squares=curv)
        w, *rest = apply(both, force)
        tgt, eng = target(gap0 - w)
        # Newton on d + 2 b a^2 = <gap>_+, diagonal: the self-image term dw_i/dd_i =
        # K_ii dF_i/dd_i = K_ii 2 a (1 + ...), and d(2 b a^2)/dd = 4 b a^2 / (gamma d)
        slope = torch.addcmul(one, k2 * a, eng)
        if curv:
            b = rest[0]
            ba2 = b * a2
            resid = torch.add(d, ba2, alpha=2.0) - tgt
            slope = torch.addcmul(slope, g4, ba2 / safe)
        else:
            resid = d - tgt
        d = torch.clamp_min(torch.addcdiv(d, resid, slope, value=-1.0), 0.0)

    a, a2, safe, force = contact(d, b)
    a_nom = settings.nominal_area
    p_star = force.sum(0) / a_nom
    alpha = (math.pi / a_nom) * a2.sum(0)
    per = (math.pi / a_nom) * a2.permute(1, 2, 0) if per_asperity else None
    if not tangent:
        return Sweep(delta=delta, p_star=p_star, alpha=alpha, stiffness=p_star * math.nan), per
    # The engagement of the last sweep (at its starting state) stands in for the final one:
    # they differ by the last update, i.e. only where an asperity is just engaging, and
    # one kernel product and softplus evaluation fewer is ~10 % of the cost.
    eng = eng * torch.sign(d)
    # Tangent along Delta: with t_i = d(total compression)/dDelta at fixed b_i, db = dB/dDelta,
    #   t_i + 2 a_i^2 db_i = e_i (1 - sum_j K_ij dF_j),  dF_j = 2 a_j t_j + 8/3 a_j^3 db_j,
    #   db = C dF,  dalpha_i = 2 pi a_i^2 t_i / (gamma_i d_i + 4 b_i a_i^2) / A_nom;
    # Jacobi sweeps with the self term K_ii 2 a_i t_i on the left.
    two_a = 2.0 * a
    denom = torch.addcmul(one, k_diag * two_a, eng)
    p_t = eng / denom
    t = p_t
    dforce = two_a * t
    if curv:
        cube = (8.0 / 3.0) * a2 * a
        q_t = torch.addcmul(2.0 * a2, k_diag * cube, eng) / denom
    for _ in range(max(iterations - 1, 1)):
        kf, *rest = apply(off_and_c, dforce)
        if curv:
            t = p_t - torch.addcmul(p_t * kf, q_t, rest[0])
            dforce = torch.addcmul(two_a * t, cube, rest[0])
        else:
            t = p_t - p_t * kf
            dforce = two_a * t
    spread = gam * safe if b is None else torch.addcmul(gam * safe, b, a2, value=4.0)
    darea = (2.0 * math.pi) * (a2 * t / spread).sum(0)
    in_contact = darea > 0
    dforce = dforce.sum(0)
    stiffness = torch.where(in_contact, dforce / torch.where(in_contact, darea, 1.0), 0.0)
    slope = (dforce / a_nom).detach()
    return Sweep(delta, p_star, alpha, stiffness, load_slope=slope), per
