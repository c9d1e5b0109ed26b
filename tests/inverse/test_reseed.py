"""Asperities that never touch over the target's range are re-seeded and put to use."""

from dataclasses import replace

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface.inverse.pipeline import DesignResult
from metainterface.inverse.refine import RefineSettings
from metainterface.inverse.reseed import idle_in_range, reseed
from metainterface.inverse.targets import design_targets

S = mi.CellSettings()
MODEL = mi.get_model("independent")


def _design():
    gamma = torch.linspace(2.0, 3.5, 9, dtype=torch.float64)[None]
    h = torch.linspace(0.0, 0.6 * S.delta_max, 9, dtype=torch.float64)[None]
    return gamma, h


def test_idle_in_range_uses_the_targets_largest_pressure():
    gamma, h = _design()
    h_up = h.clone()
    h_up[0, -1] = 3 * S.delta_max  # never touches at all
    sw = MODEL.sweep(gamma, h, S, n_delta=64)
    p_mid = sw.p_star[:, 32]  # the pressure at about half Delta_max
    idle, d_l = idle_in_range(gamma, h_up, S, sw.p_star[:, -1], MODEL)
    assert idle[0].tolist() == [False] * 8 + [True]
    assert float(d_l[0]) <= S.delta_max * (1 + 1e-9)
    # over a range that ends at half Delta_max the upper asperities do not touch either
    idle_mid, d_mid = idle_in_range(gamma, h, S, p_mid, MODEL)
    assert float(d_mid[0]) < 0.6 * S.delta_max
    assert idle_mid[0, -1] and not idle_mid[0, 0]


def test_a_design_with_an_idle_asperity_is_re_seeded_no_worse():
    gamma, h = _design()
    (target,) = design_targets(["cell"], gamma, h, S, points=129)
    h_bad = h.clone()
    h_bad[0, -1] = 3 * S.delta_max
    from metainterface.inverse.losses import TargetGrid, relative_error

    grid = TargetGrid.from_curves([(target.p_star, target.alpha)], 128)
    err = float(relative_error(gamma, h_bad, S, grid, MODEL)[0])
    r = DesignResult(
        target=target,
        method="surrogate",
        gamma=gamma[0].numpy(),
        h=h_bad[0].numpy(),
        error=err,
        seconds=0.0,
        initial_error=err,
        settings=S,
    )
    (out,) = reseed(
        [r], RefineSettings(stages=2, steps_per_stage=3, polish_iterations=30), None, MODEL, seed=0
    )
    assert out.error <= err
    assert out.h.max() - out.h.min() <= S.delta_max  # all nine carry load again
    assert any("re-seeded" in n for n in out.notes)
    # a design without idle asperities is left alone
    full = DesignResult(target, "surrogate", gamma[0].numpy(), h[0].numpy(), 0.0, 0.0, 0.0, S)
    assert reseed([full], RefineSettings(), None, MODEL, seed=0)[0] is full
    assert np.all(np.isfinite(out.gamma))


def test_refine_settings_can_leave_the_re_seeding_out(monkeypatch):
    # a scale search's quick candidates rank scales: they are not re-seeded (the chosen
    # scale's full design is)
    import metainterface.inverse.reseed as reseed_module
    from metainterface.inverse import pipeline
    from metainterface.scaling.choose import QUICK

    assert RefineSettings().reseed and not QUICK.reseed
    monkeypatch.setattr(reseed_module, "reseed", lambda *a, **k: pytest.fail("re-seeded"))
    quick = RefineSettings(stages=1, steps_per_stage=1, iterations=2, polish_iterations=0)
    target = mi.Target.builtin("bilinear")
    (r,) = pipeline.design([target], refine_settings=replace(quick, reseed=False))
    # refined a little, not re-seeded: no worse than its zero-shot start, and its error is
    # the design's own (recomputed from its shapes on the model)
    from metainterface.physics.cell import Design
    from metainterface.verify.correct import model_error

    assert r.error <= r.initial_error
    own = model_error(Design(gamma=r.gamma, h=r.h, settings=r.settings), target, r.model)
    assert r.error == pytest.approx(own, rel=1e-6)
    with pytest.raises(pytest.fail.Exception, match="re-seeded"):
        pipeline.design([target], refine_settings=quick)
