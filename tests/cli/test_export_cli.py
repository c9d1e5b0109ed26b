"""`metainterface export`: writes the file; bad input is one line and exit status 2."""

import json
from pathlib import Path

import pytest

import metainterface
from metainterface.cli import main

EXAMPLE = Path(metainterface.__file__).parent / "examples" / "example_design.json"


def test_cli_export_writes_the_file(tmp_path, capsys):
    out = tmp_path / "p.stl"
    argv = ["export", str(EXAMPLE), "--radius", "0.5mm", "--tiles", "2x2", "--out", str(out)]
    assert main([*argv, "--resolution", "12", "--base", "0.5 mm"]) == 0
    assert out.exists() and (tmp_path / "p.stl.json").exists()
    assert "watertight" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "fragment"),
    [
        (["--tiles", "0x4"], "--tiles"),
        (["--tiles", "4x"], "--tiles"),
        (["--radius", "2MPa"], "--radius expects a length"),
        (["--radius=-1mm"], "--radius must be > 0"),
        (["--radius", "zz"], "cannot read"),
        (["--base", "0mm"], "--base must be > 0"),
        (["--resolution", "0"], "--resolution"),
        (["--resolution", "abc"], "--resolution"),
        (["--format", "png"], "stl suffix but --format png"),
    ],
)
def test_cli_bad_input_is_one_line_and_exit_2(tmp_path, capsys, extra, fragment):
    out = tmp_path / "p.stl"
    argv = ["export", str(EXAMPLE), "--radius", "0.5mm", "--out", str(out), *extra]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert fragment in err
    assert len(err.splitlines()) == 1
    assert not out.exists()


@pytest.fixture(scope="module")
def sized(tmp_path_factory):
    """A design.json made for a scale (its physical block records R = 0.4 mm)."""
    out = tmp_path_factory.mktemp("sized") / "run"
    argv = ["design", "--target", "saturating", "--radius", "0.4mm", "--modulus", "2MPa"]
    assert main([*argv, "--no-verify", "--hedge", "0", "--fallback", "0", "--out", str(out)]) == 0
    return out / "design.json"


def test_cli_export_takes_the_radius_the_design_file_records(sized, tmp_path, capsys):
    capsys.readouterr()
    out = tmp_path / "p.npy"
    assert main(["export", str(sized), "--out", str(out)]) == 0
    record = json.loads((tmp_path / "p.npy.json").read_text())
    assert record["radius_m"] == pytest.approx(0.4e-3)
    assert "warning" not in capsys.readouterr().err
    # another radius is the user's to choose, and is said to differ from the design's
    assert main(["export", str(sized), "--radius", "0.5mm", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "radius 0.5 mm is not the 0.4 mm the design file records" in err


def test_cli_export_of_a_design_without_a_scale_needs_the_radius(tmp_path, capsys):
    out = tmp_path / "p.stl"
    assert main(["export", str(EXAMPLE), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--radius" in err and "records no asperity" in err
    assert not out.exists()
