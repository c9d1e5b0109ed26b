"""Friction and target CSVs as labs write them (units in the header, ';' or tab, decimal
commas, BOM, comments) read as the plain CSV; bad variants refused in one line; unit slips
in the scale warned about once."""

import contextlib
import json
import warnings

import numpy as np
import pytest

import metainterface as mi
from metainterface.cli import main

# one law: friction grows sub-linearly with the load (N); alpha up to 0.06 at this scale
LOADS = np.round(np.linspace(0.1, 1.2, 12), 3)
FRICTION = np.round(0.25e6 * 4e-4 * 0.06 * (LOADS / LOADS[-1]) ** 0.7, 6)
SCALE = {"shear_strength": "0.25MPa", "modulus": "2MPa", "radius": "0.5mm", "area": "4cm2"}


def _text(header, rows, sep=",", comma=False):
    def num(v):
        s = f"{v:.17g}"
        return s.replace(".", ",") if comma else s

    return "\n".join([header, *(sep.join(num(v) for v in row) for row in rows)]) + "\n"


def _forces(factor_n=1.0, factor_f=1.0):
    return list(zip(LOADS / factor_n, FRICTION / factor_f, strict=True))


#: name -> file text of the same law
LAB_FILES = {
    "brackets_mN": _text("normal_force [mN],friction_force [mN]", _forces(1e-3, 1e-3)),
    "parentheses_N": _text("normal_force (N),friction_force (N)", _forces()),
    "suffix_kN_uN": _text("normal_force_kN,friction_force_uN", _forces(1e3, 1e-6)),
    "micro_sign": _text("normal_force [µN],friction_force [mN]", _forces(1e-6, 1e-3)),
    "case_and_spaces": _text("  Normal_Force [mN] , FRICTION_FORCE  ", _forces(1e-3)),
    "semicolon_decimal_comma": _text("normal_force;friction_force", _forces(), sep=";", comma=True),
    "tab_decimal_comma": _text("normal_force\tfriction_force", _forces(), sep="\t", comma=True),
    "tab_points_mN": _text("normal_force [mN]\tfriction_force", _forces(1e-3), sep="\t"),
    "trailing_separator": _text(
        "normal_force;friction_force", _forces(), sep=";", comma=True
    ).replace("\n", ";\n"),
    "notes_column": "sample;normal_force;friction_force;note\n"
    + "".join(
        f"S{k};{n:.17g};{f:.17g};run {k}, dry\n".replace(".", ",")
        for k, (n, f) in enumerate(_forces())
    ),
    "comments_blanks": "# rig 3, 20 °C\n\n"
    + _text("normal_force,friction_force", _forces()).replace("\n", "\n\n", 3)
    + "# end\n",
    "coefficient_semicolon": _text(
        "Normal_Force [mN];friction_coefficient [-]",
        list(zip(LOADS * 1e3, FRICTION / LOADS, strict=True)),
        sep=";",
        comma=True,
    ),
}


def _target(path):
    return mi.Target.from_friction(path, **SCALE, fit="never")


@pytest.fixture(scope="module")
def law_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("law") / "law.csv"
    path.write_text(_text("normal_force,friction_force", _forces()))
    return path


@pytest.fixture(scope="module")
def plain(tmp_path_factory):
    path = tmp_path_factory.mktemp("plain") / "law.csv"
    path.write_text(_text("normal_force,friction_force", _forces()))
    return _target(path)


@pytest.mark.parametrize("bom", [False, True])
@pytest.mark.parametrize("variant", list(LAB_FILES))
def test_lab_friction_files_give_the_plain_target(tmp_path, plain, variant, bom):
    path = tmp_path / "law.csv"
    path.write_bytes((b"\xef\xbb\xbf" if bom else b"") + LAB_FILES[variant].encode())
    t = _target(path)
    np.testing.assert_allclose(t.p_star, plain.p_star, rtol=1e-12, atol=0)
    np.testing.assert_allclose(t.alpha, plain.alpha, rtol=1e-12, atol=0)


TARGET_ROWS = [(0.0, 0.0), (0.0005, 0.0125), (0.001, 0.02), (0.0015, 0.0255)]


