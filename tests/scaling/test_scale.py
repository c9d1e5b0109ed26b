"""A friction law's scale: which area / E* / tau makes it reachable, and designing it."""

from pathlib import Path

import numpy as np
import pytest

import metainterface as mi
from metainterface.physics.curves import design_sweep
from metainterface.units.friction import alpha_to_friction

TAU, E_STAR = 0.25e6, 2e6
TRUE_AREA = 8e-4  # the law is a cell's own curve at 8 cm^2
EXAMPLE = Path(mi.__file__).parent / "examples" / "example_design.json"


@pytest.fixture(scope="module")
def law_csv(tmp_path_factory):
    sw = design_sweep(mi.Design.load(EXAMPLE), n_delta=40)
    p, a = sw.p_star[0].numpy(), sw.alpha[0].numpy()
    fn, ff = alpha_to_friction(p, a, shear_strength=TAU, e_star=E_STAR, area=TRUE_AREA)
    path = tmp_path_factory.mktemp("law") / "law.csv"
    path.write_text(
        "normal_force,friction_force\n"
        + "".join(f"{x:.12g},{y:.12g}\n" for x, y in zip(fn, ff, strict=True))
    )
    return path


def test_the_true_area_is_in_the_feasible_range(law_csv):
    fs = mi.feasible_scale(
        law_csv, shear_strength="0.25MPa", modulus="2MPa", radius="0.5mm", area="2cm2"
    )
    assert not fs.reachable and fs.outside > 0
    spans = fs.ranges["area"]
    assert any(lo <= TRUE_AREA <= hi for lo, hi in spans)
    head, tail = fs.summary()
    assert "not reachable at area 2 cm^2" in head and "reachable with an area of" in tail
    assert "cm^2" in tail
    # at its true area everything is inside
    at_true = mi.feasible_scale(
        law_csv, shear_strength="0.25MPa", modulus="2MPa", radius="0.5mm", area="8cm2"
    )
    assert at_true.reachable
    rec = fs.record()
    assert rec["ranges"]["area"] and rec["given"]["area"] == pytest.approx(2e-4)
    at = fs.suggest()  # the area moved into its range, the rest as given
    assert any(lo <= at["area"] <= hi for lo, hi in spans)
    assert at["modulus"] == 2e6 and at["shear_strength"] == 0.25e6 and at["radius"] == 0.5e-3


def test_unreachable_by_area_alone_names_another_variable(tmp_path):
    # mu = 0.3 everywhere: alpha / P* = mu E* / tau = 2.4, below anything the cell reaches
    # at any area (area moves points along rays); a stiffer material does it
    path = tmp_path / "amontons.csv"
    fn = np.linspace(0.2, 8.0, 30)
    path.write_text("normal_force,friction_force\n" + "".join(f"{x},{0.3 * x}\n" for x in fn))
    fs = mi.feasible_scale(
        path, shear_strength="0.25MPa", modulus="2MPa", radius="0.5mm", area="4cm2"
    )
    assert fs.ranges["area"] == [] and fs.ranges["modulus"]
    at = fs.suggest()  # no area does it: the modulus moves instead
    assert at["area"] == pytest.approx(4e-4) and at["modulus"] == fs.best["modulus"] != 2e6
    assert "E* of" in fs.summary()[1] and "MPa" in fs.summary()[1]


def test_design_scale_finds_an_area_that_designs_the_law(law_csv):
    r = mi.design_scale(
        law_csv,
        shear_strength="0.25MPa",
        modulus="2MPa",
        radius="0.5mm",
        area="2cm2..20cm2",
        verify=False,
        effort=mi.Effort(hedge=2, fallback=0),  # a short search: the law is a cell's own curve
    )
    sc = r.target.meta["scale"]
    assert sc["variable"] == "area" and 2e-4 <= sc["value"] <= 20e-3
    assert r.error < 0.02  # the law is a cell's curve: some area in range designs it closely
    assert sc["tiles_per_side"] ** 2 >= sc["n_cells"]
    assert r.target.meta["friction"]["area_m2"] == pytest.approx(sc["value"])


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"area": "auto", "modulus": "1MPa..3MPa"}, "one of area, modulus, shear_strength"),
        ({"area": "5cm2..2cm2"}, "low end must be below"),
        ({"area": "1cm2..2cm2..3cm2"}, "LOW..HIGH"),
        ({"area": "4cm2"}, "with all three fixed use design"),
    ],
)
def test_design_scale_bad_input(law_csv, kw, match):
    opts = {"shear_strength": "0.25MPa", "modulus": "2MPa", "radius": "0.5mm", **kw}
    with pytest.raises(mi.MetainterfaceError, match=match):
        mi.design_scale(law_csv, **opts)
