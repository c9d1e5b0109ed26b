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
