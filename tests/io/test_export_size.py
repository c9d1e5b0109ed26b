"""Exports a user can open: large files stated first, coarser STL flanks, what one cell is."""

import json
from pathlib import Path

import numpy as np
import pytest
import trimesh

import metainterface as mi
from metainterface.cli import main
from metainterface.io import export as ex
from metainterface.io.export import height_patch, mesh_lines, stl_triangles

EXAMPLE = Path(mi.__file__).parent / "examples" / "example_design.json"


@pytest.fixture(scope="module")
def design():
    return mi.Design.load(EXAMPLE)


def test_flank_step_keeps_every_line_through_a_contact_zone(design):
    patch = height_patch(design, radius=0.5e-3, tiles=(2, 1), grid=96)
    fine_x, fine_y = mesh_lines(patch, 1)
    cols, rows = mesh_lines(patch, 4)
    assert fine_x.size == 2 * 96 + 1 and fine_y.size == 96 + 1
    assert cols.size < fine_x.size and rows.size < fine_y.size
    assert cols[0] == 0 and cols[-1] == 2 * 96 and rows[-1] == 96
    # every line within a_max of an asperity's centre line stays (a_max = pitch / 4)
    pitch = 96 // 3
    x = np.arange(2 * 96 + 1)
    near = np.abs((x % pitch) - pitch / 2) <= pitch / 4
    assert set(x[near]) <= set(cols)


def test_coarser_flanks_halve_the_stl_and_stay_watertight(design, tmp_path):
    rec1 = mi.export(design, tmp_path / "a.stl", radius="0.5mm", flank_step=1, resolution=40)
    rec4 = mi.export(design, tmp_path / "b.stl", radius="0.5mm", resolution=40)
    assert rec4["flank_step"] == 4 and rec1["flank_step"] == 1
    assert rec4["triangles"] < 0.6 * rec1["triangles"]
    mesh = trimesh.load(tmp_path / "b.stl")
    assert mesh.is_watertight and mesh.volume > 0
    # the same extents: the flanks are coarser, the patch is not smaller
    np.testing.assert_allclose(rec4["extents_mm"], rec1["extents_mm"], rtol=1e-6)
    assert (tmp_path / "b.stl").stat().st_size == 84 + 50 * rec4["triangles"]
    assert stl_triangles(3, 3) == 2 * 4 + 3 * 8


def test_a_large_file_is_stated_first_and_written_only_when_forced(design, tmp_path, monkeypatch):
    monkeypatch.setattr(ex, "LARGE_FILE_BYTES", 10**5)
    out = tmp_path / "big.stl"
    with pytest.raises(mi.MetainterfaceError) as info:
        mi.export(design, out, radius="0.5mm", tiles=(3, 3))
    msg = str(info.value)
    assert "\n" not in msg and "MB STL" in msg and "M triangles" in msg
    assert "--flank-step" in msg and "--format png" in msg and "force" in msg
    assert not out.exists() and not (tmp_path / "big.stl.json").exists()
    rec = mi.export(design, out, radius="0.5mm", tiles=(3, 3), force=True)
    assert out.stat().st_size == 84 + 50 * rec["triangles"] > 10**5


def test_cli_refuses_a_large_export_with_exit_2(design, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(ex, "LARGE_FILE_BYTES", 10**5)
    out = tmp_path / "big.npy"
    assert (
        main(["export", str(EXAMPLE), "--radius", "0.5mm", "--tiles", "4x4", "--out", str(out)])
        == 2
    )
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "MB NPY" in err and "--force" in err
    assert not out.exists()
    assert (
        main(
            [
                "export",
                str(EXAMPLE),
                "--radius",
                "0.5mm",
                "--tiles",
                "4x4",
                "--out",
                str(out),
                "--force",
            ]
        )
        == 0
    )
    assert out.exists()


def test_export_says_what_one_cell_is_against_the_physical_block(design, tmp_path, capsys):
    data = json.loads(EXAMPLE.read_text())
    data["physical"] = mi.physical(design, radius="0.5mm", modulus="2MPa", area="4cm2")
    path = tmp_path / "design.json"
    path.write_text(json.dumps(data))
    per_side = data["physical"]["tiles_per_side"]
    assert main(["export", str(path), "--radius", "0.5mm", "--out", str(tmp_path / "c.png")]) == 0
    cap = capsys.readouterr()
    assert "one cell: 2.1" in cap.out
    assert f"--tiles {per_side}x{per_side}" in cap.err and "1x1 unit cells" in cap.err
    rec = mi.export(path, tmp_path / "d.png", radius="0.5mm", tiles=(per_side, per_side))
    assert rec["cells"] == per_side**2 and "notes" not in rec
