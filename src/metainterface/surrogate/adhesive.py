"""Adhesive targets for a network that designs for adhesive contact (issue 38, item 2).

An adhesive part's alpha(P*) is the loading curve under a rising normal force
(``physics.adhesion``): it starts above 0 at zero load (every asperity at the top has snapped
in), jumps where an asperity snaps in, and depends on the work of adhesion w / (E* R). The
shipped networks never saw such curves. The adhesive network is the friction-law network
fine-tuned on targets made here from a dataset's cells:

- each cell gets a work of adhesion drawn log-uniformly in ``AdhesiveTargets.adhesion``
  (1e-6 to 3e-4 of E* R: from a stiff TPU at a millimetre to PDMS at 0.1 mm; PDMS on
  glass at R = 0.5 mm is 4.2e-5). Above that most cells of the default space, loaded from
  zero, jump past Delta_max at once: the whole curve is one snap-in;
- its adhesive loading curve is ended at an indentation Delta_L drawn log-uniformly in
  [min_end, 1] Delta_max and given by M uniform loads from 0 (M from ``laws.ROWS``), as a
  friction law in newtons arrives;
- it is read by :func:`~metainterface.physics.curves.normalised_from_points`, as in use.

Whether the network should also be told w (one more input, ``InverseMLP.adhesion_input``) or
read it off the curve alone is measured, not assumed (benchmarks/bench_adhesive_surrogate.py).
The loss is the relative curve error of the design's adhesive loading curve at the target's
loads (:func:`adhesive_error`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import torch
from torch import Tensor
from tqdm.auto import tqdm

from metainterface.errors import MetainterfaceError
from metainterface.physics.adhesion import sweep_adhesive, touch_grid
from metainterface.physics.cell import CellSettings
from metainterface.physics.curves import features_from_normalised, normalised_from_points
from metainterface.physics.jkr import ADHESION_LIMIT
from metainterface.physics.metrics import interp, relative_l2, window_mean
from metainterface.surrogate.data import Split
from metainterface.surrogate.laws import ROWS, check_counts
from metainterface.surrogate.loss import CurveTargets
from metainterface.surrogate.model import adhesion_column

#: Where the work of adhesion of training targets is drawn, in units of E* R.
ADHESION_RANGE = (1e-6, 3e-4)


@dataclass(frozen=True)
class AdhesiveTargets:
    """How adhesive targets are made from a dataset's cells.

    Attributes
    ----------
    copies : int
        Targets made from each cell (each with its own w, end and points).
    adhesion : tuple of two floats
        The range of w / (E* R), drawn log-uniformly, within (0, ADHESION_LIMIT].
    min_end : float
        Smallest end indentation Delta_L / Delta_max, in (0, 1].
    delta_samples : int
        Approaches of each cell's loading curve before it is resampled.
    """

    copies: int = 1
    adhesion: tuple[float, float] = ADHESION_RANGE
    min_end: float = 0.15
    delta_samples: int = 256

    def __post_init__(self) -> None:
        check_counts(self.copies, self.min_end, self.delta_samples)
        lo, hi = self.adhesion
        if not 0 < lo <= hi <= ADHESION_LIMIT:
            raise MetainterfaceError(
                f"adhesion must be a range within (0, {ADHESION_LIMIT:g}] (E* R), got "
                f"{self.adhesion}"
            )


def adhesive_split(
    split: Split,
    settings: CellSettings,
    seed: int,
    *,
    adhesion_input: bool,
    spec: AdhesiveTargets | None = None,
    chunk: int = 4096,
    progress: bool = False,
    device: torch.device | str = "cpu",
) -> Split:
    """Adhesive targets made from the cells of ``split`` (S rows -> up to S copies rows).

    Returns a Split whose ``adhesion`` holds each target's w / (E* R) (float64) and whose
    features (float32) carry the log10 w column at the end when ``adhesion_input``. Targets
    that carry no load by their end (a cell held by adhesion alone) are left out. The
    category names the decade of w (``"w 1e-05"``). The same seed gives the same targets;
    ``device`` is where the curves are computed (the Split is on the CPU).
    """
    spec = spec or AdhesiveTargets()
    gen = torch.Generator().manual_seed(int(seed))
    gamma = split.gamma.cpu().repeat(spec.copies, 1).double()
    h = split.h.cpu().repeat(spec.copies, 1).double()
    total = gamma.shape[0]
    lo, hi = (math.log(v) for v in spec.adhesion)
    w = torch.exp(lo + (hi - lo) * torch.rand(total, generator=gen, dtype=torch.float64))
    end = spec.min_end ** torch.rand(total, generator=gen, dtype=torch.float64)
    rows = torch.tensor(ROWS)[torch.randint(len(ROWS), (total,), generator=gen)]
    n = settings.n_steps
    alpha_hat, s_hat = torch.zeros(total, n), torch.zeros(total, n)
    p_max, a_max = torch.ones(total), torch.ones(total)
    keep = torch.zeros(total, dtype=torch.bool)
    unit = torch.linspace(0, 1, spec.delta_samples, dtype=torch.float64)
    for start in tqdm(range(0, total, chunk), desc="adhesive targets", disable=not progress):
        sl = slice(start, min(start + chunk, total))
        delta = unit[None] * (end[sl] * settings.delta_max)[:, None]
        with torch.no_grad():
            on = [t.to(device) for t in (gamma[sl], h[sl], w[sl], delta)]
            sw, _ = sweep_adhesive(on[0], on[1], settings, on[2], delta=on[3])
        load, area = sw.p_star.cpu(), sw.alpha.cpu()
        for m in ROWS:
            pick = torch.nonzero(rows[sl] == m).flatten()
            if pick.numel() == 0:
                continue
            x = torch.linspace(0, 1, m, dtype=torch.float64)[None]
            p = x * load[pick, -1:]
            a = interp(p, load[pick], area[pick])
            out = normalised_from_points(p, a, n)
            good = (load[pick, -1] > 0) & torch.stack(
                [torch.isfinite(o).reshape(pick.numel(), -1).all(-1) for o in out]
            ).all(0)
            idx = pick + start
            alpha_hat[idx], s_hat[idx] = out[0].float(), out[1].float()
            p_max[idx], a_max[idx] = out[2].float(), out[3].float()
            keep[idx] = good
    targets = CurveTargets(alpha_hat[keep], s_hat[keep], p_max[keep], a_max[keep])
    features = features_from_normalised(*(getattr(targets, f) for f in _FIELDS))
    w_kept = w[keep]
    if adhesion_input:
        features = torch.cat([features, adhesion_column(w_kept).float()], -1)
    decade = np.floor(np.log10(w_kept.numpy()))
    category = np.array([f"w 1e{int(d):+03d}" for d in decade])
    return Split(features, targets, gamma[keep].float(), h[keep].float(), category, adhesion=w_kept)


_FIELDS = ("alpha_hat", "stiffness_hat", "p_star_max", "alpha_max")


def adhesive_error(
    gamma: Tensor,
    h: Tensor,
    target: CurveTargets,
    settings: CellSettings,
    adhesion: Tensor,
    n_delta: int = 64,
    window: float = 0.0,
) -> Tensor:
    """(B,) relative L2 error of (B, N) designs' adhesive loading curves at the target's
    loads (its n_steps uniform pressures up to P*_max), each design at its own w / (E* R)
    ``adhesion`` (B,); differentiable.

    The curve is an ``n_delta`` sweep of [0, Delta_max] in float64 with, besides, an approach
    just short of each asperity's touch: the load where it snaps in is then the force at its
    touch, exact and differentiable in its height (between uniform samples it would be the
    last sample's, blind to it). It is read in the load, held beyond the design's reach;
    ``window`` > 0 reads the mean over loads within +-window P*_max instead (a snap-in is then
    a ramp whose place the gradient sees: the training loss; 0 is the error itself)."""
    g, hh = gamma.double(), h.double()
    n = target.alpha_hat.shape[-1]
    grid = torch.linspace(0, 1, n, dtype=g.dtype, device=g.device)
    top = target.p_star_max.to(g.dtype)
    p = grid[None] * top[:, None]
    delta = touch_grid(hh, settings, n_delta)
    sw, _ = sweep_adhesive(g, hh, settings, adhesion.to(g.dtype), delta=delta)
    if window > 0:
        alpha = window_mean(p, window * top, sw.p_star, sw.alpha)
    else:
        alpha = interp(p, sw.p_star, sw.alpha)
    reference = (target.alpha_hat * target.alpha_max[:, None]).to(g.dtype)
    return relative_l2(alpha, reference).to(gamma.dtype)
