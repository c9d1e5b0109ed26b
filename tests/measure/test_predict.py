"""The made part's law from its scan, held against an independent BEM of the made cell
(the closed-form made surface, made_parts.py), and the next print's correction: the
compensated design, made with the same errors, meets the target."""

from __future__ import annotations

import json

import numpy as np
import pytest
from made_parts import Made, example, made_cell, scan_of

import metainterface as mi
from metainterface.measure.predict import target_of
from metainterface.physics.grid_error import grid_curve_error
from metainterface.validation import owner_map, solve_path

st = pytest.importorskip("SurfaceTopography")

R = 0.5e-3
#: A plausible print: offsets 15 % lower, exponents 0.15 higher, tilted, noisy, 2 degrees
#: rotated, 1 % of the points missing.
MADE = Made(gamma_shift=0.15, h_scale=0.85)
SCAN = dict(cells=3, theta_deg=2.0, tilt=(0.004, -0.002), noise=2e-4, missing=0.01)


@pytest.fixture(scope="module")
def design():
    return example()


def _write(z, dx, path):
    ny, nx = z.shape
    topo = st.Topography(np.ma.masked_invalid((z * R).T), (nx * dx * R, ny * dx * R), unit="m")
    getattr(topo, "to_" + path.suffix[1:])(str(path))
    return path


@pytest.fixture(scope="module")
def measured(design, tmp_path_factory):
    z, dx = scan_of(design, MADE, points=288, **SCAN)
    path = _write(z, dx, tmp_path_factory.mktemp("scan") / "made.x3p")
    return mi.measure(
        path,
        design,
        radius="0.5mm",
        modulus="2MPa",
        shear_strength="0.5MPa",
        area="1cm^2",
        progress=False,
    )


@pytest.fixture(scope="module")
def compensation(measured):
    """``measured.compensate()``, made once: three tests look at the same correction."""
    return measured.compensate()


@pytest.mark.long
def test_bem_of_the_scan_is_the_bem_of_the_made_cell(design, measured):
    p = measured.prediction
    m = p.cell.heights.shape[0]
    s = design.settings
    u = np.arange(m) * s.cell_side / m
    uu, vv = np.meshgrid(u, u)
    exact = made_cell(uu, vv, design, MADE)
    ref = solve_path(exact - exact.max(), s.cell_side, p.p_star, owner_map(3, m), 9)
    np.testing.assert_allclose(p.alpha_bem, ref.alpha, rtol=0.02)
    assert p.cell.filled == 0.0


@pytest.mark.long
def test_made_error_is_the_made_cells(design, measured):
    # the error of the made part's closed-form model, against the design's target
    gamma, h = MADE.params(design)
    exact, _ = grid_curve_error(gamma[None], h[None], design.settings, target_of(design))
    assert measured.prediction.error_fit == pytest.approx(exact[0], rel=0.03)
    assert measured.error == pytest.approx(exact[0], abs=0.01)
    assert measured.error > 0.05  # far from the design's promise
    assert measured.prediction.error_design < 0.001
    shares = measured.prediction.share
    assert shares.sum() == pytest.approx(1.0)


@pytest.mark.long
def test_compensated_design_made_with_the_same_errors_meets_the_target(design, compensation):
    comp = compensation
    assert comp.pmap.gamma_shift == pytest.approx(0.15, abs=0.01)
    assert comp.pmap.h_scale == pytest.approx(0.85, abs=0.02)
    printed = comp.printed
    s = design.settings
    assert (printed.gamma >= s.gamma_min).all() and (printed.gamma <= s.gamma_max).all()
    gamma, h = MADE.params(printed)  # printed, then made as before
    err, cover = grid_curve_error(gamma[None], h[None], design.settings, target_of(design))
    assert err[0] < 0.01 and cover[0] == 1.0
    assert comp.error_before > 0.05 and comp.error_after < 0.01


