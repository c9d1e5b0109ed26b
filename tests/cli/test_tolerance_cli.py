"""`metainterface tolerance`: files, reproducible bytes, printer sizing, bad input -> exit 2."""

import json

import numpy as np
import pytest

import metainterface as mi
from metainterface.cli import main


@pytest.fixture
def design_file(tmp_path):
    d = mi.Design(gamma=[2.0, 3.0, 2.5, 3.5], h=[0.0, 0.004, 0.01, 0.013])
    return str(d.save(tmp_path / "design.json"))


def run(design_file, out, *extra):
    argv = ["tolerance", design_file, "--sigma-h", "1um", "--sigma-gamma", "0.05"]
    return main([*argv, "--radius", "0.5mm", "--samples", "256", "--out", str(out), *extra])


def test_writes_band_json_and_figure_and_same_seed_same_bytes(design_file, tmp_path, capsys):
    assert run(design_file, tmp_path / "a", "--seed", "5") == 0
    assert "p95" in capsys.readouterr().out
    band = (tmp_path / "a" / "band.csv").read_text()
    lines = band.splitlines()
    assert lines[0].startswith("# {") and '"seed": 5' in lines[0]
    assert lines[1] == "p_star,alpha_nominal,alpha_p05,alpha_p50,alpha_p95"
    data = np.loadtxt(tmp_path / "a" / "band.csv", delimiter=",", skiprows=2)
    assert data.shape == (128, 5) and np.all(data[:, 2] <= data[:, 4])
    rec = json.loads((tmp_path / "a" / "tolerance.json").read_text())
    assert 0 < rec["error_median"] <= rec["error_p95"]
    assert rec["first_order"]["error_p95"] > 0 and rec["settings"]["sigma_h_m"] == 1e-6
    assert (tmp_path / "a" / "tolerance.png").stat().st_size > 10_000
    assert run(design_file, tmp_path / "b", "--seed", "5") == 0
    assert (tmp_path / "b" / "band.csv").read_bytes() == band.encode()
    assert run(design_file, tmp_path / "c", "--seed", "6") == 0
    assert (tmp_path / "c" / "band.csv").read_text() != band


def test_printer_sizing(design_file, tmp_path, capsys):
    argv = ["tolerance", design_file, "--printer-sigma", "1um", "--max-error", "5%"]
    assert main([*argv, "--samples", "128", "--out", str(tmp_path / "p")]) == 0
    assert "R >=" in capsys.readouterr().out
    rec = json.loads((tmp_path / "p" / "tolerance.json").read_text())
    assert rec["printer"]["min_radius_m"] > 0 and rec["printer"]["max_error"] == 0.05
    assert rec["error_p95"] == pytest.approx(0.05, rel=0.05)


@pytest.mark.parametrize(
    ("extra", "fragment"),
    [
        (["--sigma-h=-1um"], "--sigma-h must be >= 0"),
        (["--sigma-h", "nan"], "--sigma-h"),
        (["--sigma-h", "1MPa"], "--sigma-h expects a length"),
        (["--sigma-gamma", "-0.1"], "--sigma-gamma"),
        (["--sigma-gamma", "inf"], "--sigma-gamma"),
        (["--samples", "0"], "--samples"),
        (["--radius", "1N"], "--radius expects a length"),
        (["--max-error", "5%"], "--printer-sigma and --max-error go together"),
        (["--scale-sigma", "2"], "--scale-sigma"),
    ],
)
def test_bad_input_exit_2(design_file, tmp_path, capsys, extra, fragment):
    assert run(design_file, tmp_path / "x", *extra) == 2
    err = capsys.readouterr().err.strip()
    assert fragment in err and "\n" not in err
    assert not (tmp_path / "x" / "band.csv").exists()


def test_length_without_radius_exit_2(design_file, tmp_path, capsys):
    argv = ["tolerance", design_file, "--sigma-h", "1um", "--out", str(tmp_path / "x")]
    assert main(argv) == 2
    assert "--radius" in capsys.readouterr().err


def test_model_choice_from_the_registry(design_file, tmp_path):
    assert run(design_file, tmp_path / "i", "--model", "interacting", "--samples", "16") == 0
    rec = json.loads((tmp_path / "i" / "tolerance.json").read_text())
    assert rec["settings"]["model"] == "interacting"
