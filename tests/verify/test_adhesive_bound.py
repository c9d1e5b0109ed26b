"""The adhesive check bounds its own error (issue 52): the two-grid estimate (the check on
M and on M / 2) is at least the check's true error, measured against the JKR closed form on
a Hertz asperity (the adhesive model is JKR there) and against a finer grid's solution; it
is printed beside the check's error and recorded."""

import math

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface.physics import CellSettings
from metainterface.verify.adhesive import bounded_check, solve_adhesive

W = 4.2e-5  # w / (E* R): PDMS on glass at R = 0.5 mm


@pytest.fixture(scope="module")
def hertz():
    """A Hertz asperity (gamma = 2) and its JKR loading curve as the target, from the JKR
    closed form written here (F = P* L^2, R = 1, E* = 1)."""
    d = mi.Design(gamma=np.array([2.0]), h=np.array([0.0]), settings=CellSettings(n_asperities=1))
    from metainterface.validation.heightmap import height_map

    side = height_map(d, 16).cell_side
    top = float(mi.Independent(adhesion=W).model_curve(d).p_star_max)
    p = np.linspace(0, top, 64)[1:]
    f = p * side**2
    q = 3 * math.pi * W
    a = ((f + q + np.sqrt(6 * math.pi * W * f + q * q)) / (4 / 3)) ** (1 / 3)
    return d, mi.Target(p_star=p, alpha=math.pi * a * a / side**2, name="hertz")


def _error(alpha, p, target):
    t = np.interp(p, target.p_star, target.alpha)
    return float(np.linalg.norm(alpha - t) / np.linalg.norm(t))


@pytest.mark.parametrize("grid", [64, pytest.param(128, marks=pytest.mark.long)])
def test_the_bound_holds_against_jkr_and_a_finer_grid(hertz, grid):
    design, target = hertz
    model = mi.Independent(adhesion=W)
    b = bounded_check(design, target, model, grid=grid, loads=6, max_error=0.02)
    assert b.grid == grid and b.grids == (grid // 2, grid)
    s = b.solved
    # the model is JKR on a Hertz asperity: its curve error here is the interpolation's
    # (the 63-point target read linearly between its points: ~1e-4)
    assert _error(s.alpha_model, s.p_star, target) < 1e-3
    true = _error(s.alpha_bem, s.p_star, target)
    assert 0 < true <= b.accuracy
    finer = solve_adhesive(design, target, model, grid=2 * grid, loads=6)
    inside = (s.p_star >= finer.p_star[0]) & (s.p_star <= finer.p_star[-1])
    near = np.interp(s.p_star[inside], finer.p_star, finer.alpha_bem)
    t = np.interp(s.p_star[inside], target.p_star, target.alpha)
    assert np.linalg.norm(s.alpha_bem[inside] - near) / np.linalg.norm(t) <= b.accuracy
    assert any("own error" in n for n in s.notes)


def test_the_check_records_and_prints_its_accuracy(hertz):
    design, target = hertz
    model = mi.Independent(adhesion=W)
    from metainterface.verify import bem_check

    check = bem_check(design, target, mi.Verify(grid=64, loads=4), model)
    assert check.accuracy > 0
    assert check.to_dict()["accuracy"] == check.accuracy
    assert "+-" in repr(check)


def test_a_bonded_solve_that_does_not_converge_is_an_error(hertz):
    from metainterface.validation import adhesive_bem as ab
    from metainterface.validation.heightmap import height_map

    design, _ = hertz
    hm = height_map(design, 32)
    z = torch.as_tensor(hm.heights)[None]
    with pytest.raises(mi.MetainterfaceError, match="did not converge"):
        ab.solve_jkr(z, hm.cell_side, torch.tensor([-float(z.mean()) - 0.01]), W, max_iter=2)
