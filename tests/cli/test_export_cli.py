"""`metainterface export`: writes the file; bad input is one line and exit status 2."""

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
