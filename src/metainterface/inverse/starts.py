"""Where the refinement starts: random cells, the hedge beside the surrogate's prediction, and
the prediction itself (with views of a target that ends without stiffness)."""

from __future__ import annotations

import copy
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import torch
from torch import Tensor

from metainterface.inverse.losses import TargetGrid, relative_error
from metainterface.inverse.params import (
    DTYPE,
    FULL,
    Parameterisation,
)
from metainterface.inverse.targets import Target, target_features
from metainterface.physics.cell import CellSettings
from metainterface.physics.models import ForwardModel

if TYPE_CHECKING:  # the surrogate (and its imports) load only when a design needs it
    from metainterface.surrogate.model import InverseMLP


#: How a zero-shot design's source is named (DesignResult.zero_shot_from).
SURROGATE, LAWS_NETWORK = "surrogate", "friction-law network"
ADHESIVE_NETWORK = "adhesive network"


def random_starts(
    count: int, n_targets: int, settings: CellSettings, seed: int, param: Parameterisation
) -> tuple[Tensor, Tensor]:
    """``count`` random starts (gamma, h), each (n_targets * count, N), the same for every
    target: a target's design does not depend on the others in the batch."""
    gamma, h = param.random(count, settings, torch.Generator().manual_seed(seed))
    return gamma.repeat(n_targets, 1), h.repeat(n_targets, 1)


#: Spread of the jittered copies of the zero-shot design among the hedge starts: normal,
#: with these standard deviations in units of the gamma range and of Delta_max.
JITTER_GAMMA, JITTER_H = 0.1, 0.05


def hedge_starts(
    gamma0: Tensor, h0: Tensor, hedge: int, settings: CellSettings, seed: int
) -> tuple[Tensor, Tensor]:
    """(T, hedge, N) extra starts beside the zero-shot designs gamma0, h0 (T, N).

    The first half are jittered copies of the zero-shot design: the refinement of a
    near-miss often ends in a neighbouring basin that is better.
    The rest are the random starts of the multistart baseline (its first ones), for targets
    the surrogate reads wrong (the linear law). Seeded; the same for every target."""
    t, n = gamma0.shape
    jittered = (hedge + 1) // 2
    g_r, h_r = random_starts(hedge - jittered, t, settings, seed, FULL)
    gen = torch.Generator().manual_seed(seed + 1)
    z = torch.randn((jittered, 2 * n), generator=gen, dtype=gamma0.dtype)
    span = settings.gamma_max - settings.gamma_min
    g_j = (gamma0[:, None] + JITTER_GAMMA * span * z[:, :n]).clamp(
        settings.gamma_min, settings.gamma_max
    )
    h_j = (h0[:, None] + JITTER_H * settings.delta_max * z[:, n:]).clamp_min(0.0)
    return (
        torch.cat([g_j, g_r.view(t, -1, n)], 1),
        torch.cat([h_j, h_r.view(t, -1, n)], 1),
    )


def predict(
    model: InverseMLP,
    targets: Sequence[Target],
    settings: CellSettings,
    adhesion: float = 0.0,
) -> tuple[Tensor, Tensor]:
    """Zero-shot designs (T, N) for the targets from the surrogate (a network that reads
    adhesion is given ``adhesion``, w / (E* R)).

    One target at a time, in float64. Matrix products round differently with the batch size
    (by ~1e-16 in float64), and the refinement's stopping decisions can carry even that into
    another local optimum. Row by row, a target gets the same design alone or in any batch,
    and the network is cheap next to the refinement."""
    net = copy.deepcopy(model).to(DTYPE).eval()
    extra = None
    if net.adhesion_input:
        from metainterface.surrogate.model import adhesion_column

        extra = adhesion_column(torch.tensor([adhesion], dtype=DTYPE))[0]
    with torch.no_grad():
        rows = [
            net.design(conform(net, target_features(t, settings.n_steps), extra), settings)
            for t in targets
        ]
    return torch.cat([g for g, _ in rows]), torch.cat([h for _, h in rows])


#: Views of a target without stiffness that the surrogate also reads: its end extended by
#: these factors of P*_max (the tail's power law continued) and cut at these fractions.
#: The network was trained on curves that end at Delta_max; a measured law ends wherever
#: the measurement stopped, and a design that follows it may reach Delta_max later or
#: sooner. Each view's prediction is measured on the target itself and the best kept.
#: 24 end factors log-spaced over [0.15, 12] (benchmarks/bench_friction_laws.py: 12 gave
#: a median zero-shot error a tenth higher, 40 a tenth lower at twice the views).
_ENDS = np.geomspace(0.15, 12.0, 24)


EXTEND_VIEWS = tuple(float(f) for f in _ENDS if f > 1.05)


CUT_VIEWS = tuple(float(f) for f in _ENDS if f < 0.95)


#: The share of the pressure range whose log-log slope continues the tail.
TAIL_SHARE = 0.25


