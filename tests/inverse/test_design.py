"""Inverse design: targets, batched L-BFGS, refinement meets realisable targets, the CLI."""

import numpy as np
import pytest
import torch

from metainterface.errors import MetainterfaceError
from metainterface.inverse import builtin_target, design, target_from_csv
from metainterface.inverse.lbfgs import minimize
from metainterface.inverse.params import FULL
from metainterface.inverse.refine import RefineSettings
from metainterface.physics import CellSettings

S = CellSettings()
# a short polish too: the tests check what each option does, not the last digits of a design
FAST = RefineSettings(stages=3, steps_per_stage=2, iterations=20, polish_iterations=30)


def test_batched_lbfgs_rows_are_independent():
    a = torch.tensor([1.0, 2.0, 0.5], dtype=torch.float64)

    def rosen(x):
        return (a - x[:, 0]) ** 2 + 100 * (x[:, 1] - x[:, 0] ** 2) ** 2

    r = minimize(
        rosen,
        torch.zeros(3, 2, dtype=torch.float64),
        lr=1.0,
        max_iter=200,
        tol_change=1e-12,
        tol_loss=1e-14,
    )
    np.testing.assert_allclose(r.x, torch.stack([a, a**2], 1), atol=1e-4)


def test_lbfgs_stall_stops_only_the_stalled_row():
    # row 0 creeps down a nearly flat slope, row 1 is a plain quadratic
    def fun(x):
        creep = 1.0 + 1e-3 * torch.exp(-x[0, 0])
        return torch.stack([creep, ((x[1] - 3.0) ** 2).sum()])

    x0 = torch.zeros(2, 2, dtype=torch.float64)
    free = minimize(fun, x0, max_iter=60, tol_grad=0.0, tol_change=0.0, tol_loss=0.0, tol_stall=0.0)
    stalled = minimize(
        fun, x0, max_iter=60, tol_grad=0.0, tol_change=0.0, tol_loss=0.0, tol_stall=1e-3
    )
    assert stalled.x[0, 0] < free.x[0, 0]  # the creeping row stopped early ...
    np.testing.assert_allclose(stalled.x[1], [3.0, 3.0], atol=1e-6)  # ... the other did not


def test_parameterisation_round_trip():
    g = torch.tensor([[2.0, 3.0, 1.9, 3.9]], dtype=torch.float64)
    h = torch.tensor([[0.004, 0.0, 0.01, 0.002]], dtype=torch.float64)
    s4 = CellSettings(n_asperities=4)
    g2, h2 = FULL.to_design(FULL.from_design(g, h, s4), s4)
    order = torch.argsort(h, dim=-1)
    np.testing.assert_allclose(h2, h.gather(-1, order), atol=1e-9)
    np.testing.assert_allclose(g2, g.gather(-1, order), atol=1e-3)


def test_refinement_meets_a_realisable_target_unlike_the_training_categories():
    # a realisable target from a design with alternating shapes and even spacing
    from metainterface.inverse.targets import design_target_of

    t = design_target_of("alt", [1.8, 4.0] * 4 + [2.5], [k / 9 for k in range(9)], "test")
    r = design([t], "multistart", starts=4, seed=1, refine_settings=FAST)[0]
    assert r.error < 0.02 and r.error <= r.initial_error


def test_builtin_targets_and_csv_errors(tmp_path):
    for name in ("saturating", "bilinear", "linear"):
        t = builtin_target(name)
        assert t.p_star[0] == 0 and np.all(np.diff(t.p_star) > 0) and t.alpha[-1] > 0
    with pytest.raises(MetainterfaceError, match="unknown target 'wavy'"):
        builtin_target("wavy")
    cases = {
        "p_star,alpha\n0,0\n1e-4,0.01\n": "at least 3 points",
        "p_star,alpha\n0,0\n1e-4,nan\n2e-4,0.02\n": "row 2: alpha is not a finite",
        "p_star,alpha\n0,0\n2e-4,0.01\n1e-4,0.02\n": "row 3: p_star must be strictly increasing",
        "p_star,alpha\n0,0\n1e-4,-0.01\n2e-4,0.02\n": "row 2: alpha = -0.01 is negative",
        "pressure,alpha\n0,0\n1,1\n2,2\n": "missing column",
    }
    for text, msg in cases.items():
        f = tmp_path / "t.csv"
        f.write_text(text)
        with pytest.raises(MetainterfaceError, match=msg):
            target_from_csv(f)


def test_hedge_starts_are_refined_with_the_zero_shot_one():
    t = [builtin_target("bilinear")]
    pure = design(t, "surrogate", refine_settings=FAST)[0]
    hedged = design(t, "surrogate", hedge=3, seed=2, refine_settings=FAST)[0]
    assert pure.start == 0 and 0 <= hedged.start <= 3
    assert hedged.initial_error == pytest.approx(pure.initial_error)  # the zero-shot row's
    assert hedged.error < 0.05


