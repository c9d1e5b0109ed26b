"""The one test of whether a law is reachable by the cell: the envelope of alpha(P*) that
cells reach, and how far a law's points leave it.

The envelope is estimated from a fixed family of designs (uniform cells over a gamma grid
at h = 0, single active asperities, and random cells), computed once per cell on a fine
pressure grid. It is pointwise, so a law inside it is not proven reachable (one cell must
follow the whole law: the design decides), but a law outside it is not: ``reachability``,
``feasible_scale``, ``design_scale`` and ``design`` all ask :func:`reach_violation`, so
they give one answer. The exact pointwise bounds (each asperity free to pick its gamma at
every load, :func:`~metainterface.units.reach.alpha_bounds`) are wider than what one cell
does: on 290 random power laws that they passed and this envelope refused, the designs
missed by 4-39 %.

With adhesion (w / (E* R) > 0, issue 38) the family is the same, each cell of JKR asperities
(``Independent(adhesion=w)``, its loading curve under a rising force), and the envelope is
computed for that w; the test is otherwise the same. An adhesive cell carries area at zero
load, so its envelope starts above 0 there.
"""

from __future__ import annotations

import functools
from dataclasses import asdict
from pathlib import Path

import numpy as np
import torch

from metainterface._threads import threads_for
from metainterface.inverse.params import DTYPE, FULL
from metainterface.inverse.starts import random_starts
from metainterface.inverse.targets import Target
from metainterface.physics.cell import CellSettings
from metainterface.physics.metrics import interp
from metainterface.physics.models import Independent

#: Slack on the envelope before a point counts as out of reach, as a share of the law's
#: largest alpha (the curve error's scale).
TOLERANCE = 0.05


def reachable_envelope(
    p_star: np.ndarray,
    settings: CellSettings,
    samples: int = 2000,
    seed: int = 0,
    adhesion: float = 0.0,
) -> tuple[np.ndarray, np.ndarray, float]:
    """An estimate of the alpha range reachable at each pressure (M,): (lo, hi, P*_reach).

    From a fixed family of designs: uniform cells over a gamma grid at h = 0, single active
    asperities, and ``samples`` random cells; P*_reach is the largest pressure any reaches.
    The envelope is computed once per cell (and work of adhesion ``adhesion`` = w / (E* R),
    0 for none) on a fine pressure grid and interpolated (lo = inf, hi = -inf beyond
    P*_reach).
    """
    grid, lo, hi, reach = _envelope(settings, samples, seed, adhesion=_adhesion(adhesion))
    p = np.asarray(p_star, dtype=np.float64)
    inside = p <= reach
    lo_q = np.where(inside, np.interp(p, grid, lo), np.inf)
    hi_q = np.where(inside, np.interp(p, grid, hi), -np.inf)
    return lo_q, hi_q, reach


def _adhesion(w: object) -> float:
    """w / (E* R) as a float key of the envelope's cache (rounded to 12 digits, so that
    the same w reached by two routes is one envelope)."""
    value = float(w)  # type: ignore[arg-type]
    return float(f"{value:.12g}") if value > 0 else 0.0


#: The default cell's envelope without adhesion (the family of ``reachable_envelope``'s
#: defaults, 256 pressures), precomputed: computing it took 0.8 s of CPU, in every process
#: that designs or tests a law (a README design took ~8 s in all). Written by ``python -m
#: metainterface.inverse.envelope``; tests/inverse/test_envelope.py computes it afresh and
#: compares. Any other cell, family, grid or adhesion is computed (once per process).
SHIPPED = Path(__file__).resolve().parents[1] / "weights" / "envelope.npz"
_DEFAULT = (2000, 0, 256)


def _key(settings: CellSettings, samples: int, seed: int, points: int) -> str:
    """What an envelope was computed for, as text (stored with the shipped one)."""
    return repr((sorted(asdict(settings).items()), samples, seed, points))


