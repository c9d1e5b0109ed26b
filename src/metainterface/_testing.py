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


def held_back_cell(seed: int, settings=None) -> tuple[np.ndarray, np.ndarray]:
    """The held-back adhesive cell of ``seed``: gamma (9,) in [1.8, 4.0] and h (9,) [R] in
    [0, 0.6] Delta_max, its lowest offset 0 (``settings``: default ``CellSettings()``)."""
    from metainterface.physics.cell import CellSettings

    s = settings or CellSettings()
    rng = np.random.default_rng(seed)
    g = rng.uniform(1.8, 4.0, 9)
    h = rng.uniform(0, 0.6, 9) * s.delta_max
    return g, h - h.min()


def adhesive_cell_curve(
    adhesion: float, seed: int = 11, rows: int = 24, top: float = 0.95
) -> tuple[np.ndarray, np.ndarray]:
    """A held-back adhesive cell's loading curve under a rising force, (P*, alpha) (rows,).

    The cell: :func:`held_back_cell` of ``seed`` (9 asperities of the paper's space),
    under ``Independent(adhesion)`` (w / (E* R)).
    P* runs from 0 to ``top`` times the largest pressure it reaches. Each row is the exact
    law at its load (``alpha_at(exact=True)``: Newton on P*(Delta), no interpolation in a
    sweep, which smears a snap-in between its samples), and the zero-load row the state
    where the rising force first holds zero load (the end of the snap-in's plateau at P* = 0,
    as the package defines F_0): a cell whose first snap-in pulls a second tip into contact
    at zero force has both in contact there.
    """
    import torch

    from metainterface.physics.cell import CellSettings
    from metainterface.physics.models import Independent

    s = CellSettings()
    g, h = held_back_cell(seed, s)
    model = Independent(adhesion=adhesion)
    gt, ht = torch.as_tensor(g)[None], torch.as_tensor(h)[None]
    with torch.no_grad():
        p_max = float(model.sweep(gt, ht, s, n_delta=2049).p_star[0, -1])
        p = np.linspace(0, top * p_max, rows)
        a = model.alpha_at(gt, ht, s, torch.as_tensor(p)[None], exact=True)[0][0].numpy()
    return p, a
