"""`metainterface validate`: output files and summary line; bad input is one line, exit 2."""

import json
import sys
from importlib.resources import files
from pathlib import Path

import numpy as np
import pytest

from metainterface.cli import main

EXAMPLE = str(files("metainterface") / "examples" / "example_design.json")


def test_validate_writes_csv_figure_and_prints_the_error(tmp_path, capsys):
    design = json.loads(Path(EXAMPLE).read_text())
    design["target"] = {"p_star": [0.0, 0.001, 0.002], "alpha": [0.0, 0.04, 0.07]}
    path = tmp_path / "d.json"
    path.write_text(json.dumps(design))
    out = tmp_path / "run"
    args = ["validate", str(path), "--grid", "96", "--loads", "2", "--jobs", "1"]
    assert main([*args, "--out", str(out)]) == 0
    data = np.genfromtxt(out / "bem.csv", delimiter=",", names=True, skip_header=1)
    assert data.dtype.names == (
        "p_star",
        "alpha_bem",
        "alpha_model",
        "rel_err",
        "p_max",
        "alpha_bem_pixels",
    )
    np.testing.assert_allclose(data["rel_err"], data["alpha_bem"] / data["alpha_model"] - 1)
    assert (out / "bem.csv").read_text().startswith("# {")
    assert (out / "validation.png").stat().st_size > 20_000
    per = np.genfromtxt(out / "asperities.csv", delimiter=",", names=True, skip_header=1)
    assert len(per.dtype.names) == 1 + 2 * 9
    printed = capsys.readouterr().out
    assert "largest relative error over the upper half of the loads" in printed


def one_line_error(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--grid", "100"], "grid must be a multiple of the lattice side n = 3"),
        (["--p-max", "1.0"], "beyond what the design reaches at Delta_max"),
    ],
)
def test_bad_grid_or_load_is_one_line(tmp_path, capsys, extra, message):
    out = tmp_path / "run"
    assert main(["validate", EXAMPLE, *extra, "--jobs", "1", "--out", str(out)]) == 2
    assert message in one_line_error(capsys)
    assert not out.exists()


def test_loads_must_be_positive(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["validate", EXAMPLE, "--loads", "0", "--out", str(tmp_path)])
    assert exc.value.code == 2
    assert "--loads: must be > 0" in capsys.readouterr().err


def test_malformed_design_file(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text('{"gamma": [2.0, 2.0, 2.0, 2.0], "h": [0, 0, 0')
    assert main(["validate", str(bad), "--out", str(tmp_path / "run")]) == 2
    assert "malformed JSON" in one_line_error(capsys)
    bad.write_text(json.dumps({"gamma": [2.0] * 4, "h": [0.0] * 4, "target": {"p_star": 1}}))
    assert main(["validate", str(bad), "--grid", "8", "--out", str(tmp_path / "run")]) == 2
    assert "target" in one_line_error(capsys)


def test_missing_tamaas_says_how_to_install(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "tamaas", None)  # import tamaas -> ImportError
    run = ["validate", EXAMPLE, "--engine", "tamaas", "--out", str(tmp_path / "run")]
    assert main(run) == 2
    assert "pip install 'metainterface[bem]'" in one_line_error(capsys)
    # the default engine needs no Tamaas
    args = ["validate", EXAMPLE, "--grid", "48", "--loads", "2", "--workers", "1"]
    assert main([*args, "--device", "cpu", "--out", str(tmp_path / "torch")]) == 0
    assert "(torch engine)" in capsys.readouterr().out


def test_bad_engine_and_device_are_one_line_errors(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["validate", EXAMPLE, "--engine", "nope", "--out", str(tmp_path)])
    assert exc.value.code == 2
    assert "--engine: invalid choice" in capsys.readouterr().err
    assert main(["validate", EXAMPLE, "--device", "tpu", "--out", str(tmp_path / "a")]) == 2
    assert "device must be one of auto, cpu, cuda" in one_line_error(capsys)
    run = ["validate", EXAMPLE, "--engine", "tamaas", "--device", "cuda"]
    assert main([*run, "--out", str(tmp_path / "b")]) == 2
    assert "device" in one_line_error(capsys)


def test_validate_physics_reports_both(tmp_path, capsys):
    out = tmp_path / "run"
    args = ["validate", EXAMPLE, "--grid", "96", "--loads", "2", "--jobs", "1"]
    assert main([*args, "--physics", "interacting", "--out", str(out)]) == 0
    bem = np.genfromtxt(out / "bem.csv", delimiter=",", names=True, skip_header=1)
    both = np.genfromtxt(out / "models.csv", delimiter=",", names=True, skip_header=1)
    assert both.dtype.names == (
        "p_star",
        "alpha_bem",
        "alpha_independent",
        "alpha_interacting",
        "rel_err_independent",
        "rel_err_interacting",
    )
    np.testing.assert_allclose(both["p_star"], bem["p_star"])
    np.testing.assert_allclose(both["alpha_interacting"], bem["alpha_model"], rtol=1e-4)
    np.testing.assert_allclose(
        both["rel_err_independent"], both["alpha_bem"] / both["alpha_independent"] - 1
    )
    printed = capsys.readouterr().out
    assert "by model (loads from the interacting model): independent" in printed
    assert '"loads_from": "interacting"' in (out / "models.csv").read_text().splitlines()[0]


def test_validate_of_an_adhesive_design_says_it_leaves_adhesion_out(tmp_path, capsys):
    design = json.loads(Path(EXAMPLE).read_text())
    design["model"] = "independent(adhesion=4e-05)"  # as design.json records it
    path = tmp_path / "d.json"
    path.write_text(json.dumps(design))
    # asked for the adhesionless model (without --physics: the adhesive BEM, issue 52)
    args = ["validate", str(path), "--grid", "48", "--loads", "2", "--workers", "1"]
    args += ["--physics", "independent"]
    assert main([*args, "--out", str(tmp_path / "run")]) == 0
    err = capsys.readouterr().err
    assert "designed with the adhesive model independent(adhesion=4e-05)" in err
    assert "without adhesion, against the independent model" in err


def test_a_sweep_with_an_adhesive_design_says_it_leaves_adhesion_out(tmp_path, capsys):
    design = json.loads(Path(EXAMPLE).read_text())
    (tmp_path / "plain.json").write_text(json.dumps(design))
    design["model"] = "independent(adhesion=4e-05)"
    (tmp_path / "sticky.json").write_text(json.dumps(design))
    args = ["validate", str(tmp_path / "plain.json"), str(tmp_path / "sticky.json")]
    assert main([*args, "--grid", "48", "--loads", "2", "--out", str(tmp_path / "run")]) == 0
    err = capsys.readouterr().err
    assert "sticky was designed with the adhesive model independent(adhesion=4e-05)" in err
    assert "plain" not in err.split("warning:")[-1]