def test_hedges_run_only_where_the_zero_shot_design_misses(monkeypatch):
    from metainterface.inverse import pipeline

    t = [builtin_target("saturating"), builtin_target("linear")]
    pure = design(t, "surrogate", refine_settings=FAST)
    batches = []
    real = pipeline._design

    def spy(targets, *args, **kw):
        batches.append(([x.name for x in targets], kw["hedge"], kw.get("hedges_only", False)))
        return real(targets, *args, **kw)

    monkeypatch.setattr(pipeline, "_design", spy)
    # saturating's refined prediction is within 1 %, linear's is not
    gated = design(t, "surrogate", hedge=3, refine_settings=FAST, hedge_error=0.01)
    assert pure[0].error < 0.01 < pure[1].error
    assert batches == [(["saturating", "linear"], 0, False), (["linear"], 3, True)]
    assert gated[0].error == pure[0].error and gated[0].start == 0
    assert gated[1].error <= pure[1].error and 0 <= gated[1].start <= 3
    assert gated[1].initial_error == pure[1].initial_error  # the zero-shot row's
    batches.clear()
    design(t, "surrogate", hedge=3, refine_settings=FAST, hedge_error=0.0)
    assert batches == [(["saturating", "linear"], 3, False)]  # one batch, as all need them


def test_fallback_multistart_for_targets_the_surrogate_misses():
    # an exactly linear law is far from every training curve: the surrogate's refined design
    # misses it, so the fallback multistart runs and the better design is kept
    t = [builtin_target("linear"), builtin_target("saturating")]
    pure = design(t, "surrogate", refine_settings=FAST)
    multi = design(t[:1], "multistart", starts=4, seed=5, refine_settings=FAST)[0]
    both = design(t, "surrogate", fallback=4, seed=5, refine_settings=FAST)
    assert pure[0].error > 0.02 and pure[1].error < 0.02
    assert both[0].error == pytest.approx(min(pure[0].error, multi.error), abs=1e-12)
    assert both[0].fallback == (multi.error < pure[0].error) and both[0].method == "surrogate"
    assert not both[1].fallback and both[1].error == pytest.approx(pure[1].error)


def test_random_starts_are_nested_and_the_same_for_every_target():
    from metainterface.inverse.starts import random_starts

    g8, h8 = random_starts(8, 3, S, seed=5, param=FULL)
    g3, h3 = random_starts(3, 1, S, seed=5, param=FULL)
    assert g8.shape == (24, 9)
    torch.testing.assert_close(g8[:8], g8[16:])  # target 0 and target 2
    torch.testing.assert_close(g8[:3], g3)  # the first 3 of 8 starts are the 3 starts
    torch.testing.assert_close(h8[:3], h3)
    assert float(g8.min()) >= S.gamma_min and float(g8.max()) <= S.gamma_max
    assert float(h8.min()) >= 0 and float(h8.max()) <= S.delta_max


@pytest.mark.parametrize("method", ["multistart", "surrogate"])
def test_a_targets_design_does_not_depend_on_the_batch(method):
    sat, bil = builtin_target("saturating"), builtin_target("bilinear")
    kw = dict(starts=3, hedge=2, refine_settings=FAST)
    both = design([sat, bil], method, **kw)
    alone = design([bil], method, **kw)[0]
    np.testing.assert_array_equal(both[1].gamma, alone.gamma)
    np.testing.assert_array_equal(both[1].h, alone.h)
    assert both[1].error == alone.error


def test_hedge_starts_jitter_the_zero_shot_design():
    from metainterface.inverse.starts import JITTER_GAMMA, hedge_starts, random_starts

    g0 = torch.full((2, 9), 3.0, dtype=torch.float64)
    h0 = torch.linspace(0, 0.5 * S.delta_max, 9, dtype=torch.float64).expand(2, 9)
    g, h = hedge_starts(g0, h0, 5, S, seed=0)
    assert g.shape == h.shape == (2, 5, 9)
    # three jittered copies around the zero-shot design, then the first two random starts
    spread = (g[:, :3] - 3.0).std()
    assert 0.3 * JITTER_GAMMA * 2.2 < float(spread) < 3 * JITTER_GAMMA * 2.2
    g_r, h_r = random_starts(2, 1, S, seed=0, param=FULL)
    torch.testing.assert_close(g[0, 3:], g_r)
    torch.testing.assert_close(h[1, 3:], h_r)
    assert float(h.min()) >= 0


def test_a_start_on_the_bounds_can_still_move():
    # gammas on both bounds and all gaps 0, what the surrogate outputs for the linear law:
    # within 1e-4 of the bounds the sigmoid and softplus were flat and L-BFGS never moved
    from metainterface.inverse.losses import TargetGrid, relative_error
    from metainterface.inverse.refine import refine

    target = builtin_target("linear")
    grid = TargetGrid.from_curves([(target.p_star, target.alpha)], 128)
    gamma = torch.tensor([[1.8, 1.8, 1.8, 4.0, 4.0, 1.8, 4.0, 4.0, 4.0]], dtype=torch.float64)
    h = torch.zeros(1, 9, dtype=torch.float64)
    h[0, -1] = 1.1 * S.delta_max
    before = float(relative_error(gamma, h, S, grid))
    raw = refine(FULL.from_design(gamma, h, S), S, grid, FAST)
    after = float(relative_error(*FULL.to_design(raw, S), S, grid))
    assert before > 1.0 and after < 0.15
