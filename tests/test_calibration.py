"""Calibration of tau and w from a sphere friction test (issue 38): a synthetic JKR test
with 3 % noise is recovered within the reported uncertainty; the CLI prints the options."""

import math

import numpy as np
import pytest

from metainterface.calibration import calibrate_sphere, jkr_contact_radius, sphere_friction
from metainterface.cli import main

R, E, TAU, W = 5e-3, 2.4e6, 0.3e6, 0.05  # a 5 mm sphere on PDMS, 50 mJ/m^2


def test_jkr_radius_closed_forms():
    # zero load: a^3 = 9 pi w R^2 / (2 E*); pull-off at -3/2 pi w R: a^3 = a0^3 / 4
    a0 = jkr_contact_radius(np.array([0.0]), W, R, E)[0]
    assert a0**3 == pytest.approx(4.5 * math.pi * W * R**2 / E, rel=1e-12)
    a_off = jkr_contact_radius(np.array([-1.5 * math.pi * W * R]), W, R, E)[0]
    assert a_off**3 == pytest.approx(a0**3 / 4, rel=1e-9)
    # Hertz without adhesion: a^3 = 3 F R / (4 E*)
    assert jkr_contact_radius(np.array([2.0]), 0.0, R, E)[0] ** 3 == pytest.approx(
        3 * 2.0 * R / (4 * E), rel=1e-12
    )


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_recovers_tau_and_w_within_uncertainty(seed):
    rng = np.random.default_rng(seed)
    fn = np.linspace(-0.5, 20.0, 25) * 1e-3  # a pull to 20 mN (pull-off 1.2 mN)
    ff = sphere_friction(fn, TAU, W, R, E) * (1 + 0.03 * rng.standard_normal(fn.size))
    cal = calibrate_sphere(fn, ff, radius=R, e_star=E)
    ci = cal.interval(0.95)
    assert ci["tau"][0] <= TAU <= ci["tau"][1]
    assert ci["work"][0] <= W <= ci["work"][1]
    assert cal.tau_sigma < 0.05 * TAU and cal.work_sigma < 0.3 * W
    assert 0.01 < cal.residual_rms < 0.06


def test_no_adhesion_gives_w_near_zero():
    fn = np.linspace(1.0, 20.0, 12) * 1e-3
    cal = calibrate_sphere(fn, sphere_friction(fn, TAU, 0.0, R, E), radius=R, e_star=E)
    assert cal.tau == pytest.approx(TAU, rel=1e-6)
    assert cal.work == pytest.approx(0.0, abs=1e-6 * W)


