"""The surrogate reads targets without a stiffness column (friction laws) as well as it can."""

import numpy as np
import torch

import metainterface as mi
from metainterface.inverse import pipeline, starts
from metainterface.inverse.targets import design_targets, target_features
from metainterface.surrogate.checkpoint import default_model_path, load_model


def _cells(count=6, seed=3):
    s = mi.CellSettings()
    gen = torch.Generator().manual_seed(seed)
    g = s.gamma_min + (s.gamma_max - s.gamma_min) * torch.rand(count, 9, generator=gen)
    h = s.delta_max * torch.rand(count, 9, generator=gen)
    return design_targets([f"c{i}" for i in range(count)], g.double(), h.double(), s)


def test_constant_training_inputs_are_set_to_their_constant():
    net, _, _ = load_model(default_model_path())
    t = _cells(1)[0]
    bare = mi.Target(p_star=t.p_star, alpha=t.alpha, name="bare")
    raw = target_features(bare)
    assert raw[128] > 0  # S* at P* = 0 by finite differences, where training always had 0
    x = starts.conform(net, raw)
    fixed = net.constant_inputs()
    assert fixed.sum() >= 1
    np.testing.assert_array_equal(x[0, fixed].numpy(), net.in_mean[fixed].double().numpy())
    np.testing.assert_array_equal(x[0, ~fixed].numpy(), raw[~fixed].double().numpy())


def test_cell_curves_without_stiffness_read_like_with_it():
    cells = _cells()
    bare = [mi.Target(p_star=t.p_star, alpha=t.alpha, name=t.name) for t in cells]
    opts = dict(effort=mi.Effort(refine=False, hedge=0, fallback=0), verify=False)
    with_s = np.array([r.error for r in mi.design(cells, **opts)])
    without = np.array([r.error for r in mi.design(bare, **opts)])
    # the same network on the same curves: a few % at most either way (before the constant
    # inputs were conformed, the median without stiffness was ~30 %)
    assert np.median(without) < 0.03
    assert np.median(without) < 2 * np.median(with_s) + 0.01


def test_views_of_a_law_never_make_the_prediction_worse():
    p = np.linspace(0.0, 2e-3, 40)
    law = mi.Target(p_star=p, alpha=0.05 * (1 - np.exp(-p / 6e-4)), name="law")
    views = starts.target_views(law)
    assert len(views) == len(starts.EXTEND_VIEWS) + len(starts.CUT_VIEWS)
    ends = sorted(v.p_star_max / law.p_star_max for v in views)
    assert ends[0] < 1 < ends[-1]
    for v in views:  # every view keeps the law where it overlaps
        k = min(v.p_star.size, p.size)
        np.testing.assert_allclose(v.alpha[:k], law.alpha[:k])
    net, settings, _ = load_model(default_model_path())
    g0, h0 = starts.predict(net, [law], settings)
    g1, h1, src = starts.best_views(net, [law], g0, h0, settings, mi.get_model("independent"), 128)
    assert src[0].startswith("surrogate")
    grid = pipeline.TargetGrid.from_curves([(law.p_star, law.alpha)], 128)
    e0 = pipeline.relative_error(g0, h0, settings, grid)
    e1 = pipeline.relative_error(g1, h1, settings, grid)
    assert float(e1[0]) <= float(e0[0])
