"""Fitting the lattice, the tilt and every asperity to a scan (least squares in torch).

Two stages, both on the points within the disc of radius p / 2 around each lattice point
(the inscribed circle of the asperity's square; the corners hold the steps between squares):

1. ``fit_lattice``: the lattice (origin, rotation, pitch), the tilt plane and, per asperity
   of the design (shared by every cell), a tip height z0_k and an exponent gamma_k, all at
   once. The asperities sit on the rigid lattice here, so a tilt cannot pass for shifted
   tips, and the plane is not biased by the pattern as a plain least-squares plane is.
2. ``fit_asperities``: with the plane removed, every asperity of every cell on its own:
   tip height, exponent and lateral position (dx, dy), and its tip radius (the radius of
   curvature of a paraboloid fitted within ``TIP_SHARE`` a_max of the tip).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import torch

from metainterface.inverse.levmar import least_squares
from metainterface.measure.lattice import Lattice
from metainterface.measure.scan import Scan
from metainterface.measure.surface import profile
from metainterface.physics.cell import Design
from metainterface.physics.sneddon import shape_constant

#: Points used by the lattice fit (a fixed random subset of the measured ones).
LATTICE_POINTS = 20_000
#: Points kept per asperity in the per-asperity fit (a regular subset beyond this).
ASPERITY_POINTS = 2_000
#: An asperity is fitted when at least this share of its disc is measured and its tip is in
#: the scan.
MIN_COVER = 0.4
#: Tip radius: paraboloid fitted within this share of a_max from the tip.
TIP_SHARE = 0.35
#: Exponents are kept in this range while fitting (the closed forms' range).
GAMMA_RANGE = (1.05, 40.0)


@dataclass(frozen=True)
class LatticeFit:
    """Stage 1. lattice; tilt: (2,) plane slopes (dz/dx, dz/dy) [dimensionless]; z0, gamma:
    (N,) tip heights [units of R] and exponents shared by the cells; rms: residual [R]."""

    lattice: Lattice
    tilt: np.ndarray
    z0: np.ndarray
    gamma: np.ndarray
    rms: float


@dataclass(frozen=True)
class AsperityFits:
    """Stage 2, one row per fitted asperity instance (B of them).

    kind: (B,) asperity index k of the design; cell: (B, 2) the unit cell (column, row) it
    lies in; z0: (B,) tip height [R] (plane removed); gamma: (B,); shift: (B, 2) lateral
    offset from the lattice point, in cell axes [units of R]; tip_radius, tip_radius_design:
    (B,) [units of R] (inf where the tip is flat); rms: (B,) residual [R]; cover: (B,) share
    of the disc measured.
    """

    kind: np.ndarray
    cell: np.ndarray
    z0: np.ndarray
    gamma: np.ndarray
    shift: np.ndarray
    tip_radius: np.ndarray
    tip_radius_design: np.ndarray
    rms: np.ndarray
    cover: np.ndarray


def _grid_points(scan: Scan, limit: int, seed: int = 0) -> tuple[np.ndarray, ...]:
    ok = np.flatnonzero(scan.valid.ravel())
    if ok.size > limit:
        ok = np.sort(np.random.default_rng(seed).choice(ok, limit, replace=False))
    i, j = np.divmod(ok, scan.shape[1])
    return j * scan.dx, i * scan.dy, scan.heights.ravel()[ok]


def _lbfgs(params: list[torch.Tensor], loss_fn, iters: int = 200) -> None:
    opt = torch.optim.LBFGS(
        params,
        lr=1.0,
        max_iter=iters,
        tolerance_grad=1e-12,
        tolerance_change=1e-14,
        history_size=20,
        line_search_fn="strong_wolfe",
    )

    def closure() -> torch.Tensor:
        opt.zero_grad()
        loss = loss_fn()
        loss.backward()
        return loss

    opt.step(closure)


def fit_lattice(
    scan: Scan,
    design: Design,
    start: Lattice,
    tilt0: np.ndarray,
    z0_start: np.ndarray,
    gamma_start: np.ndarray,
    *,
    tied: bool = False,
    rounds: int = 2,
    height_scale: float = 1.0,
) -> LatticeFit:
    """Stage 1 (module docstring) from first estimates: ``start`` lattice, tilt (2,), and
    per-asperity tip heights z0 (N,) [R] and exponents (N,) (from a first stage 2).

    tied: the tip heights follow the design's, z0_k = z_c - a h_k (a height scale a), for
    scans that show each asperity in one cell only: there a free z0_k per asperity would
    take up the tilt.

    height_scale: the scan's heights over the design's (``Orientation.height_scale``): a
    scan in the wrong height unit (a factor 1000) is fitted at the design's scale, for its
    slip to be reported rather than the fit to diverge; tilt, tips and rms come back in the
    scan's own heights."""
    s = design.settings
    n, pitch0 = s.n_side, start.design_pitch
    zs = s.delta_max  # height scale of the unknowns
    hs = height_scale if height_scale > 0 else 1.0
    x_np, y_np, z_np = _grid_points(scan, LATTICE_POINTS)
    z_np = z_np / hs
    tilt0, z0_start = np.asarray(tilt0) / hs, np.asarray(z0_start) / hs
    x, y, z = (torch.as_tensor(a) for a in (x_np, y_np, z_np))
    # unknowns, each of order one: origin / pitch, angle, log scale, tilt * pitch / zs, ...
    o = torch.tensor(start.origin / pitch0, requires_grad=True)
    th = torch.tensor(start.theta, requires_grad=True)
    ls = torch.tensor(math.log(start.scale), requires_grad=True)
    tilt = torch.tensor(np.asarray(tilt0) * pitch0 / zs, requires_grad=True)
    z0 = torch.tensor(np.asarray(z0_start) / zs, requires_grad=True)
    zc = torch.tensor(0.0, dtype=torch.float64, requires_grad=True)
    scale = torch.tensor(1.0, dtype=torch.float64, requires_grad=True)
    h_design = torch.as_tensor(design.h - design.h.min()) / zs

    def tips() -> torch.Tensor:
        return -scale * h_design if tied else z0

    g = torch.tensor(np.asarray(gamma_start, dtype=np.float64), requires_grad=True)

    def local(o, th, ls):
        c, sn = torch.cos(th), torch.sin(th)
        dx, dy = x / pitch0 - o[0], y / pitch0 - o[1]
        k = torch.exp(-ls)
        return k * (c * dx + sn * dy), k * (-sn * dx + c * dy)  # in design pitches

    rms = math.nan
    for _ in range(rounds):
        with torch.no_grad():  # which asperity and which points, fixed for the round
            u, v = local(o, th, ls)
            col, row = torch.floor(u), torch.floor(v)
            kind = (torch.remainder(row, n) * n + torch.remainder(col, n)).long()
            r = torch.hypot(u - col - 0.5, v - row - 0.5)
            keep = r < 0.5  # the disc inscribed in the asperity's square
        xs, ys, zk, kk = x[keep], y[keep], z[keep], kind[keep]
        cols, rows = col[keep], row[keep]
        if zk.numel() == 0:
            break

        def loss_fn(xs=xs, ys=ys, zk=zk, kk=kk, cols=cols, rows=rows):
            c, sn = torch.cos(th), torch.sin(th)
            dx, dy = xs / pitch0 - o[0], ys / pitch0 - o[1]
            k = torch.exp(-ls)
            uu, vv = k * (c * dx + sn * dy), k * (-sn * dx + c * dy)
            rr = _radius(uu - cols - 0.5, vv - rows - 0.5) * pitch0  # design units
            gk = g.clamp(*GAMMA_RANGE)[kk]
            model = profile(rr, tips()[kk] * zs, gk, s.radius) + zc * zs
            model = model + (tilt[0] * xs + tilt[1] * ys) * zs / pitch0
            return ((zk - model) ** 2).mean() / zs**2

        _lbfgs([o, th, ls, tilt, z0 if not tied else scale, g, zc], loss_fn, iters=300)
        rms = float(loss_fn().detach().sqrt()) * zs
    with torch.no_grad():
        lat = Lattice(
            origin=o.numpy() * pitch0,
            theta=float(th),
            pitch=float(torch.exp(ls)) * pitch0,
            design_pitch=pitch0,
        )
        return LatticeFit(
            lattice=lat,
            tilt=tilt.numpy() * zs * hs / pitch0,
            z0=(tips() + zc).numpy() * zs * hs,
            gamma=g.clamp(*GAMMA_RANGE).numpy().copy(),
            rms=rms * hs,
        )


