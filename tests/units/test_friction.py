"""Friction law (N) <-> dimensionless alpha(P*) target, Bowden-Tabor F_f = tau A_real."""

from pathlib import Path

import numpy as np
import pytest

import metainterface
from metainterface.errors import MetainterfaceError
from metainterface.physics import Design
from metainterface.physics.curves import design_sweep
from metainterface.units.friction import (
    alpha_to_friction,
    friction_columns,
    friction_target,
    friction_target_from_options,
    friction_to_alpha,
    read_friction_csv,
)

TAU, E_STAR, RADIUS, AREA = 0.25e6, 2e6, 0.5e-3, 4e-4  # 0.25 MPa, 2 MPa, 0.5 mm, 4 cm^2
EXAMPLE = Path(metainterface.__file__).parent / "examples" / "example_design.json"


def _model_curve():
    sw = design_sweep(Design.load(EXAMPLE), n_delta=40)
    return sw.p_star[0].numpy(), sw.alpha[0].numpy()


def _write(path, **columns):
    names = list(columns)
    rows = zip(*(columns[n] for n in names), strict=True)
    body = "\n".join(",".join(f"{v:.17g}" for v in row) for row in rows)
    path.write_text('# {"note": "test"}\n' + ",".join(names) + "\n" + body + "\n")
    return path  # with a '#' comment line, as the package writes them


def test_friction_csv_round_trips_to_the_alpha_target(tmp_path):
    p_star, alpha = _model_curve()
    fn, ff = alpha_to_friction(p_star, alpha, shear_strength=TAU, e_star=E_STAR, area=AREA)
    path = _write(tmp_path / "f.csv", normal_force=fn, friction_force=ff)
    target = friction_target(path, shear_strength=TAU, e_star=E_STAR, radius=RADIUS, area=AREA)
    assert p_star[0] == 0  # the curve starts at the origin: nothing added
    np.testing.assert_allclose(target.p_star, p_star, rtol=1e-8, atol=1e-14)
    np.testing.assert_allclose(target.alpha, alpha, rtol=1e-8, atol=1e-14)
    back = alpha_to_friction(
        target.p_star, target.alpha, shear_strength=TAU, e_star=E_STAR, area=AREA
    )
    np.testing.assert_allclose(back, (fn, ff), rtol=1e-8, atol=1e-12)
    assert target.columns().keys() == {"p_star", "alpha"}
    assert target.record()["area_m2"] == AREA


def test_closed_form_of_the_conversion():
    p, a = friction_to_alpha([10.0], [2.0], shear_strength=TAU, e_star=E_STAR, area=AREA)
    assert p[0] == pytest.approx(10.0 / (AREA * E_STAR))
    assert a[0] == pytest.approx(2.0 / (TAU * AREA))


def test_coefficient_csv_gives_the_same_target_with_the_origin_added(tmp_path):
    p_star, alpha = _model_curve()
    fn, ff = alpha_to_friction(p_star[1:], alpha[1:], shear_strength=TAU, e_star=E_STAR, area=AREA)
    path = _write(tmp_path / "mu.csv", normal_force=fn, friction_coefficient=ff / fn)
    target = friction_target(path, shear_strength=TAU, e_star=E_STAR, radius=RADIUS, area=AREA)
    np.testing.assert_allclose(target.p_star, p_star, rtol=1e-8, atol=1e-14)
    np.testing.assert_allclose(target.alpha, alpha, rtol=1e-8, atol=1e-14)
    assert target.law.rows[0] == 0  # the added origin


def test_report_columns_invert_the_target():
    cols = friction_columns([0.0, 0.01], [0.0, 0.02], shear_strength=TAU, e_star=E_STAR, area=AREA)
    assert cols["normal_force"][1] == pytest.approx(0.01 * AREA * E_STAR)
    assert cols["friction_force"][1] == pytest.approx(0.02 * AREA * TAU)
    assert np.isnan(cols["friction_coefficient"][0])
    assert cols["friction_coefficient"][1] == pytest.approx(0.02 * TAU / (0.01 * E_STAR))


@pytest.mark.parametrize(
    ("rows", "match"),
    [
        # friction decreasing with load: impossible with tau > 0, the row is named
        ([(1, 0.5), (2, 0.8), (3, 0.7)], r"row 3: friction 0\.7 N .* cannot decrease"),
        ([(0, 0.1), (1, 0.5), (2, 0.8)], r"row 1: friction 0\.1 N at zero normal force"),
        ([(1, 0.5), (1, 0.6), (2, 0.8)], r"row 2: normal_force 1 N is not above"),
        ([(1, 0.5), (2, -0.6), (3, 0.8)], r"row 2: friction_force = -0\.6"),
        ([(1, 0.5), (2, 200.0)], r"row 2: friction 200 N needs a real contact area"),
        ([(1, 0.5)], "at least 2 rows"),
    ],
)
def test_impossible_friction_laws_name_the_row(tmp_path, rows, match):
    # fit="never": the rows must be a law as they stand ("auto" would fit such rows)
    fn, ff = np.array(rows, dtype=float).T
    path = _write(tmp_path / "f.csv", normal_force=fn, friction_force=ff)
    with pytest.raises(MetainterfaceError, match=match):
        friction_target(
            path, shear_strength=TAU, e_star=E_STAR, radius=RADIUS, area=AREA, fit="never"
        )


def test_missing_columns_and_too_small_an_area(tmp_path):
    path = _write(tmp_path / "bad.csv", load=[1.0, 2.0], friction=[0.1, 0.2])
    with pytest.raises(MetainterfaceError, match="normal_force,friction_coefficient"):
        read_friction_csv(path)
    good = _write(tmp_path / "f.csv", normal_force=[1.0, 2.0], friction_force=[0.1, 0.2])
    with pytest.raises(MetainterfaceError, match="smaller than one unit cell"):
        friction_target(good, shear_strength=TAU, e_star=E_STAR, radius=RADIUS, area=1e-7)
    with pytest.raises(MetainterfaceError, match="shear strength must be"):
        friction_target(good, shear_strength=-1.0, e_star=E_STAR, radius=RADIUS, area=AREA)


def test_options_with_units(tmp_path):
    path = _write(tmp_path / "f.csv", normal_force=[1.0, 2.0], friction_force=[0.1, 0.2])
    target = friction_target_from_options(
        path, shear_strength="0.25MPa", modulus="2 MPa", radius="0.5mm", area="4cm2"
    )
    assert (target.shear_strength, target.e_star, target.radius) == (TAU, E_STAR, RADIUS)
    assert target.area == pytest.approx(AREA)
    assert target.alpha[-1] == pytest.approx(0.2 / (TAU * AREA))
    with pytest.raises(MetainterfaceError, match="missing --modulus"):
        friction_target_from_options(
            path, shear_strength="0.25MPa", modulus=None, radius="0.5mm", area="4cm2"
        )
    with pytest.raises(MetainterfaceError, match="--shear-strength expects a pressure"):
        friction_target_from_options(
            path, shear_strength="0.25mm", modulus="2MPa", radius="0.5mm", area="4cm2"
        )
