"""The two training schedules of the paper (sec. 3, appendix A.2).

Contact regularisation: the softplus steepness kappa_s grows exponentially from kappa_start
to kappa_end over the first ``kappa_fraction`` of the epochs, then stays at kappa_end.
Curriculum: the parameter-anchor weight lambda falls linearly from lambda_start to 0 over the
first ``curriculum_epochs`` epochs. Adhesive targets: the loss's snap-in window falls
linearly from window_start to 0 over ``window_epochs`` (0: held).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Schedules:
    """The training schedules by epoch: the softplus steepness kappa_s [1/R], raised
    exponentially from ``kappa_start`` to ``kappa_end`` over the first ``kappa_fraction`` of
    the ``epochs``, and the curriculum weight lambda, falling linearly from ``lambda_start``
    to 0 over ``curriculum_epochs``."""

    epochs: int
    kappa_start: float = 1e3
    kappa_end: float = 1e5
    kappa_fraction: float = 0.25
    lambda_start: float = 1.0
    curriculum_epochs: int = 20
    window_start: float = 0.0
    window_epochs: int = 0

    def kappa(self, epoch: int) -> float:
        """Softplus steepness at 0-based ``epoch`` [1/R]."""
        span = max(1, round(self.kappa_fraction * self.epochs))
        frac = min(1.0, epoch / span)
        return float(
            math.exp(math.log(self.kappa_start) * (1 - frac) + math.log(self.kappa_end) * frac)
        )

    def lam(self, epoch: int) -> float:
        """Curriculum weight lambda at 0-based ``epoch``; 0 from curriculum_epochs on."""
        if self.curriculum_epochs <= 0:
            return 0.0
        return self.lambda_start * max(0.0, 1.0 - epoch / self.curriculum_epochs)

    def window(self, epoch: int) -> float:
        """The adhesive loss's snap-in window at 0-based ``epoch`` (a fraction of P*_max)."""
        if self.window_epochs <= 0:
            return self.window_start
        return self.window_start * max(0.0, 1.0 - epoch / self.window_epochs)
