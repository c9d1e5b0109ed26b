"""The shipped envelope of the default cell is the one the code computes."""

import numpy as np

from metainterface.inverse import envelope
from metainterface.physics.cell import CellSettings


def test_shipped_envelope_is_the_computed_one():
    settings = CellSettings()
    key = envelope._key(settings, *envelope._DEFAULT)
    shipped = envelope._shipped(key)
    assert shipped is not None, f"{envelope.SHIPPED} missing or stale: regenerate it"
    computed = envelope.compute_envelope(settings, *envelope._DEFAULT)
    for a, b in zip(shipped[:3], computed[:3], strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-15)
    assert abs(shipped[3] - computed[3]) <= 1e-12 * computed[3]


def test_other_cells_are_computed_not_shipped():
    other = CellSettings(gamma_max=3.5)
    assert envelope._shipped(envelope._key(other, *envelope._DEFAULT)) is None
    envelope._envelope.cache_clear()
    grid, lo, hi, reach = envelope._envelope(other, 50, 0, 32)
    assert grid.shape == lo.shape == hi.shape == (32,)
    assert np.all(lo[1:] <= hi[1:]) and reach > 0
