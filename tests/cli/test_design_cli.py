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
    args = ["design", "--target-csv", str(csv), "--out", str(out), "--refine", "none"]
    assert main([*args, "--no-verify"]) == 0
    folder = out  # one target: its files directly in --out
    assert {p.name for p in folder.iterdir()} == {"design.json", "curve.csv", "design.png"}
    data = json.loads((folder / "design.json").read_text())
    assert data["method"] == "surrogate" and 0 <= data["relative_error"] < 1
    assert "version" in data["provenance"]
    assert data["target"]["points"] == len(t.p_star[::8])
    assert "surrogate" in capsys.readouterr().out


def test_a_long_target_makes_a_small_design_file(tmp_path, capsys):
    """The target is stored once, decimated in design.json; the whole of it goes to
    target.csv only with --full-target, and no CSV's provenance line carries it."""
    p = np.linspace(0.0, 0.002, 20_000)
    csv = tmp_path / "measured_friction_of_batch_seventeen.csv"
    alpha = 0.04 * (1 - np.exp(-p / 6e-4))
    csv.write_text(
        "p_star,alpha\n" + "".join(f"{a:.9g},{b:.9g}\n" for a, b in zip(p, alpha, strict=True))
    )
    out = tmp_path / "out"
    args = ["design", "--target-csv", str(csv), "--out", str(out), "--refine", "none"]
    assert main([*args, "--full-target", "--no-verify"]) == 0
    data = json.loads((out / "design.json").read_text())
    assert (out / "design.json").stat().st_size < 80_000
    assert data["target"]["points"] == 20_000 and len(data["target"]["p_star"]) <= 1024
    assert data["target"]["p_star"][-1] == pytest.approx(0.002)
    assert data["target"]["sha256"].startswith("sha256:")
    full = np.loadtxt(out / "target.csv", delimiter=",", skiprows=2)
    assert full.shape == (20_000, 2)
    for name in ("curve.csv", "target.csv"):
        header = (out / name).read_text().splitlines()[0]
        assert len(header) < 600 and header.startswith("# {")
    table = capsys.readouterr().out.splitlines()
    # the table fits the long name: every row's columns start where the header's do
    head = table[0]
    row = next(line for line in table if line.startswith(csv.stem))
    assert row.index(" %") > head.index("zero-shot") and len(row) == len(head)


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
        "--no-verify",
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


def test_compare_of_one_target_writes_into_out(tmp_path):
    out = tmp_path / "cmp"
    quick = ["--refine", "none", "--starts", "2", "--hedge", "0", "--fallback", "0", "--no-verify"]
    assert main(["design", "--target", "linear", "--compare", "--out", str(out), *quick]) == 0
    assert {p.name for p in out.iterdir()} == {"surrogate", "multistart", "hertz", "compare.png"}
    assert (out / "hertz" / "design.json").is_file()


def test_design_cli_area_auto_and_fit(tmp_path, capsys):
    """--area auto designs the area with the cell and reports it; scattered rows are fitted
    (friction_fit.png); a fixed area out of reach is answered with what to change."""
    rng = np.random.default_rng(0)
    loads = np.repeat(np.linspace(0.5, 8.0, 10), 2)
    friction = 0.4 * loads**0.8 * (1 + 0.03 * rng.standard_normal(loads.size))
    csv = tmp_path / "measured.csv"
    csv.write_text(
        "normal_force,friction_force\n"
        + "\n".join(f"{n},{f}" for n, f in zip(loads[::-1], friction[::-1], strict=True))
    )
    base = ["design", "--friction-csv", str(csv), "--shear-strength", "0.25MPa"]
    base += ["--modulus", "20MPa", "--radius", "0.5mm", "--refine", "none", "--fallback", "0"]
    base += ["--hedge", "0", "--no-verify"]  # the scale's quick designs take the hedge too
    out = tmp_path / "auto"
    assert main([*base, "--area", "auto", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "monotone cubic spline" in text and "chose area =" in text and "tiles" in text
    data = json.loads((out / "design.json").read_text())
    scale = data["target"]["scale"]
    assert scale["variable"] == "area"
    assert data["physical"]["area_m2"] == pytest.approx(scale["value"])
    assert (out / "friction_fit.png").exists()
    # the export tiles the area chosen
    npy = tmp_path / "patch.npy"
    args = ["export", str(out / "design.json"), "--radius", "0.5mm", "--tiles", "auto"]
    assert main([*args, "--resolution", "8", "--out", str(npy)]) == 0
    n = data["physical"]["tiles_per_side"]
    assert json.loads((tmp_path / "patch.npy.json").read_text())["tiles"] == [n, n]
    capsys.readouterr()
    fixed = tmp_path / "fixed"
    # out of reach at the area given: refused (exit 2, nothing written), with the scales that
    # would reach it and the reachable friction coefficients
    assert main([*base, "--area", "1000cm2", "--out", str(fixed)]) == 2
    said = capsys.readouterr()
    assert "not reachable at area" in said.out
    assert "reachable with" in said.out and "--area auto" in said.out
    assert "a cell reaches mu" in said.err and "--force" in said.err
    assert not (fixed / "design.json").exists()
    assert main([*base, "--area", "auto", "--target", "linear", "--out", str(fixed)]) == 2
    assert "alone" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--work-of-adhesion", "-5mJ/m2", "--work-of-adhesion must be >= 0"),
        ("--modulus", "-2.4MPa", "--modulus must be > 0"),
        ("--radius", "-.5mm", "--radius must be > 0"),
    ],
)
def test_a_negative_quantity_is_told_its_range(tmp_path, capsys, option, value, message):
    """A negative value with its unit is read as a value and answered with its range (not
    argparse's "expected one argument"), before anything is designed."""
    csv = tmp_path / "law.csv"
    csv.write_text("normal_force,friction_force\n" + "".join(f"{f},{f}\n" for f in range(1, 12)))
    scale = {"--shear-strength": "0.3MPa", "--modulus": "2.4MPa", "--radius": "0.5mm"}
    scale[option] = value
    argv = ["design", "--friction-csv", str(csv), "--area", "4cm2", "--out", str(tmp_path / "o")]
    argv += [x for kv in scale.items() for x in kv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()


def test_an_adhesive_check_finer_than_the_bem_allows_is_refused_before_any_work(tmp_path, capsys):
    """An adhesive design's check refuses a grid above 256 points per asperity (its error
    stops falling there and its estimate no longer holds: bench_adhesive_convergence.py),
    at once, with the range, nothing written; the adhesionless check takes the same grid."""
    csv = tmp_path / "law.csv"
    csv.write_text("normal_force,friction_force\n" + "".join(f"{f},{6 * f}\n" for f in range(1, 6)))
    argv = ["design", "--friction-csv", str(csv), "--area", "auto", "--out", str(tmp_path / "o")]
    argv += ["--shear-strength", "0.3MPa", "--modulus", "2.4MPa", "--radius", "0.5mm"]
    argv += ["--work-of-adhesion", "50mJ/m2", "--verify-grid", "1536"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "--verify-grid must be at most 768" in err, err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()
