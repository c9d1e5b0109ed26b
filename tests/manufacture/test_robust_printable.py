"""Robust design and printable heights, as a user calls them (API and command line)."""

import json

import numpy as np
import pytest

import metainterface as mi
from metainterface.cli import main

DMAX = 0.02


def test_z_step_puts_heights_on_the_grid_and_reports_the_cost(tmp_path):
    r = mi.design(
        "bilinear",
        z_step="1um",
        out=tmp_path,
        verify=False,
        scale=mi.Scale(radius="0.5mm"),
        effort=mi.Effort(hedge=2, fallback=0),
    )
    step = 1e-6 / 0.5e-3
    levels = r.design.h / step
    np.testing.assert_allclose(levels, np.round(levels), atol=1e-9)
    q = r.printable
    assert q["z_step"] == pytest.approx(step) and q["z_step_m"] == pytest.approx(1e-6)
    assert q["error_after_refine"] <= q["error_after_snap"]
    assert q["error_before_snap"] < q["error_after_snap"]  # the snap costs something here
    assert r.error == q["error_after_refine"]
    rec = json.loads((tmp_path / "design.json").read_text())
    assert rec["relative_error"] == r.error and rec["printable"]["z_step_m"] == 1e-6
    assert "layer grid" in repr(r)
    # the design's error is what the curve of the snapped heights gives
    t = mi.tolerance(tmp_path / "design.json", samples=16)
    assert t.error_nominal == pytest.approx(r.error, rel=1e-3)


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"z_step": 0.05}, "z_step must be in (0, Delta_max"),
        ({"z_step": -0.001}, "z_step"),
        ({"z_step": "1um"}, "give radius"),
        ({"z_step": "1MPa", "scale": mi.Scale(radius="1mm")}, "z_step expects a length"),
        ({"robust": True}, "needs sigma_h"),
        ({"robust": mi.Robust()}, "needs sigma_h"),
        ({"robust": mi.Robust(sigma_h=-1.0)}, "sigma_h"),
        ({"robust": mi.Robust(sigma_gamma=float("nan"))}, "sigma_gamma"),
        ({"robust": mi.Robust(sigma_h=0.001, samples=0)}, "robust_samples"),
    ],
)
def test_bad_manufacturing_options_are_one_line(kwargs, fragment):
    """(The old one-by-one keywords' errors: tests/test_options.py.)"""
    with pytest.raises(mi.MetainterfaceError) as exc:
        mi.design("bilinear", **kwargs)
    assert fragment in str(exc.value) and "\n" not in str(exc.value)


def test_export_on_the_layer_grid(tmp_path):
    d = mi.Design(gamma=[2.0, 3.0, 2.5, 3.5], h=[0.0, 0.0041, 0.0099, 0.0128])
    rec = mi.export(d, tmp_path / "p.npy", radius="0.5mm", z_step="1um")
    z = rec["z_step"]
    assert z["z_step_m"] == pytest.approx(1e-6)
    assert z["levels"] == [0, 2, 5, 6]  # h / (0.002 R), rounded
    assert z["largest_shift_m"] == pytest.approx(0.0008 * 0.5e-3, rel=1e-6)
    heights = np.load(tmp_path / "p.npy")
    plain = mi.export(d, tmp_path / "q.npy", radius="0.5mm")
    assert "z_step" not in plain and not np.array_equal(heights, np.load(tmp_path / "q.npy"))
    with pytest.raises(mi.MetainterfaceError, match="z_step"):
        mi.export(d, tmp_path / "r.npy", radius="0.5mm", z_step="20um")  # Delta_max = 10 um


def test_robust_design_reports_both_and_lowers_the_made_error(tmp_path):
    kw = dict(sigma_h=0.1 * DMAX, sigma_gamma=0.05)
    # both designs with the same short search (no fallback multistart): the comparison is
    # robust against nominal, not of search efforts
    quick = mi.Effort(hedge=2, fallback=0)
    rob = mi.design(
        "saturating",
        robust=mi.Robust(samples=8, **kw),
        out=tmp_path / "r",
        verify=False,
        effort=quick,
    )
    nom = mi.design("saturating", out=tmp_path / "n", verify=False, effort=quick)
    s = rob.robust
    assert s["error_nominal"] == rob.error and s["sigma_h"] == pytest.approx(0.1 * DMAX)
    assert 0 < s["error_median"] <= s["error_p95"]
    rec = json.loads((tmp_path / "r" / "design.json").read_text())
    assert rec["relative_error"] == rob.error and rec["robust"]["error_p95"] == s["error_p95"]
    assert "robust: made cells" in repr(rob)
    t_rob = mi.tolerance(tmp_path / "r" / "design.json", samples=1024, seed=9, **kw)
    t_nom = mi.tolerance(tmp_path / "n" / "design.json", samples=1024, seed=9, **kw)
    assert np.mean(t_rob.errors) < np.mean(t_nom.errors)
    assert nom.error <= rob.error  # the nominal fit is what robustness trades


@pytest.mark.parametrize(
    ("extra", "fragment"),
    [
        (["--robust"], "--robust needs"),
        (["--sigma-h", "1um", "--radius", "1mm"], "need --robust"),
        (["--z-step", "1um"], "--radius"),
        (["--z-step", "30um", "--radius", "0.5mm"], "--z-step must be in"),
        (["--robust", "--sigma-h", "1um"], "--radius"),
        (["--robust", "--sigma-gamma", "-1"], "--sigma-gamma"),
        (["--robust", "--sigma-h", "0.001", "--robust-samples", "0"], "--robust-samples"),
    ],
)
def test_cli_bad_manufacturing_options_exit_2(tmp_path, capsys, extra, fragment):
    assert main(["design", "--target", "bilinear", "--out", str(tmp_path), *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert fragment in err and "\n" not in err


@pytest.mark.parametrize(
    ("z_step", "fragment"),
    [
        ("30um", "--z-step must be in (0, Delta_max = 10 um], got 30 um"),
        ("1MPa", "--z-step expects a length"),
        ("0", "--z-step must be in (0, Delta_max"),
    ],
)
def test_cli_export_bad_z_step_exit_2(tmp_path, capsys, z_step, fragment):
    """export checks --z-step against the design's own Delta_max (10 um at R = 0.5 mm)."""
    design = mi.Design(gamma=np.full(4, 2.5), h=np.zeros(4)).save(tmp_path / "d.json")
    out = tmp_path / "p.stl"
    args = ["export", str(design), "--radius", "0.5mm", "--z-step", z_step, "--out", str(out)]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert fragment in err and "\n" not in err and not out.exists()


def test_cli_robust_and_z_step(tmp_path, capsys):
    argv = ["design", "--target", "saturating", "--method", "multistart", "--starts", "2"]
    argv += ["--robust", "--sigma-h", "1um", "--radius", "0.5mm", "--robust-samples", "4"]
    assert main([*argv, "--z-step", "1um", "--out", str(tmp_path), "--no-verify"]) == 0
    out = capsys.readouterr().out
    assert "made p95" in out and "snapped" in out
    rec = json.loads((tmp_path / "design.json").read_text())
    assert {"robust", "printable", "relative_error"} <= set(rec)
    assert rec["printable"]["error_after_refine"] == rec["relative_error"]