def target_views(target: Target) -> list[Target]:
    """The extended and cut views of a target (see EXTEND_VIEWS), without stiffness."""
    p, a = target.p_star, target.alpha
    p_max, a_max = float(p[-1]), float(a[-1])
    tail = (p >= (1 - TAIL_SHARE) * p_max) & (p > 0) & (a > 0)
    slope = 1.0
    if tail.sum() >= 2 and np.ptp(np.log(p[tail])) > 0:
        slope = float(np.polyfit(np.log(p[tail]), np.log(a[tail]), 1)[0])
    slope = float(np.clip(slope, 0.2, 1.5))  # a contact curve's tail: sub- to mildly super-linear
    views = []
    for k in EXTEND_VIEWS:
        extra = p_max * np.linspace(1.0, k, 17)[1:]
        ext_a = np.minimum(a_max * (extra / p_max) ** slope, 0.99)
        views.append(
            Target(np.concatenate([p, extra]), np.concatenate([a, ext_a]), name=target.name)
        )
    for f in CUT_VIEWS:
        keep = p <= f * p_max
        if keep.sum() >= 3 and a[keep][-1] > 0:
            views.append(Target(p[keep], a[keep], name=target.name))
    return views


def best_views(
    net: InverseMLP,
    targets: Sequence[Target],
    gamma0: Tensor,
    h0: Tensor,
    settings: CellSettings,
    model: ForwardModel,
    points: int,
    laws_net: InverseMLP | None = None,
    adhesive_net: InverseMLP | None = None,
) -> tuple[Tensor, Tensor, list[str]]:
    """The zero-shot designs (T, N), each target without stiffness given the best, by the
    error on the target itself, of its own prediction (gamma0, h0), those of its views
    (:func:`target_views`), and, with ``laws_net`` (the network trained on targets made the
    way friction laws arrive), that network's on the target and its views; with
    ``adhesive_net`` (for a model with adhesion), that network's on the target, read without
    its stiffness, and its views. Also, per target, which prediction it is (e.g.
    ``"friction-law network, end x0.4"``)."""
    gamma0, h0 = gamma0.clone(), h0.clone()
    labels = [SURROGATE] * len(targets)
    for i, t in enumerate(targets):
        if t.stiffness is not None and adhesive_net is None:
            continue
        g_c, h_c, names = [gamma0[i : i + 1]], [h0[i : i + 1]], [SURROGATE]
        plain = t if t.stiffness is None else Target(t.p_star, t.alpha, name=t.name)
        views = target_views(plain)
        ends = [f", end x{v.p_star_max / t.p_star_max:.2g}" for v in views]
        sources = []
        if t.stiffness is None:
            sources = [
                (net, SURROGATE, views, ends),
                (laws_net, LAWS_NETWORK, [t, *views], ["", *ends]),
            ]
        sources.append((adhesive_net, ADHESIVE_NETWORK, [plain, *views], ["", *ends]))
        for source, label, read, named in sources:
            if source is None or not read:
                continue
            g_v, h_v = predict(source, read, settings, adhesion=model.adhesion)
            g_c.append(g_v)
            h_c.append(h_v)
            names += [label + e for e in named]
        if len(g_c) == 1:
            continue
        g, h = torch.cat(g_c), torch.cat(h_c)
        grid = TargetGrid.from_curves([(t.p_star, t.alpha)], points)
        err = relative_error(
            g, h, settings, grid.rows(torch.zeros(g.shape[0], dtype=torch.long)), model
        )
        k = int(err.argmin())
        gamma0[i], h0[i], labels[i] = g[k], h[k], names[k]
    return gamma0, h0, labels


def shipped_adhesive_net(
    model_path: str | os.PathLike[str] | None, settings: CellSettings, model: ForwardModel
) -> InverseMLP | None:
    """The shipped adhesive network (``surrogate.adhesive``) where the model has adhesion,
    the shipped surrogate designs and the network is there for the same cell; else None."""
    from metainterface.surrogate.checkpoint import default_adhesive_model_path

    if not model.adhesion:
        return None
    return _beside_shipped(model_path, default_adhesive_model_path(), settings)


def shipped_laws_net(
    model_path: str | os.PathLike[str] | None, settings: CellSettings, targets: Sequence[Target]
) -> InverseMLP | None:
    """The shipped friction-law network, where the shipped surrogate designs targets without
    stiffness and the network is there (and made for the same cell); else None. A surrogate
    of the user's own is used alone: the shipped laws network was fine-tuned from ours."""
    from metainterface.surrogate.checkpoint import default_laws_model_path

    if all(t.stiffness is not None for t in targets):
        return None
    return _beside_shipped(model_path, default_laws_model_path(), settings)


def _beside_shipped(
    model_path: str | os.PathLike[str] | None, path: Path, settings: CellSettings
) -> InverseMLP | None:
    """The shipped network at ``path`` where the design uses the shipped surrogate (None, or
    its path) and that network is there for the same cell; else None."""
    from metainterface.surrogate.checkpoint import default_model_path, design_model

    shipped = model_path is None or Path(model_path).resolve() == default_model_path().resolve()
    if not shipped or not path.is_file():
        return None
    net, trained, _ = design_model(path)
    return net if trained == settings else None


def conform(net: InverseMLP, features: Tensor, extra: Tensor | None = None) -> Tensor:
    """Features (F,) as a (1, F) float64 batch (``extra`` columns appended: the adhesion
    input), with the inputs that were constant in the network's training set set to that
    constant. The standardisation divides them by a spread of ~1e-6: a target that differs
    there by round-off or an estimate (S* at P* = 0 by finite differences) would push the
    first layer 1e5 standard deviations away."""
    x = features.to(DTYPE)
    if extra is not None:
        x = torch.cat([x, extra.to(DTYPE)])
    x = x[None]
    return torch.where(net.constant_inputs(), net.in_mean.to(DTYPE), x)