def levelled(scan: Scan, tilt: np.ndarray) -> np.ndarray:
    """(ny, nx) heights less the fitted tilt plane [units of R] (NaN kept)."""
    x, y = np.meshgrid(*scan.coords())
    return scan.heights - (tilt[0] * x + tilt[1] * y)


def fit_asperities(
    scan: Scan,
    design: Design,
    lattice: Lattice,
    tilt: np.ndarray,
    *,
    gamma_start: float | None = None,
    top_band: float = 0.0,
) -> AsperityFits:
    """Stage 2 (module docstring): every asperity whose tip is in the scan and whose disc is
    at least ``MIN_COVER`` measured. gamma_start: one exponent to start every fit from
    (before the lattice's orientation is known); None: the design's at each position.
    top_band [R]: points within this of an asperity's highest are left out of its fit (a
    flat or terraced top is no power law's: the flank gives the tip the print cut)."""
    s = design.settings
    n = s.n_side
    p = lattice.design_pitch
    z = levelled(scan, tilt)
    ny, nx = scan.shape
    width, height = scan.size
    # the unit cells the scan touches: its corners in cell coordinates
    cu, cv = lattice.to_cell(np.array([0, width, 0, width]), np.array([0, 0, height, height]))
    rows = range(math.floor(cv.min() / p) - 1, math.ceil(cv.max() / p) + 1)
    cols = range(math.floor(cu.min() / p) - 1, math.ceil(cu.max() / p) + 1)
    radius_px = 0.5 * lattice.pitch
    xs, ys, zs_, meta = [], [], [], []
    for row in rows:
        for col in cols:
            cx, cy = lattice.to_scan(np.array((col + 0.5) * p), np.array((row + 0.5) * p))
            cx, cy = float(cx), float(cy)
            if not (0 <= cx < width and 0 <= cy < height):
                continue
            j0, j1 = (
                int(max(0, (cx - radius_px) / scan.dx)),
                int(min(nx, (cx + radius_px) / scan.dx + 2)),
            )
            i0, i1 = (
                int(max(0, (cy - radius_px) / scan.dy)),
                int(min(ny, (cy + radius_px) / scan.dy + 2)),
            )
            jj, ii = np.meshgrid(np.arange(j0, j1), np.arange(i0, i1))
            px, py = jj * scan.dx, ii * scan.dy
            inside = np.hypot(px - cx, py - cy) < radius_px
            disc = math.pi * radius_px**2 / (scan.dx * scan.dy)
            ok = inside & np.isfinite(z[i0:i1, j0:j1])
            cover = ok.sum() / disc
            if cover < MIN_COVER:
                continue
            idx = np.flatnonzero(ok.ravel())
            if idx.size > ASPERITY_POINTS:
                idx = idx[:: math.ceil(idx.size / ASPERITY_POINTS)]
            xs.append(px.ravel()[idx] - cx)
            ys.append(py.ravel()[idx] - cy)
            zs_.append(z[i0:i1, j0:j1].ravel()[idx])
            kind = (row % n) * n + (col % n)
            meta.append((kind, col, row, cover))
    if not meta:
        return AsperityFits(*(np.zeros((0,)) for _ in range(9)))
    b = len(meta)
    width_ = max(a.size for a in xs)
    pad = np.zeros((3, b, width_))
    mask = np.zeros((b, width_), dtype=bool)
    fitted = np.zeros((b, width_), dtype=bool)  # the points the fit uses (below the top band)
    for i, (a, c, d) in enumerate(zip(xs, ys, zs_, strict=True)):
        fitted[i, : a.size] = d < d.max() - top_band if top_band > 0 else True
        pad[0, i, : a.size], pad[1, i, : a.size], pad[2, i, : a.size] = a, c, d
        mask[i, : a.size] = True
    kinds = np.array([m[0] for m in meta])
    # rotate the offsets into cell axes and scale to design units
    ct, st_ = math.cos(lattice.theta), math.sin(lattice.theta)
    k = 1.0 / lattice.scale
    pu = torch.as_tensor(k * (ct * pad[0] + st_ * pad[1]))
    pv = torch.as_tensor(k * (-st_ * pad[0] + ct * pad[1]))
    zt = torch.as_tensor(pad[2])
    m = torch.as_tensor(mask)
    zsc = s.delta_max
    top = np.array([np.nanmax(np.where(mask[i], pad[2, i], np.nan)) for i in range(b)])
    g_start = design.gamma[kinds] if gamma_start is None else np.full(b, gamma_start)
    x0 = torch.stack(
        [
            torch.as_tensor(top / zsc),
            torch.as_tensor(g_start.astype(np.float64)),
            torch.zeros(b, dtype=torch.float64),
            torch.zeros(b, dtype=torch.float64),
        ],
        dim=1,
    )
    mf = torch.as_tensor(fitted)
    weight = mf / mf.sum(1, keepdim=True).sqrt() / zsc  # each asperity's mean square

    def fun(x: torch.Tensor, idx: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        return _asperity_residuals(x, pu[idx], pv[idx], zt[idx], weight[idx], p, zsc, s.radius)

    x = least_squares(fun, x0, max_iter=60, max_step=0.5).x
    z0 = x[:, 0]
    gam = x[:, 1].clamp(*GAMMA_RANGE)
    sh = x[:, 2:]
    with torch.no_grad():
        rr = _radius(pu - sh[:, :1] * p, pv - sh[:, 1:] * p)
        model = profile(rr, z0[:, None] * zsc, gam[:, None], s.radius)
        rms = torch.sqrt((torch.where(m, zt - model, 0.0) ** 2).sum(1) / m.sum(1)).numpy()
        rr_np = rr.numpy()
    tip = TIP_SHARE * s.a_max
    radius, radius_design = np.full(b, np.inf), np.full(b, np.inf)
    dz = pad[2]
    for i in range(b):
        near = mask[i] & (rr_np[i] < tip)
        if near.sum() < 6:
            continue
        radius[i] = _paraboloid(rr_np[i][near], dz[i][near])
        ref = profile(
            torch.as_tensor(rr_np[i][near]),
            torch.tensor(0.0),
            torch.tensor(float(design.gamma[kinds[i]])),
            s.radius,
        ).numpy()
        radius_design[i] = _paraboloid(rr_np[i][near], ref)
    return AsperityFits(
        kind=kinds,
        cell=np.array([(mm[1], mm[2]) for mm in meta]),
        z0=z0.detach().numpy() * zsc,
        gamma=gam.detach().numpy().copy(),
        shift=sh.detach().numpy() * p,
        tip_radius=radius,
        tip_radius_design=radius_design,
        rms=rms,
        cover=np.array([mm[3] for mm in meta]),
    )


def _asperity_residuals(
    x: torch.Tensor,
    pu: torch.Tensor,
    pv: torch.Tensor,
    z: torch.Tensor,
    weight: torch.Tensor,
    pitch: float,
    zsc: float,
    radius: float,
) -> tuple[torch.Tensor, torch.Tensor]:
    """Weighted residuals (B, P) of z - (z0 - c r^gamma) and their Jacobian (B, P, 4) in
    x = (z0 / zsc, gamma, shift_u / pitch, shift_v / pitch) (B, 4)."""
    z0, g = x[:, :1] * zsc, x[:, 1:2].clamp(*GAMMA_RANGE)
    du, dv = pu - x[:, 2:3] * pitch, pv - x[:, 3:4] * pitch
    r = _radius(du, dv)
    c = shape_constant(g, radius)
    rg = r**g
    res = (z - (z0 - c * rg)) * weight
    # d model: z0 -> 1; gamma -> -c r^g (ln r - ln R); shift_u -> c g r^(g-2) du pitch
    d_g = -c * rg * (torch.log(r) - math.log(radius))
    d_s = c * g * rg / r**2 * pitch
    jac = (
        torch.stack([torch.full_like(r, zsc), d_g, d_s * du, d_s * dv], dim=-1) * -weight[..., None]
    )
    return res, jac


def _radius(du: torch.Tensor, dv: torch.Tensor) -> torch.Tensor:
    """hypot(du, dv) with a finite gradient at 0 (a tip on a grid point)."""
    return torch.sqrt(du**2 + dv**2 + 1e-24)


def _paraboloid(r: np.ndarray, z: np.ndarray) -> float:
    """Radius of curvature rho of z = a - r^2 / (2 rho) fitted by least squares (inf if flat)."""
    a = np.stack([np.ones_like(r), -0.5 * r**2], axis=1)
    coef, *_ = np.linalg.lstsq(a, z, rcond=None)
    return float(1.0 / coef[1]) if coef[1] > 0 else math.inf