@pytest.mark.parametrize(
    "text",
    [
        _text("p_star;alpha", TARGET_ROWS, sep=";", comma=True),
        _text("P_STAR\tAlpha", TARGET_ROWS, sep="\t", comma=True),
        _text("p_star\talpha", TARGET_ROWS, sep="\t"),
        "\ufeff# made by hand\n\n" + _text(" p_star ; alpha ", TARGET_ROWS, sep=";"),
    ],
    ids=["semicolon_comma", "tab_comma", "tab", "bom_comment_blank"],
)
def test_lab_target_files_give_the_plain_target(tmp_path, text):
    plain, lab = tmp_path / "plain.csv", tmp_path / "lab.csv"
    plain.write_text(_text("p_star,alpha", TARGET_ROWS))
    lab.write_text(text, encoding="utf-8")
    a, b = mi.Target.from_csv(plain), mi.Target.from_csv(lab)
    np.testing.assert_array_equal(a.p_star, b.p_star)
    np.testing.assert_array_equal(a.alpha, b.alpha)


BAD_FRICTION = {
    "normal_force [lbs],friction_force\n1,0.3\n2,0.5\n3,0.6\n": (
        "column normal_force [lbs]",
        "not a force unit",
        "mN",
    ),
    "normal_force [blorps],friction_force\n1,0.3\n": ("unknown unit 'blorps'", "kN"),
    # a force whose factor to newtons overflows (years^90): pint's OverflowError was a traceback
    "normal_force [N (a/s)^90],friction_force\n1,0.3\n": ("floating-point range", "mN"),
    "normal_force,friction_force [kg]\n1,0.3\n": ("column friction_force [kg]", "not a force"),
    "normal_force,friction_coefficient [N]\n1,0.3\n2,0.3\n3,0.3\n": (
        "friction_coefficient",
        "dimensionless",
    ),
    "normal_force,friction_force\n1,0;0,3\n": ("row 1", "ambiguous", "';'"),
    "normal_force,friction_force\n1,5,0,3\n2,0,0,5\n": ("row 1", "decimal commas"),
    "normal_force;friction_force\n1,5;0.3\n": ("row 1, column friction_force", "decimal point"),
    "normal_force\tfriction_force\n1,000\t0,3\n": ("row 1, column normal_force", "ambiguous"),
    "normal_force;friction_force\n1;0,3\n2;0,5x\n": ("row 2, column friction_force", "0,5x"),
    "load;friction_force\n1;0,3\n": ("missing column", "normal_force"),
}


@pytest.mark.parametrize("text", list(BAD_FRICTION))
def test_bad_lab_friction_files_are_one_line_errors(tmp_path, text):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(mi.MetainterfaceError) as err:
        _target(path)
    message = str(err.value)
    assert "\n" not in message and message.startswith(str(path)), message
    for fragment in BAD_FRICTION[text]:
        assert fragment in message, (fragment, message)


@pytest.mark.parametrize(
    ("text", "fragments"),
    [
        ("p_star [N],alpha\n0,0\n1e-4,0.01\n2e-4,0.02\n", ("column p_star [N]", "dimensionless")),
        ("p_star;alpha\n0;0\n0,0001;0.01\n", ("row 2, column alpha", "decimal point")),
        ("p_star,alpha\n0,0\n0,0001,0,01\n", ("row 2", "ambiguous")),
    ],
)
def test_bad_lab_target_files_are_one_line_errors(tmp_path, text, fragments):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(mi.MetainterfaceError) as err:
        mi.Target.from_csv(path)
    message = str(err.value)
    assert "\n" not in message and message.startswith(str(path)), message
    for fragment in fragments:
        assert fragment in message, (fragment, message)


# --- the command line ---------------------------------------------------------------------

QUICK = ["--method", "hertz", "--starts", "1", "--refine", "none", "--no-verify"]


def _cli_scale(**over):
    s = {**SCALE, **over}
    return [
        *("--shear-strength", s["shear_strength"], "--modulus", s["modulus"]),
        *("--radius", s["radius"], "--area", s["area"]),
    ]


def test_cli_reads_a_lab_file_as_the_plain_one(tmp_path, plain, capsys):
    path = tmp_path / "law.csv"
    path.write_text(LAB_FILES["semicolon_decimal_comma"].replace("normal_force", "normal_force_N"))
    out = tmp_path / "out"
    argv = ["design", "--friction-csv", str(path), *_cli_scale(), *QUICK, "--out", str(out)]
    assert main(argv) == 0, capsys.readouterr().err
    assert "unit slip" not in capsys.readouterr().err
    target = json.loads((out / "design.json").read_text())["target"]
    np.testing.assert_allclose(target["p_star"], plain.p_star, rtol=1e-12)
    np.testing.assert_allclose(target["alpha"], plain.alpha, rtol=1e-12)


