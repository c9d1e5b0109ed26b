"""`metainterface design`: outputs, targets from CSV and friction laws, bad input."""

import json

import numpy as np
import pytest

import metainterface as mi
from metainterface.cli import main


def test_design_cli_writes_outputs(tmp_path, capsys):
    out = tmp_path / "out"
    csv = tmp_path / "mine.csv"
    t = mi.Target.builtin("saturating")
    csv.write_text(
        "p_star,alpha\n"
        + "\n".join(f"{p},{a}" for p, a in zip(t.p_star[::8], t.alpha[::8], strict=True))
    )
    assert main(["design", "--target-csv", str(csv), "--out", str(out), "--refine", "none"]) == 0
    folder = out  # one target: its files directly in --out
    for f in ("design.json", "target.csv", "curve.csv", "design.png"):
        assert (folder / f).is_file(), f
    data = json.loads((folder / "design.json").read_text())
    assert data["method"] == "surrogate" and 0 <= data["relative_error"] < 1
    assert "version" in data["provenance"]
    assert "surrogate" in capsys.readouterr().out


def test_design_cli_bad_input(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("p_star,alpha\n0,0\n1e-4,0.01\n0.5e-4,0.02\n")
    out = tmp_path / "o"
    assert main(["design", "--target-csv", str(bad), "--out", str(out)]) == 2
    assert "row 3" in capsys.readouterr().err and not out.exists()
    assert main(["design", "--target", "nope", "--out", str(out)]) == 2


def test_design_from_a_friction_law_with_units_and_a_pressure_limit(tmp_path, capsys):
    # friction grows with load, sub-linearly; tau = 0.25 MPa, E* = 2 MPa, A = 4 cm^2
    loads = np.linspace(0.0, 1.2, 12)  # N; P* = F / (A E*) up to 1.5e-3
    friction = 0.25e6 * 4e-4 * 0.06 * (loads / loads[-1]) ** 0.7  # alpha up to 0.06
    csv = tmp_path / "law.csv"
    csv.write_text(
        "normal_force,friction_force\n"
        + "\n".join(f"{n},{f}" for n, f in zip(loads, friction, strict=True))
    )
    out = tmp_path / "out"
    args = [
        "design",
        "--friction-csv",
        str(csv),
        "--shear-strength",
        "0.25MPa",
        "--modulus",
        "2MPa",
        "--radius",
        "0.5mm",
        "--area",
        "4cm2",
        "--out",
        str(out),
        "--refine",
        "none",
        "--max-pressure",
        "0.5",
    ]
    assert main(args) == 0, capsys.readouterr().err
    data = json.loads((out / "design.json").read_text())
    assert data["physical"]["radius_m"] == pytest.approx(5e-4)
    assert data["physical"]["n_cells"] == pytest.approx(4e-4 / data["physical"]["cell_area_m2"])
    assert data["pressure_check"]["limit_p_over_e_star"] == pytest.approx(0.5)
    assert "friction" in data["target"]
    np.testing.assert_allclose(data["target"]["alpha"][-1], 0.06, rtol=1e-9)
    assert main([*args[:-4], "--modulus", "2mm"]) == 2  # a length is not a stress
    assert "modulus" in capsys.readouterr().err