@functools.lru_cache(maxsize=64)
def _envelope(
    settings: CellSettings, samples: int, seed: int, points: int = 256, adhesion: float = 0.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The family's envelope on ``points`` pressures over [0, P*_reach]: the shipped one
    for the default cell and family without adhesion, else computed."""
    if not adhesion and (samples, seed, points) == _DEFAULT and settings == CellSettings():
        shipped = _shipped(_key(settings, samples, seed, points))
        if shipped is not None:
            return shipped
    return compute_envelope(settings, samples, seed, points, adhesion)


def _shipped(key: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, float] | None:
    """The shipped envelope if it was computed for ``key`` (else None: compute it)."""
    try:
        with np.load(SHIPPED) as f:
            if str(f["key"]) != key:
                return None
            return f["grid"].copy(), f["lo"].copy(), f["hi"].copy(), float(f["reach"])
    except (OSError, KeyError, ValueError):
        return None


def write_shipped(path: Path = SHIPPED) -> Path:
    """Compute the default cell's envelope and write it where ``_envelope`` reads it."""
    args = (CellSettings(), *_DEFAULT)
    grid, lo, hi, reach = compute_envelope(*args)
    np.savez(path, key=np.array(_key(*args)), grid=grid, lo=lo, hi=hi, reach=np.array(reach))
    return path


def compute_envelope(
    settings: CellSettings, samples: int, seed: int, points: int = 256, adhesion: float = 0.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The family's envelope on ``points`` pressures over [0, P*_reach] (P*_reach = 0: no
    cell of the family reaches a positive load, as where adhesion holds every asperity
    below Delta_max; the grid is then the one point 0, out of reach above it)."""
    n = settings.n_asperities
    gammas = torch.linspace(settings.gamma_min, settings.gamma_max, 12, dtype=DTYPE)
    uniform = gammas[:, None].expand(-1, n)
    single_h = torch.full((12, n), 3 * settings.delta_max, dtype=DTYPE)
    single_h[:, 0] = 0.0
    g_r, h_r = random_starts(samples, 1, settings, seed, FULL)
    gamma = torch.cat([uniform, uniform, g_r])
    h = torch.cat([torch.zeros(12, n, dtype=DTYPE), single_h, h_r])
    if adhesion:
        # The JKR family costs ~1 CPU s in float64, once per w, and a modulus scan asks for
        # one w per modulus: float32 takes 2.2x less and moves lo, hi and P*_reach by < 1e-6
        # relative (w = 1e-7 .. 3e-2, 4 and 9 asperities), against a 5 % tolerance.
        gamma, h = gamma.float(), h.float()
    # 2,024 cells at once: large kernels, which gain from every thread (1.85x on two idle
    # cores, an adhesive one), unlike the design work that usually asks for the envelope
    with torch.no_grad(), threads_for("heavy"):
        sw = Independent(adhesion=adhesion).load_area(gamma, h, settings)
        p, a = sw.p_star, sw.alpha
        if not adhesion:  # the adhesionless curve starts at the origin
            zero = torch.zeros_like(p[:, :1])
            p, a = torch.cat([zero, p], dim=-1), torch.cat([zero, a], dim=-1)
        p_max = p[:, -1]
        reach = float(p_max.max())
        # denser near 0, where every curve rises steeply (alpha ~ P*^(2/gamma))
        grid = reach * torch.linspace(0.0, 1.0, points if reach > 0 else 1, dtype=p.dtype) ** 2
        alpha = interp(grid[None].expand(gamma.shape[0], -1).contiguous(), p, a)
    reached = grid[None] <= p_max[:, None]
    lo = torch.where(reached, alpha, torch.inf).amin(0)
    hi = torch.where(reached, alpha, -torch.inf).amax(0)
    grid_np, lo_np, hi_np = (v.numpy().astype(np.float64) for v in (grid, lo, hi))
    return grid_np, lo_np, hi_np, reach


def reach_violation(
    p_star: np.ndarray,
    alpha: np.ndarray,
    settings: CellSettings,
    tolerance: float = TOLERANCE,
    adhesion: float | np.ndarray = 0.0,
) -> np.ndarray:
    """How far each point of laws (..., K) leaves the envelope (..., K): 0 inside (within
    ``tolerance`` times the law's largest alpha of it, the scale of the curve error), else
    the log-ratio by which alpha misses it; beyond the largest reachable P*, 1 plus the
    log-ratio of the pressure to it. Points at P* <= 0 are not tested (0).

    adhesion: w / (E* R) of the cells, a number or one per law (...,) (a scale search over
    the modulus moves w / (E* R) with E*); each distinct value has its own envelope.
    """
    p = np.asarray(p_star, dtype=np.float64)
    a = np.maximum(np.asarray(alpha, dtype=np.float64), 1e-300)
    w = np.broadcast_to(np.asarray(adhesion, dtype=np.float64), p.shape[:-1])
    slack = tolerance * np.max(a, axis=-1, keepdims=True)
    if w.ndim == 0:
        lo, hi, top = reachable_envelope(p, settings, adhesion=float(w))
        reach = np.full((*p.shape[:-1], 1), top)
    else:
        lo, hi, reach = np.empty_like(p), np.empty_like(p), np.empty((*p.shape[:-1], 1))
        for value in np.unique(w):
            rows = w == value
            lo[rows], hi[rows], reach[rows] = reachable_envelope(
                p[rows], settings, adhesion=float(value)
            )
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        below = np.log(np.maximum((lo - slack) / a, 1.0))
        above = np.log(np.maximum(a / (hi + slack), 1.0))
        beyond = np.log(np.maximum(p / reach, 1.0))
        v = np.where(p > reach, np.where(np.isfinite(beyond), beyond, 30.0) + 1.0, below + above)
    return np.where(p > 0, v, 0.0)


def target_adhesion(target: Target) -> float:
    """w / (E* R) that a target was converted with (0: none or not a friction law)."""
    meta = target.meta if isinstance(target.meta, dict) else {}
    friction = meta.get("friction")
    if not isinstance(friction, dict):
        return 0.0
    return float(friction.get("adhesion", 0.0) or 0.0)


def reachability_warnings(
    target: Target, settings: CellSettings, adhesion: float | None = None
) -> list[str]:
    """One line where the target leaves the reachable envelope (:func:`reach_violation`),
    else none. adhesion: w / (E* R) of the cells (None: the target's own,
    :func:`target_adhesion`)."""
    w = target_adhesion(target) if adhesion is None else float(adhesion)
    lo, hi, p_reach = reachable_envelope(target.p_star, settings, adhesion=w)
    v = reach_violation(target.p_star, target.alpha, settings, adhesion=w)
    out = []
    if target.p_star_max > p_reach:
        out.append(
            f"target {target.name}: P* = {target.p_star_max:.4g} is beyond the largest pressure "
            f"any design in the bounds reaches at Delta_max ({p_reach:.4g})"
        )
    outside = (v > 0) & np.isfinite(lo)
    if outside.any():
        i = int(np.flatnonzero(outside)[0])
        out.append(
            f"target {target.name}: alpha = {target.alpha[i]:.4g} at P* = {target.p_star[i]:.4g} "
            f"is outside the reachable envelope there, alpha in [{lo[i]:.4g}, {hi[i]:.4g}] "
            f"({int(outside.sum())} of {target.p_star.size} points outside)"
        )
    return out


if __name__ == "__main__":  # pragma: no cover - regenerates the shipped file
    print(write_shipped())
