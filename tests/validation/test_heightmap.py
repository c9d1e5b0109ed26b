"""The periodic height map: layout (k // n, k % n), profile, anchoring, tips up."""

import numpy as np
import pytest

from metainterface.errors import MetainterfaceError
from metainterface.physics import CellSettings, Design
from metainterface.validation import cell_height_map, height_map, owner_map

S9 = CellSettings()


def lone_high_asperity(k: int) -> Design:
    """Nine asperities; only asperity k reaches the top (h = 0.001), the rest sit 0.01 lower."""
    h = np.full(9, 0.011)
    h[k] = 0.001
    return Design(gamma=np.linspace(1.8, 4.0, 9), h=h, settings=S9)


def test_owner_map_follows_the_lattice():
    expected = np.arange(9).reshape(3, 3).repeat(2, axis=0).repeat(2, axis=1)
    np.testing.assert_array_equal(owner_map(3, 6), expected)


@pytest.mark.parametrize("k", [0, 1, 5, 7])
def test_tips_up_at_the_lattice_centres(k):
    # The sign check: the highest point is the tip of the highest asperity, at its lattice
    # centre (row k // n along y, column k % n along x), never a cell corner.
    hm = height_map(lone_high_asperity(k), 96)
    z = hm.heights
    m = 96 // 3
    i, j = np.unravel_index(np.argmax(z), z.shape)
    assert (i, j) == ((k // 3) * m + m // 2, (k % 3) * m + m // 2)
    assert z.max() == 0.0  # anchored: min h -> 0, tips up
    assert (z <= 0).all()
    # every lattice cell peaks at its centre and is lowest at its corners
    for q in range(9):
        block = z[(q // 3) * m : (q // 3 + 1) * m, (q % 3) * m : (q % 3 + 1) * m]
        assert np.unravel_index(np.argmax(block), block.shape) == (m // 2, m // 2)
        assert block[0, 0] == block.min()


def test_profile_is_the_power_law_of_the_owner():
    d = lone_high_asperity(4)
    hm = height_map(d, 192)
    g, h = d.gamma[4], d.h[4] - d.h.min()
    centre = 192 // 2  # asperity 4 is the middle cell; its centre is a grid point
    for steps in (0, 5, 20, 31):
        r = steps * hm.spacing
        expected = -(h + r**g / 2)  # c = 1 / (2 R^(gamma - 1)), R = 1
        assert hm.heights[centre, centre + steps] == pytest.approx(expected, rel=1e-12)
        assert hm.heights[centre + steps, centre] == pytest.approx(expected, rel=1e-12)
    assert hm.spacing * hm.grid == pytest.approx(S9.cell_side)
    assert hm.owner[centre, centre] == 4


def test_radius_scales_the_shape_constant():
    s = CellSettings(n_asperities=1, radius=2.0, delta_max=0.04)
    hm = cell_height_map(np.array([3.0]), np.array([0.0]), s, 64)
    r = 10 * hm.spacing
    assert hm.heights[32, 42] == pytest.approx(-(r**3) / (2 * 2.0**2), rel=1e-12)


def test_default_grid_and_bad_grids():
    assert height_map(lone_high_asperity(0)).grid == 768
    for bad in (100, 3, 0):
        with pytest.raises(MetainterfaceError, match="multiple of the lattice side n = 3"):
            height_map(lone_high_asperity(0), bad)
    with pytest.raises(MetainterfaceError, match="length n_asperities = 9"):
        cell_height_map(np.ones(4) * 2, np.zeros(4), S9, 96)
