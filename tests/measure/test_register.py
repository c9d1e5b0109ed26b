"""Registration and the asperity fit recover errors injected into scans of made parts,
written from the profile's closed form (made_parts.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from made_parts import Made, example, made_cell, scan_of

import metainterface as mi
from metainterface.measure.register import register
from metainterface.measure.scan import from_array
from metainterface.measure.surface import lattice_surface
from metainterface.validation import height_map

R = 0.5e-3


@pytest.fixture(scope="module")
def design():
    return example()


def _register(design, z, dx, **kw):
    return register(from_array(z * R, pixel_size=dx * R, radius=R, **kw), design)


def test_surface_is_the_designed_height_map(design):
    hm = height_map(design, grid=96)
    x = np.arange(96) * hm.spacing
    u, v = np.meshgrid(x, x)
    z = lattice_surface(u, v, -(design.h - design.h.min()), design.gamma, design.settings)
    np.testing.assert_allclose(z, hm.heights, atol=1e-12)


def test_test_scans_are_the_designed_map(design):
    # the reference surface of these tests agrees with the package's designed map
    hm = height_map(design, grid=96)
    x = np.arange(96) * hm.spacing
    u, v = np.meshgrid(x, x)
    np.testing.assert_allclose(made_cell(u, v, design, Made()), hm.heights, atol=1e-12)


def test_print_errors_tilt_rotation_noise_missing(design):
    made = Made(gamma_shift=0.15, h_scale=0.85)
    tilt = (0.004, -0.002)  # ~0.2 degrees
    noise = 2e-4  # 0.1 um at R = 0.5 mm
    z, dx = scan_of(
        design, made, cells=3, points=240, theta_deg=2.0, tilt=tilt, noise=noise, missing=0.02
    )
    reg = _register(design, z, dx)
    gamma, h = made.params(design)
    assert reg.lattice.to_dict()["rotation_deg"] == pytest.approx(2.0, abs=0.02)
    assert reg.lattice.scale == pytest.approx(1.0, abs=1e-3)
    # the tilt to within what tilts the scan by no more than the heights' tolerance below
    # (1 % of Delta_max from edge to edge); white noise alone would allow ~1e-6
    side = dx * max(z.shape)
    np.testing.assert_allclose(reg.tilt, tilt, atol=0.01 * design.delta_max / side)
    np.testing.assert_allclose(reg.gamma, gamma, atol=0.01)
    h_aligned = h - h.mean() + (design.h - design.h.min()).mean()
    np.testing.assert_allclose(reg.h, h_aligned, atol=0.01 * design.delta_max)
    assert (reg.seen == 9).all()  # 3 x 3 cells, every asperity in each
    assert (reg.gamma_spread < 0.01).all()
    # the systematic errors read as they were made: offsets 15 % lower, exponents + 0.15
    dh = reg.h - reg.h.mean()
    dh_design = design.h - design.h.mean()
    assert np.polyfit(dh_design, dh, 1)[0] == pytest.approx(0.85, abs=0.01)
    assert np.mean(reg.gamma - design.gamma) == pytest.approx(0.15, abs=0.005)


def test_levelling_is_not_biased_by_the_pattern(design):
    # a plain least-squares plane through a patterned, partly covered scan is tilted by
    # the pattern; the lattice fit's plane is not
    z, dx = scan_of(design, Made(), cells=1.6, points=160, tilt=(0.003, 0.0))
    reg = _register(design, z, dx)
    y, x = np.mgrid[: z.shape[0], : z.shape[1]] * dx
    plain = np.linalg.lstsq(
        np.stack([x.ravel(), y.ravel(), np.ones(x.size)], 1), z.ravel(), rcond=None
    )[0][:2]
    ours = np.abs(reg.tilt - (0.003, 0.0)).max()
    assert ours < 5e-4
    assert np.abs(plain - (0.003, 0.0)).max() > 5 * ours


def test_shrunk_and_offset_lattice(design):
    z, dx = scan_of(design, Made(), cells=2.2, points=200, offset=(0.41, 0.77), shrink=0.98)
    reg = _register(design, z, dx)
    assert reg.lattice.scale == pytest.approx(0.98, abs=1e-3)
    np.testing.assert_allclose(reg.gamma, design.gamma, atol=0.01)


def test_partial_cell(design):
    # 0.7 of a unit cell: some asperities are seen, the others keep the design's values
    z, dx = scan_of(design, Made(gamma_shift=0.1), cells=0.7, points=120, offset=(0.05, 0.05))
    reg = _register(design, z, dx)
    seen = reg.seen > 0
    assert 1 <= seen.sum() < 9
    np.testing.assert_allclose(reg.gamma[seen], design.gamma[seen] + 0.1, atol=0.01)
    np.testing.assert_array_equal(reg.gamma[~seen], design.gamma[~seen])


def test_rounded_tips_read_as_a_larger_tip_radius(design):
    a_max = design.settings.a_max
    made = Made(tip_rho=5.0, tip_r0=0.45 * a_max)
    z, dx = scan_of(design, made, cells=1.0, points=240)
    reg = _register(design, z, dx)
    # within the fitting radius (0.35 a_max) the made tip is the cap of radius 5 R
    np.testing.assert_allclose(reg.tip_radius, 5.0, rtol=0.02)
    sharp = design.gamma < 2.4
    assert (reg.tip_radius_design[sharp] < 2.5).all()


def test_scan_smaller_than_one_lattice_cell(design):
    z, dx = scan_of(design, Made(), cells=0.25, points=60)
    with pytest.raises(mi.MetainterfaceError, match="smaller than one lattice cell"):
        _register(design, z, dx)


def test_scan_without_the_lattice(design):
    rng = np.random.default_rng(1)
    side = design.settings.cell_side
    z = rng.normal(0, 0.01, (150, 150))
    with pytest.raises(mi.MetainterfaceError, match="does not show this design's lattice"):
        _register(design, z, 2 * side / 150)


def test_other_design_does_not_register(design):
    # a lattice of another pitch (a design for a deeper indentation at the same R)
    other = mi.Design(gamma=design.gamma, h=design.h, settings=design.settings.with_(delta_max=0.2))
    z, dx = scan_of(other, Made(), cells=2.0, points=200)
    assert not math.isclose(other.settings.cell_side, design.settings.cell_side, rel_tol=0.3)
    with pytest.raises(mi.MetainterfaceError, match="does not show this design's lattice"):
        _register(design, z, dx)
