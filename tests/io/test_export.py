"""Manufacturing exports: height maps (NPY/PNG/TIFF) and the watertight STL."""

import json
from pathlib import Path

import numpy as np
import pytest
import tifffile
import trimesh
from PIL import Image

import metainterface
from metainterface.errors import MetainterfaceError
from metainterface.io.export import export_design, format_for, height_patch, parse_tiles
from metainterface.physics import Design
from metainterface.validation.heightmap import height_map

EXAMPLE = Path(metainterface.__file__).parent / "examples" / "example_design.json"
R = 0.5e-3  # 0.5 mm
GRID = 24  # points per cell side: small and fast, a multiple of n = 3


@pytest.fixture(scope="module")
def design():
    return Design.load(EXAMPLE)


def test_npy_is_the_validation_height_map_times_r(design, tmp_path):
    out = tmp_path / "cell.npy"
    rec = export_design(design, out, radius=R, tiles=(2, 3), resolution=None)
    cell = height_map(design, rec["grid_per_cell"])
    np.testing.assert_allclose(np.load(out), np.tile(cell.heights * R, (3, 2)), rtol=0, atol=0)
    assert rec["pixel_size_m"] == pytest.approx(cell.spacing * R)
    side = json.loads((tmp_path / "cell.npy.json").read_text())
    assert side["provenance"]["version"] == metainterface.__version__
    assert side["tiles"] == [2, 3]


@pytest.mark.parametrize("suffix", [".png", ".tiff"])
def test_16_bit_images_decode_with_the_sidecar_scale(design, tmp_path, suffix):
    out = tmp_path / f"patch{suffix}"
    rec = export_design(design, out, radius=R, tiles=(2, 1), resolution=40.0)
    levels = np.asarray(Image.open(out)) if suffix == ".png" else tifffile.imread(out)
    assert levels.dtype == np.uint16
    assert levels.max() == 65535
    assert levels.min() == 0
    side = json.loads(out.with_name(out.name + ".json").read_text())
    assert side == {**rec, "provenance": side["provenance"]}
    decoded = side["z_min_m"] + levels * side["height_scale_m_per_level"]
    expected = np.tile(height_map(design, rec["grid_per_cell"]).heights * R, (1, 2))
    np.testing.assert_allclose(decoded, expected, atol=side["height_scale_m_per_level"])


def test_stl_is_watertight_with_the_tiled_extents(design, tmp_path):
    out = tmp_path / "patch.stl"
    base = 1e-3
    patch = height_patch(design, radius=R, tiles=(2, 3), grid=GRID)
    rec = export_design(design, out, radius=R, tiles=(2, 3), base=base, resolution=GRID / 2.1)
    assert rec["grid_per_cell"] == GRID  # the cell side is ~2.1 mm at R = 0.5 mm
    mesh = trimesh.load(out)
    assert mesh.is_watertight
    assert mesh.is_winding_consistent
    assert mesh.volume > 0
    cell_mm = design.settings.cell_side * R * 1e3
    relief_mm = (patch.heights.max() - patch.heights.min()) * 1e3
    np.testing.assert_allclose(
        mesh.extents, [2 * cell_mm, 3 * cell_mm, relief_mm + base * 1e3], rtol=1e-6
    )
    np.testing.assert_allclose(mesh.bounds[0], 0.0, atol=1e-6)
    assert rec["triangles"] == len(mesh.faces)
    assert rec["units"] == "mm"


def test_tiles_and_formats():
    assert parse_tiles("4x4") == (4, 4)
    assert parse_tiles("3X2") == (3, 2)
    assert parse_tiles("5") == (5, 5)
    for bad in ("0x4", "4x", "x4", "4x4x4", "-1x2", "a"):
        with pytest.raises(MetainterfaceError, match="--tiles"):
            parse_tiles(bad)
    assert format_for("a.tif") == "tiff"
    assert format_for("a.bin", "stl") == "stl"
    with pytest.raises(MetainterfaceError, match="png suffix but --format stl"):
        format_for("a.png", "stl")
    with pytest.raises(MetainterfaceError, match="cannot tell the format"):
        format_for("a.bin")