def test_cli_bad_lab_file_is_one_line(tmp_path, capsys):
    path = tmp_path / "law.csv"
    path.write_text("normal_force [lbs];friction_force\n1;0,3\n2;0,5\n3;0,6\n")
    argv = ["design", "--friction-csv", str(path), *_cli_scale(), *QUICK]
    assert main([*argv, "--out", str(tmp_path / "o")]) == 2
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert len(err) == 1 and "normal_force [lbs]" in err[0] and "force unit" in err[0], err


# --- unit slips ---------------------------------------------------------------------------

SLIPS = [
    ({"modulus": 2.4}, "modulus 2.4 Pa is below 1 kPa: a unit slip? (2.4MPa)"),
    ({"modulus": "2e12"}, "modulus 2 TPa is above 1 TPa: a unit slip? (2GPa)"),
    (
        {"modulus": "2MPa", "shear_strength": "250MPa"},
        "shear strength 250 MPa is above the modulus 2 MPa: a unit slip? (250kPa)",
    ),
    ({"radius": 0.5}, "radius 0.5 m is above 10 cm: a unit slip? (0.5mm)"),
]


@pytest.mark.parametrize(("scale", "message"), SLIPS)
def test_a_unit_slip_warns_once_at_the_users_line(law_file, scale, message):
    from metainterface.units.plausible import unit_slips
    from metainterface.units.quantities import parse_length, parse_pressure

    si = {
        "modulus": parse_pressure(scale.get("modulus", "2MPa")),
        "shear_strength": parse_pressure(scale.get("shear_strength", "0.25MPa")),
        "radius": parse_length(scale.get("radius", "0.5mm")),
    }
    assert unit_slips(**si) == [message]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        # the slipped scale may make the law impossible: the warning comes first
        with contextlib.suppress(mi.MetainterfaceError):
            mi.reachability(law_file, **{**SCALE, **scale})
    slips = [w for w in caught if issubclass(w.category, mi.UnitSlipWarning)]
    assert [str(w.message) for w in slips] == [message]
    assert slips[0].filename == __file__


def test_plausible_scales_do_not_warn(law_file):
    from metainterface.units.plausible import unit_slips

    assert unit_slips(modulus=2e6, shear_strength=0.25e6, radius=5e-4) == []
    assert unit_slips(modulus=1e3, shear_strength=1e3, radius=0.1) == []  # the edges
    assert unit_slips(modulus=200e9, radius=2e-6) == []  # steel, a micro-asperity
    with warnings.catch_warnings():
        warnings.simplefilter("error", mi.UnitSlipWarning)
        mi.reachability(law_file, **SCALE)
        mi.physical(mi.Design(gamma=[2.0] * 9, h=[0.0] * 9), radius="0.5mm", modulus="2MPa")


def test_python_physical_warns_for_a_slipped_radius():
    with pytest.warns(mi.UnitSlipWarning, match=r"radius 0.5 m .*\(0.5mm\)") as caught:
        mi.physical(mi.Design(gamma=[2.0] * 9, h=[0.0] * 9), radius=0.5, modulus="2MPa")
    assert len([w for w in caught if w.category is mi.UnitSlipWarning]) == 1


def test_cli_shows_a_unit_slip_once_in_one_line(tmp_path, capsys):
    # a slipped radius (0.2 m, meant 0.2 mm) on a patch large enough to hold its cells: the
    # law, its feasible scale and the design each read the radius, the line comes once
    big = tmp_path / "big.csv"
    big.write_text(_text("normal_force [kN],friction_force [kN]", _forces(0.1, 0.1)))
    argv = ["design", "--friction-csv", str(big), *_cli_scale(radius="0.2", area="4m2")]
    assert main([*argv, *QUICK, "--out", str(tmp_path / "o")]) == 0
    err = [ln for ln in capsys.readouterr().err.splitlines() if "unit slip" in ln]
    assert err == [
        "metainterface design: warning: radius 0.2 m is above 10 cm: a unit slip? (0.2mm)"
    ]
