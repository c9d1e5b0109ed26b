"""Data made for the tests and benchmarks (never downloaded): laws near the edge of reach."""

from __future__ import annotations

import numpy as np

from metainterface.units.reach import alpha_bounds


def borderline_laws(
    count: int, seed: int, points: int = 16, smallest: float = 0.1
) -> list[tuple[np.ndarray, np.ndarray]]:
    """``count`` power laws alpha = top (P*/P*_max)^m, each as (P*, alpha) of ``points``
    samples, whose top point lies from a little below the exact pointwise bounds
    (:func:`~metainterface.units.reach.alpha_bounds`) to a little above them: where two
    reach tests that differ are most likely to disagree. P*_max is drawn in
    [smallest, 1] x the largest pressure any cell reaches; m in [0.3, 1.2]."""
    rng = np.random.default_rng(seed)
    _, _, reach = alpha_bounds(np.array([1e-3]))
    out = []
    for _ in range(count):
        p_max = reach * rng.uniform(smallest, 1.0)
        p = np.linspace(p_max / 25, p_max, points)
        lo, hi, _ = alpha_bounds(p)
        top = lo[-1] + rng.uniform(-0.2, 1.2) * (hi[-1] - lo[-1])
        out.append((p, top * (p / p_max) ** rng.uniform(0.3, 1.2)))
    return out
