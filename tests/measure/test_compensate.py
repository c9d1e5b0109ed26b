"""The designed -> made map and the pre-distorted print, on made parts given in closed form
(no scan): the map is recovered exactly, and the compensated print, made by it, meets the
target within the printer's bounds."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from made_parts import example

from metainterface.measure.compensate import PrintMap, compensate, fit_map
from metainterface.measure.predict import target_of
from metainterface.physics.grid_error import grid_curve_error


@pytest.fixture(scope="module")
def design():
    return example()


def _made(design, shift, scale, gamma_bias, h_bias):
    """A registration as ``register`` reports it: made (gamma, h), h aligned on the mean."""
    h0 = design.h - design.h.min()
    h = scale * h0 + h_bias
    h = h - h.mean() + h0.mean()
    gamma = design.gamma + shift + gamma_bias
    return SimpleNamespace(gamma=gamma, h=h, seen=np.ones(design.n_asperities, dtype=int))


def test_the_map_is_recovered(design):
    n = design.n_asperities
    gamma_bias = np.zeros(n)
    gamma_bias[3] = 0.05
    h_bias = np.zeros(n)
    h_bias[5] = 0.1 * design.delta_max
    reg = _made(design, 0.2, 0.9, gamma_bias, h_bias)
    pmap = fit_map([(design, reg)])
    # the map reproduces the made part from the design (heights up to a common offset)
    g, h = pmap.made(design.gamma, design.h)
    np.testing.assert_allclose(g, reg.gamma, atol=1e-12)
    np.testing.assert_allclose(h - h.mean(), reg.h - reg.h.mean(), atol=1e-12)
    assert pmap.gamma_shift == pytest.approx(0.2 + 0.05 / n)
    assert pmap.h_scale == pytest.approx(0.9, abs=0.02)


def test_the_print_made_by_the_map_meets_the_target(design):
    pmap = PrintMap(
        gamma_shift=0.15,
        h_scale=0.85,
        gamma_bias=np.zeros(design.n_asperities),
        h_bias=np.zeros(design.n_asperities),
    )
    comp = compensate(design, pmap)
    s = design.settings
    assert (comp.printed.gamma >= s.gamma_min).all()
    assert (comp.printed.gamma <= s.gamma_max).all() and (comp.printed.h >= 0).all()
    # the design's first asperity sits on the lower bound: it cannot be printed 0.15 lower
    assert comp.printed.gamma[0] == pytest.approx(s.gamma_min, abs=0.01)
    g, h = pmap.made(comp.printed.gamma, comp.printed.h)
    err, cover = grid_curve_error(g[None], h[None], design.settings, target_of(design))
    assert err[0] == pytest.approx(comp.error_family, abs=1e-9)
    assert err[0] < 0.01 and cover[0] == 1.0
    # judged in BEM on the made cell (power laws only here): as good as the family says
    assert comp.error_after < 0.01
    assert comp.error_before > 0.05
