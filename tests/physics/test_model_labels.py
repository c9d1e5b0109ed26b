"""A design file's forward model, adhesion included, is the one the commands that read the
file use: the label design.json records reads back (``mi.get_model``), and ``curve``,
``tolerance``, ``view`` and ``calibrate`` take it unless told another."""

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface.cli import main

W = 4e-5  # w / (E* R): PDMS on glass at R = 0.5 mm, about
GAMMA = [2.0, 2.2, 2.5, 2.8, 3.0, 3.2, 2.4, 2.6, 3.4]
H = [0.0, 0.001, 0.002, 0.003, 0.005, 0.007, 0.01, 0.013, 0.016]


@pytest.mark.parametrize(
    "model",
    [
        mi.Independent(),
        mi.Independent(adhesion=W),
        mi.Interacting(adhesion=W),
        mi.Interacting(curvature=True),
    ],
)
def test_a_recorded_label_reads_back_as_its_model(model):
    assert mi.get_model(model.label) == model


@pytest.mark.parametrize("label", ["independent(foo=1)", "nope(adhesion=1e-5)", "independent(("])
def test_a_label_of_nothing_registered_is_one_line(label):
    with pytest.raises(mi.MetainterfaceError, match="model must be one of"):
        mi.get_model(label)


def test_adhesive_alpha_does_not_depend_on_the_order_of_the_loads():
    """The adhesive curve is a path (the force's running maximum): two grids asked in one
    call, the second below the first, read what each asked alone reads."""
    d = mi.Design(gamma=GAMMA, h=H)
    g, h = d.tensors(torch.float64)
    m = mi.Independent(adhesion=W)
    p_max = float(m.model_curve(d).p_star_max)
    low, high = (
        torch.linspace(a, b, 9, dtype=torch.float64) * p_max for a, b in ((0, 0.5), (0.3, 1))
    )
    with torch.no_grad():
        both, _ = m.alpha_at(g, h, d.settings, torch.cat([high, low])[None], exact=True)
        alone = [m.alpha_at(g, h, d.settings, q[None], exact=True)[0] for q in (high, low)]
    np.testing.assert_allclose(both.numpy(), torch.cat(alone, -1).numpy(), rtol=1e-9, atol=1e-12)


@pytest.fixture
def sticky_file(tmp_path):
    d = mi.Design(gamma=GAMMA, h=H)
    physical = {"radius_m": 0.5e-3, "area_m2": 4e-4, "e_star_pa": 2.4e6}
    return d.save(
        tmp_path / "design.json", model=mi.Independent(adhesion=W).label, physical=physical
    )


def test_curve_and_tolerance_of_an_adhesive_file_are_adhesive(sticky_file, tmp_path):
    own = mi.curve(sticky_file)
    sticky = mi.curve(sticky_file, model=mi.Independent(adhesion=W))
    plain = mi.curve(sticky_file, model="independent")
    np.testing.assert_allclose(own.alpha, sticky.alpha)
    assert own.alpha[0] > 0 and plain.alpha[0] == 0  # in contact at zero load: adhesion
    # without manufacturing errors every made copy is the design: its error, not another's
    t = mi.tolerance(sticky_file, samples=16, target="nominal")
    assert t.settings.model == mi.Independent(adhesion=W).label
    assert t.error_median < 0.01
    assert main(["curve", str(sticky_file), "--out", str(tmp_path / "c.csv")]) == 0


def test_calibrate_reads_an_adhesive_design_file(sticky_file, tmp_path, capsys):
    from metainterface.calibration import design_friction

    d = mi.Design.load(sticky_file)
    fn = np.linspace(0.0, 0.05, 12)
    ff = design_friction(fn, 0.3e6, 0.05, d, e_star=2.4e6, area=4e-4, radius=0.5e-3)
    csv = tmp_path / "patch.csv"
    csv.write_text(
        "normal_force,friction_force\n"
        + "".join(f"{a:.12g},{b:.12g}\n" for a, b in zip(fn, ff, strict=True))
    )
    assert main(["calibrate", str(csv), "--design", str(sticky_file), "--modulus", "2.4MPa"]) == 0
    assert "w   = 50" in capsys.readouterr().out
