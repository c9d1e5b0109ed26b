"""Tensors for training and evaluation, from a dataset file of the generator."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
from torch import Tensor

from metainterface.data.load import Dataset
from metainterface.errors import MetainterfaceError
from metainterface.physics.curves import features_from_normalised
from metainterface.surrogate.loss import CurveTargets


@dataclass(frozen=True)
class Split:
    """One split of a dataset as float32 tensors (S rows)."""

    features: Tensor  # (S, 2n + 2)
    targets: CurveTargets
    gamma: Tensor  # (S, N)
    h: Tensor  # (S, N)
    category: np.ndarray  # (S,) str
    #: (S,) float64 work of adhesion w / (E* R) of each target (adhesive targets, else None)
    adhesion: Tensor | None = None

    def __len__(self) -> int:
        return self.features.shape[0]

    def to(self, device: torch.device) -> Split:
        """The split with its tensors on ``device`` (itself when they are there already)."""
        if self.features.device == device:
            return self
        t = self.targets
        return Split(
            self.features.to(device),
            CurveTargets(
                t.alpha_hat.to(device),
                t.stiffness_hat.to(device),
                t.p_star_max.to(device),
                t.alpha_max.to(device),
            ),
            self.gamma.to(device),
            self.h.to(device),
            self.category,
            None if self.adhesion is None else self.adhesion.to(device),
        )

    def adhesion_rows(self, idx: Tensor) -> Tensor | None:
        """The work of adhesion of the rows ``idx`` (None for targets without adhesion)."""
        return None if self.adhesion is None else self.adhesion.index_select(0, idx)

    def rows(self, idx: Tensor) -> tuple[Tensor, CurveTargets, Tensor, Tensor]:
        """The rows ``idx`` (a 1-D index tensor): features, targets, gamma, h."""

        def take(a: Tensor) -> Tensor:
            return a.index_select(0, idx)  # ~5x faster than a[idx] for row gathers

        t = self.targets
        return (
            take(self.features),
            CurveTargets(
                take(t.alpha_hat), take(t.stiffness_hat), take(t.p_star_max), take(t.alpha_max)
            ),
            take(self.gamma),
            take(self.h),
        )


def split_of(dataset: Dataset, name: str) -> Split:
    """The rows of a loaded dataset whose split is ``name`` (train, val or test); a split
    with no rows is a one-line error (too few samples to split)."""
    sub = dataset.subset(name)
    if len(sub) == 0:
        where = f"{dataset.path}: " if dataset.path is not None else ""
        raise MetainterfaceError(
            f"{where}the {name} split is empty ({len(dataset)} samples); generate more samples"
        )

    def f32(a: np.ndarray) -> Tensor:
        return torch.as_tensor(a, dtype=torch.float32)

    targets = CurveTargets(
        f32(sub.alpha_hat), f32(sub.stiffness_hat), f32(sub.p_star_max), f32(sub.alpha_max)
    )
    feats = features_from_normalised(
        targets.alpha_hat, targets.stiffness_hat, targets.p_star_max, targets.alpha_max
    )
    return Split(feats, targets, f32(sub.gamma), f32(sub.h), np.asarray(sub.category))