def test_cli(tmp_path, capsys):
    fn = np.linspace(0.0, 20.0, 15) * 1e-3
    ff = sphere_friction(fn, TAU, W, R, E)
    csv = tmp_path / "sphere.csv"
    csv.write_text(
        "normal_force [mN],friction_force [mN]\n"
        + "".join(f"{a * 1e3:.9g},{b * 1e3:.9g}\n" for a, b in zip(fn, ff, strict=True))
    )
    out = tmp_path / "cal.json"
    args = ["calibrate", str(csv), "--sphere-radius", "5mm", "--modulus", "2.4MPa"]
    assert main([*args, "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "--shear-strength 300kPa --work-of-adhesion 50mJ/m2" in text
    assert out.exists()
    assert main(["calibrate", str(csv), "--sphere-radius", "5 MPa", "--modulus", "2MPa"]) == 2


# --- a made design's friction test (given its design.json) -------------------------------

AREA, R_ASP = 4e-4, 0.5e-3  # a 4 cm^2 patch of 0.5 mm asperities, PDMS on glass


def _made_design(tmp_path):
    """A held-back 9-asperity design saved as design.json with its physical block, and a
    friction test of it: 20 loads from 0 to 95 % of its largest."""
    import torch

    import metainterface as mi
    from metainterface.physics import CellSettings

    s = CellSettings()
    rng = np.random.default_rng(11)
    h = rng.uniform(0, 0.6, 9) * s.delta_max
    d = mi.Design(gamma=rng.uniform(1.8, 4.0, 9), h=h - h.min(), settings=s)
    path = d.save(tmp_path / "design.json", physical={"radius_m": R_ASP, "area_m2": AREA})
    g, hh = d.tensors(torch.float64)
    model = mi.Independent(adhesion=W / (E * R_ASP))
    with torch.no_grad():
        p_max = float(model.sweep(g, hh, s, n_delta=2049).p_star[0, -1])
    return d, path, np.linspace(0.0, 0.95 * p_max, 20) * AREA * E


@pytest.mark.parametrize("seed", [0, 2])
def test_made_design_recovers_tau_and_w_within_uncertainty(tmp_path, seed):
    """A synthetic test of a made design (known tau, w, 3 % noise) is recovered within the
    reported 95 % ranges."""
    from metainterface.calibration import calibrate_design, design_friction

    d, _, fn = _made_design(tmp_path)
    clean = design_friction(fn, TAU, W, d, e_star=E, area=AREA, radius=R_ASP)
    assert clean[0] > 0.1 * clean[-1]  # friction at zero load: the adhesion's offset
    ff = clean * (1 + 0.03 * np.random.default_rng(seed).standard_normal(fn.size))
    cal = calibrate_design(fn, ff, d, e_star=E, area=AREA, radius=R_ASP)
    ci = cal.interval(0.95)
    assert ci["tau"][0] <= TAU <= ci["tau"][1]
    assert ci["work"][0] <= W <= ci["work"][1]
    assert cal.tau_sigma < 0.05 * TAU and cal.work_sigma < 0.3 * W
    # without noise: exact
    exact = calibrate_design(fn, clean, d, e_star=E, area=AREA, radius=R_ASP)
    assert exact.tau == pytest.approx(TAU, rel=1e-4)
    assert exact.work == pytest.approx(W, rel=1e-3)


def test_made_design_cli(tmp_path, capsys):
    """`calibrate friction.csv --design design.json --modulus ...` prints the options that
    feed design; a pull (negative load) and a missing radius are one-line errors."""
    import json

    from metainterface.calibration import design_friction

    d, path, fn = _made_design(tmp_path)
    ff = design_friction(fn, TAU, W, d, e_star=E, area=AREA, radius=R_ASP)
    csv = tmp_path / "patch.csv"
    csv.write_text(
        "normal_force,friction_force\n"
        + "".join(f"{a:.12g},{b:.12g}\n" for a, b in zip(fn, ff, strict=True))
    )
    out = tmp_path / "cal.json"
    args = ["calibrate", str(csv), "--design", str(path), "--modulus", "2.4MPa"]
    assert main([*args, "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "--shear-strength 300kPa --work-of-adhesion 50mJ/m2" in text
    assert "area 4 cm^2" in text
    rec = json.loads(out.read_text())
    assert rec["area_m2"] == AREA and rec["radius_m"] == R_ASP
    # the tested patch given another area: tau scales as 1 / A, and w moves with P*
    assert main([*args, "--area", "8cm2"]) == 0
    assert "--shear-strength 300kPa" not in capsys.readouterr().out
    pulled = tmp_path / "pull.csv"
    pulled.write_text("normal_force [mN],friction_force [mN]\n-100,1000\n500,2000\n1000,3000\n")
    assert main(["calibrate", str(pulled), "--design", str(path), "--modulus", "2.4MPa"]) == 2
    assert "got -100 mN" in capsys.readouterr().err  # in the file's units
    bare = d.save(tmp_path / "bare.json")  # no physical block: R and the area unknown
    assert main(["calibrate", str(csv), "--design", str(bare), "--modulus", "2.4MPa"]) == 2
    assert "--radius" in capsys.readouterr().err
    with pytest.raises(SystemExit) as neither:  # a sphere or a design: argparse says so
        main(["calibrate", str(csv), "--modulus", "2.4MPa"])
    assert neither.value.code == 2
    assert "--sphere-radius --design" in capsys.readouterr().err


def test_made_design_refuses_a_pull(tmp_path):
    from metainterface.calibration import calibrate_design

    d, _, fn = _made_design(tmp_path)
    with pytest.raises(Exception, match="loads >= 0"):
        calibrate_design(np.r_[-0.1, fn[1:4]], np.ones(4), d, e_star=E, area=AREA, radius=R_ASP)


def test_made_design_is_calibrated_with_the_model_it_was_made_with(tmp_path):
    """A design.json that names the interacting model is calibrated with it: a noiseless
    test made by that model is recovered exactly, and the same data read with the paper's
    independent model gives another w (so the choice is not a no-op)."""
    from metainterface.calibration import calibrate_csv, calibrate_design, design_friction

    d, _, fn = _made_design(tmp_path)
    fn = fn[::2]  # 10 loads: the interacting model costs a few sweeps a solve
    path = d.save(
        tmp_path / "made.json", physical={"radius_m": R_ASP, "area_m2": AREA}, model="interacting"
    )
    ff = design_friction(fn, TAU, W, d, e_star=E, area=AREA, radius=R_ASP, model="interacting")
    csv = tmp_path / "patch.csv"
    csv.write_text(
        "normal_force,friction_force\n"
        + "".join(f"{a:.12g},{b:.12g}\n" for a, b in zip(fn, ff, strict=True))
    )
    cal = calibrate_csv(csv, design=path, modulus="2.4MPa")
    assert cal.tau == pytest.approx(TAU, rel=1e-3)
    assert cal.work == pytest.approx(W, rel=1e-2)
    assert "interacting" in cal.contact
    other = calibrate_design(fn, ff, d, e_star=E, area=AREA, radius=R_ASP)
    assert abs(other.work - W) > 1e-3 * W or abs(other.tau - TAU) > 1e-3 * TAU
