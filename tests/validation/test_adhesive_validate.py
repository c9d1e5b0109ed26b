"""`mi.validate` / `metainterface validate` of an adhesive design (issue 52): the JKR-limit
BEM by approach, on the rising-force branch, against the adhesive model; checked on a Hertz
asperity against the JKR closed form (Johnson, Kendall & Roberts 1971), written here apart
from the package's code."""

import math

import numpy as np
import pytest

import metainterface as mi
from metainterface.cli import main
from metainterface.physics import CellSettings

W = 4.2e-5  # w / (E* R): PDMS on glass at R = 0.5 mm


def _hertz():
    return mi.Design(
        gamma=np.array([2.0]), h=np.array([0.0]), settings=CellSettings(n_asperities=1)
    )


def _jkr_alpha(p_star, side, w):
    """pi a^2 / L^2 of an isolated JKR sphere (R = 1, E* = 1) at the cell's force P* L^2."""
    f = p_star * side**2
    q = 3 * math.pi * w
    a = ((f + q + np.sqrt(6 * math.pi * w * f + q * q)) / (4 / 3)) ** (1 / 3)
    return math.pi * a * a / side**2


def test_adhesive_hertz_asperity_against_jkr_at_the_default_grid():
    """At the default grid (256 n = 256^2) the BEM's contact fraction on the rising branch
    is within 3 % of JKR's (the solver's own sphere test measures 2.6-3 % at 256^2 over a
    loading path, a / dx ~ 15-32: the edge placed to a fraction of a spacing), and the
    adhesive model is JKR itself (to 1e-6: it interpolates its sweep, ~1e-7). The result
    compares with the adhesive model."""
    design = _hertz()
    model = mi.Independent(adhesion=W)
    r = mi.validate(design, model=model, loads=3)
    assert r.grid == 256 and r.model.adhesion == W
    assert r.p_star.size >= 3 and np.all(r.p_star > 0) and np.all(np.diff(r.p_star) > 0)
    jkr = _jkr_alpha(r.p_star, r.heights.cell_side, W)
    assert np.abs(r.alpha_bem / jkr - 1).max() < 0.03
    assert np.abs(r.alpha_model / jkr - 1).max() < 1e-6  # its sweep interpolated: 1e-7
    assert np.abs(r.rel_err).max() < 0.03
    assert np.all(r.residual <= 1e-10)  # every bonded solve converged


def test_cli_validates_a_design_made_with_adhesion(tmp_path, capsys):
    """A design.json whose model has adhesion is validated in the adhesive BEM without
    --physics; 128^2 (a / dx ~ 8-16: the solver's sphere test allows 8 % there, a pixel
    ring being ~15 % of the area)."""
    design = _hertz()
    path = design.save(tmp_path / "design.json", model=mi.Independent(adhesion=W).label)
    out = tmp_path / "val"
    assert main(["validate", str(path), "--grid", "128", "--loads", "2", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "adhesive BEM" in text and "adhesion=" in text
    assert (out / "bem.csv").exists()
    r = mi.validate(path, grid=128, loads=2)
    jkr = _jkr_alpha(r.p_star, r.heights.cell_side, W)
    assert np.abs(r.alpha_bem / jkr - 1).max() < 0.08


def test_adhesive_validation_takes_a_count_of_loads():
    with pytest.raises(mi.MetainterfaceError, match="count"):
        mi.validate(_hertz(), model=mi.Independent(adhesion=W), loads=[1e-4, 2e-4])
