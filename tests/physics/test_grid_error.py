"""The one curve error on the target's 128-point grid, times a BEM ratio
(``physics.grid_error``), against closed forms: a target that is the cell's own curve
scores 0, a constant ratio c scores |c - 1|, a target past the cell's reach scores the
missed share of its load range, and a ratio that is not finite counts as 1."""

from importlib.resources import files

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface.physics.grid_error import (
    ERROR_POINTS,
    error_grid,
    grid_curve_error,
    ratio_on_grid,
)
from metainterface.physics.registry import get_model


@pytest.fixture(scope="module")
def cell():
    """The packaged example's cell and its own exact curve on 4001 points up to P*_max."""
    d = mi.Design.load(str(files("metainterface") / "examples" / "example_design.json"))
    gamma, h = (np.atleast_2d(v.numpy()) for v in d.tensors(torch.float64))
    model = get_model(None)
    with torch.no_grad():
        g, hh = torch.as_tensor(gamma), torch.as_tensor(h)
        _, p_max = model.alpha_at(g, hh, d.settings, torch.zeros(1, 2, dtype=torch.float64))
        p = torch.linspace(0.0, float(p_max[0]), 4001, dtype=torch.float64)[None]
        alpha, _ = model.alpha_at(g, hh, d.settings, p, exact=True)
    return d, gamma[0], h[0], p[0].numpy(), alpha[0].numpy()


def test_error_grid_is_128_uniform_points_with_zero_below_the_first():
    grid, ref = error_grid((np.array([0.5, 1.0, 2.0]), np.array([0.1, 0.2, 0.4])))
    assert ERROR_POINTS == 128 and grid.shape == ref.shape == (128,)
    assert grid[0] == 0.0 and grid[-1] == 2.0 and np.allclose(np.diff(grid), 2.0 / 127)
    assert ref[0] == 0.0 and ref[-1] == pytest.approx(0.4)


def test_ratio_on_grid_holds_the_ends_and_ignores_non_finite_ratios():
    grid = np.linspace(0.0, 1.0, 5)
    r = ratio_on_grid(grid, np.array([0.25, 0.75]), np.array([1.1, 1.3]))
    assert r.tolist() == pytest.approx([1.1, 1.1, 1.2, 1.3, 1.3])
    r = ratio_on_grid(grid, np.array([0.25, 0.75]), np.array([np.inf, np.nan]))
    assert r.tolist() == [1.0] * 5


def test_own_curve_scores_zero_and_a_constant_ratio_scores_its_offset(cell):
    d, gamma, h, p, a = cell
    err, cov = grid_curve_error(gamma, h, d.settings, (p, a))
    # the target is the cell's own exact curve, read linearly between 4001 points: the
    # interpolation error of a smooth curve at that spacing is far below 1e-5
    assert err[0] < 1e-5 and cov[0] == pytest.approx(1.0)
    loads = np.linspace(0.1, 0.9, 6) * p[-1]
    err, _ = grid_curve_error(gamma, h, d.settings, (p, a), ratio=(loads, np.full(6, 1.03)))
    assert err[0] == pytest.approx(0.03, abs=1e-5)  # fit = ||0.03 a|| / ||a||
    # an infinite ratio at one load counts as 1 there, not as a huge error nearby
    ratio = np.array([np.inf, 1.0, 1.0, 1.0, 1.0, 1.0])
    err, _ = grid_curve_error(gamma, h, d.settings, (p, a), ratio=(loads, ratio))
    assert err[0] < 1e-5


def test_a_target_past_the_cells_reach_charges_the_missed_range(cell):
    d, gamma, h, p, a = cell
    # the same curve, then 50 % more load range the cell cannot reach
    p_long = np.concatenate([p, p[-1] * np.linspace(1.001, 1.5, 50)])
    a_long = np.concatenate([a, a[-1] * np.linspace(1.0, 1.2, 50)])
    err, cov = grid_curve_error(gamma, h, d.settings, (p_long, a_long))
    assert cov[0] == pytest.approx(1 / 1.5)
    # fit over the reached grid points is ~0 (the own curve): the error is 1 - coverage
    assert err[0] == pytest.approx(1 - 1 / 1.5, abs=1e-4)


def test_batched_rows_score_independently(cell):
    d, gamma, h, p, a = cell
    g2 = np.stack([gamma, np.clip(gamma + 0.2, None, d.settings.gamma_max)])
    h2 = np.stack([h, h])
    err, _ = grid_curve_error(g2, h2, d.settings, (p, a))
    one, _ = grid_curve_error(g2[1], h2[1], d.settings, (p, a))
    assert err[0] < 1e-5 and err[1] == pytest.approx(one[0], rel=1e-12) and err[1] > 1e-3