@pytest.mark.long
def test_files(design, measured, compensation, tmp_path):
    comp = compensation
    measured.write(tmp_path, compensate=comp)
    summary = json.loads((tmp_path / "measured.json").read_text())
    assert summary["asperities_fitted"] == 81
    assert summary["lattice"]["rotation_deg"] == pytest.approx(2.0, abs=0.05)
    rows = summary["asperities"]
    # h deviations in um: 15 % of each designed offset above the mean, less below it
    h_design = np.array([r["h_design_um"] for r in rows])
    dev = np.array([r["h_deviation_um"] for r in rows])
    np.testing.assert_allclose(dev, -0.15 * (h_design - h_design.mean()), atol=0.1)
    cells = summary["cells"]
    assert len(cells) == 81
    for row in rows:  # each asperity's made height is the mean over its cells
        mine = [c["h_um"] for c in cells if c["k"] == row["k"]]
        assert np.mean(mine) == pytest.approx(row["h_made_um"], abs=1e-6)
    lines = (tmp_path / "bem.csv").read_text().splitlines()
    assert json.loads(lines[0][2:])["settings"]["command"] == "measure"  # provenance
    header = lines[1].split(",")
    assert header[:2] == ["p_star", "alpha_bem"] and "friction_N" in header
    table = np.loadtxt(tmp_path / "bem.csv", delimiter=",", skiprows=2)
    # friction = tau alpha A, normal force = P* E* A
    np.testing.assert_allclose(table[:, header.index("friction_N")], 0.5e6 * table[:, 1] * 1e-4)
    np.testing.assert_allclose(table[:, header.index("normal_force_N")], 2e6 * table[:, 0] * 1e-4)
    assert (tmp_path / "measured.png").stat().st_size > 10_000
    again = mi.Design.load(tmp_path / "compensated.json")
    np.testing.assert_allclose(again.gamma, comp.printed.gamma)


def test_gwyddion_scan_of_one_cell(design, tmp_path):
    made = Made(gamma_shift=-0.1, h_scale=1.1)
    z, dx = scan_of(design, made, cells=1.2, points=160, theta_deg=-1.0, noise=1e-4)
    path = _write(z, dx, tmp_path / "made.gwy")
    res = mi.measure(path, design, radius="0.5mm", progress=False, loads=4)
    gamma, _ = made.params(design)
    np.testing.assert_allclose(res.registration.gamma, gamma, atol=0.02)
    assert res.prediction.p_star.size == 4


def test_friction_needs_all_three(design):
    z, dx = scan_of(design, MADE, cells=1.2, points=100)
    with pytest.raises(mi.MetainterfaceError, match="modulus, shear_strength and area"):
        mi.measure(z * R, design, radius="0.5mm", pixel_size=dx * R, modulus="2MPa")


@pytest.mark.long
def test_compensated_design_exports_as_any_other(compensation, tmp_path):
    mi.export(compensation.printed, tmp_path / "next.npy", radius="0.5mm")
    assert np.isfinite(np.load(tmp_path / "next.npy")).all()


@pytest.mark.long
def test_map_from_two_scans(design, measured):
    # a second part of the same print, scanned elsewhere on the plate, less well
    z, dx = scan_of(design, MADE, cells=2, points=180, theta_deg=-1.0, noise=4e-4, seed=3)
    # only its registration and shapes join the map: its own BEM curve is not used, so 2 loads
    other = mi.measure(z * R, design, radius="0.5mm", pixel_size=dx * R, progress=False, loads=2)
    comp = measured.compensate(other)
    assert comp.pmap.gamma_shift == pytest.approx(0.15, abs=0.01)
    assert comp.pmap.h_scale == pytest.approx(0.85, abs=0.02)
    assert comp.error_after < 0.01


@pytest.mark.long
def test_a_shape_the_family_cannot_describe_is_reported(design):
    # tips flattened to caps of radius 20 R over half of a_max: no power law fits them, so
    # the BEM on the measured cell and the fitted model part, and the result says where
    made = Made(tip_rho=20.0, tip_r0=0.5 * design.settings.a_max)
    z, dx = scan_of(design, made, cells=1.2, points=160)
    res = mi.measure(z * R, design, radius="0.5mm", pixel_size=dx * R, progress=False, loads=3)
    np.testing.assert_allclose(res.registration.tip_radius, 20.0, rtol=0.03)
    assert res.prediction.disagree.all()
    assert "not all power laws" in res.summary()["disagreement"]
    # the same scan without the caps: the two agree
    z, dx = scan_of(design, Made(), cells=1.2, points=160)
    res = mi.measure(z * R, design, radius="0.5mm", pixel_size=dx * R, progress=False, loads=3)
    assert not res.prediction.disagree.any()
    assert "disagreement" not in res.summary()
