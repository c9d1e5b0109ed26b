"""Reading scans: SurfaceTopography's formats and arrays, sizes and units, missing points,
and the one-line errors."""

from __future__ import annotations

import numpy as np
import pytest

import metainterface as mi
from metainterface.measure.scan import from_array, read_scan

st = pytest.importorskip("SurfaceTopography")

R = 0.5e-3  # m


def _heights(shape=(30, 40), seed=0):
    z = np.random.default_rng(seed).normal(0.0, 1e-6, shape)  # m
    z[3, 4] = np.nan
    z[10, 20] = np.nan
    return z


# SurfaceTopography's NetCDF reader leaves its memory map open (its warning, not ours)
@pytest.mark.filterwarnings("ignore:Cannot close a netcdf_file")
@pytest.mark.parametrize("suffix", ["x3p", "gwy", "nc", "txt"])
def test_formats_keep_size_unit_and_missing_points(tmp_path, suffix):
    z = _heights()  # (ny, nx), rows along y
    ny, nx = z.shape
    topo = st.Topography(np.ma.masked_invalid(z.T), (nx * 2e-6, ny * 3e-6), unit="m")
    path = tmp_path / f"scan.{suffix}"
    getattr(topo, {"txt": "to_matrix", "nc": "to_netcdf"}.get(suffix, f"to_{suffix}"))(str(path))
    scan = read_scan(path, radius="0.5mm")
    assert scan.shape == (ny, nx)
    assert scan.missing == 2
    assert np.isnan(scan.heights[3, 4]) and np.isnan(scan.heights[10, 20])
    assert scan.dx == pytest.approx(2e-6 / R, rel=1e-6)
    assert scan.dy == pytest.approx(3e-6 / R, rel=1e-6)
    ok = np.isfinite(z)
    np.testing.assert_allclose(scan.heights[ok], z[ok] / R, rtol=1e-6)


def test_height_unit_and_size_where_the_file_has_none(tmp_path):
    z = np.nan_to_num(_heights()) * 1e6  # in um
    path = tmp_path / "scan.npy"
    np.save(path, z.T)
    with pytest.raises(mi.MetainterfaceError, match="no height unit"):
        read_scan(path, radius=R)
    with pytest.raises(mi.MetainterfaceError, match="no lateral size"):
        read_scan(path, radius=R, height_unit="um")
    scan = read_scan(path, radius=R, height_unit="um", size=("80um", "90um"))
    assert scan.dx == pytest.approx(2e-6 / R) and scan.dy == pytest.approx(3e-6 / R)
    np.testing.assert_allclose(scan.heights, z * 1e-6 / R)


def test_unknown_format_is_one_line(tmp_path):
    path = tmp_path / "notes.xyz"
    path.write_text("this is no topography\n")
    with pytest.raises(mi.MetainterfaceError, match="unknown scan format") as info:
        read_scan(path, radius=R)
    assert "\n" not in str(info.value)


def test_missing_file():
    with pytest.raises(mi.MetainterfaceError, match="not found"):
        read_scan("/nonexistent/scan.x3p", radius=R)


def test_array_with_pixel_size_and_units():
    z = _heights()
    scan = from_array(z * 1e9, pixel_size="2um", radius="0.5mm", height_unit="nm")
    assert scan.dx == scan.dy == pytest.approx(2e-6 / R)
    np.testing.assert_allclose(scan.heights[np.isfinite(z)], z[np.isfinite(z)] / R)
    assert scan.missing == 2


@pytest.mark.parametrize(
    ("value", "match"),
    [
        (np.zeros(10), "2-D"),
        (np.zeros((4, 40)), "at least"),
        (np.full((20, 20), np.nan), "almost no measured"),
    ],
)
def test_array_errors(value, match):
    with pytest.raises(mi.MetainterfaceError, match=match):
        from_array(value, pixel_size="1um", radius=R)


def test_bad_pixel_size_names_the_field():
    with pytest.raises(mi.MetainterfaceError, match="pixel_size"):
        from_array(np.zeros((20, 20)), pixel_size="-1um", radius=R)
