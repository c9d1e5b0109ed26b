"""The public API as a notebook user calls it: numpy and lists in, numpy out, one-line errors."""

import json
import math

import matplotlib
import numpy as np
import pytest

import metainterface as mi

matplotlib.use("Agg")


def test_everything_public_is_exported_and_documented():
    for name in mi.__all__:
        obj = getattr(mi, name)
        if name != "__version__" and not isinstance(obj, dict):
            assert obj.__doc__, name
            assert name in mi.__doc__ or name in ("MetainterfaceError",), name


def test_targets_from_arrays_builtins_and_csv(tmp_path):
    t = mi.Target(p_star=[0.0, 1e-3, 2e-3], alpha=[0.0, 0.02, 0.03], name="mine")
    assert isinstance(t.p_star, np.ndarray) and t.p_star_max == 2e-3
    assert "mine" in repr(t) and "3 points" in repr(t)
    assert set(mi.Target.builtins()) == {"saturating", "bilinear", "linear"}
    b = mi.Target.builtin("bilinear")
    assert b.p_star[0] == 0 and np.all(np.diff(b.p_star) > 0)
    csv = tmp_path / "law.csv"
    csv.write_text("p_star,alpha\n0,0\n0.001,0.02\n0.002,0.03\n")
    assert mi.Target.from_csv(csv).name == "law"


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        (dict(p_star=[0, 1e-3, np.nan], alpha=[0, 0.1, 0.2]), "p_star is not a finite"),
        (dict(p_star=[0, 2e-3, 1e-3], alpha=[0, 0.1, 0.2]), "strictly increasing"),
        (dict(p_star=[0, 1e-3, 2e-3], alpha=[0, 0.5, 1.2]), "alpha = 1.2 is not < 1"),
        (dict(p_star=[0, 1e-3], alpha=[0, 0.1]), "at least 3 points"),
        (dict(p_star=[0, 1e-3, 2e-3], alpha=[0, 0.1]), "same length"),
        (dict(p_star="abc", alpha=[0, 0.1, 0.2]), "p_star must be a list of numbers"),
    ],
)
def test_bad_targets_are_one_line_errors(kwargs, fragment):
    with pytest.raises(mi.MetainterfaceError, match=fragment) as exc:
        mi.Target(**kwargs)
    assert "\n" not in str(exc.value)


def test_curve_from_lists_matches_hertz():
    # nine identical Hertzian asperities at h = 0: F = 4/3 a^3 / R per asperity, so
    # alpha = 9 pi a^2 / A and P* = 9 (4/3) a^3 / A with a = sqrt(R Delta)
    s = mi.CellSettings()
    c = mi.curve(gamma=[2.0] * 9, h=[0.0] * 9, steps=64)
    assert isinstance(c.alpha, np.ndarray) and c.alpha.shape == (64,)
    a = np.sqrt(c.delta)
    np.testing.assert_allclose(c.alpha, 9 * math.pi * a**2 / s.nominal_area, rtol=1e-12)
    np.testing.assert_allclose(c.p_star, 9 * 4 / 3 * a**3 / s.nominal_area, rtol=1e-12)
    assert "independent" in repr(c)


def test_models_are_objects_and_one_registry_serves_every_function(tmp_path):
    d = mi.Design(gamma=[2.0, 3.0, 4.0, 2.5], h=[0.0, 0.002, 0.004, 0.001])
    by_name = mi.curve(d, model="interacting", steps=32)
    by_object = mi.curve(d, model=mi.Interacting(), steps=32)
    np.testing.assert_array_equal(by_name.alpha, by_object.alpha)
    with_b = mi.curve(d, model=mi.Interacting(curvature=True), steps=32)
    assert with_b.model == "interacting(curvature=True)"
    assert not np.allclose(with_b.alpha, by_name.alpha)
    assert set(mi.MODELS) == {"independent", "interacting"}
    with pytest.raises(mi.MetainterfaceError, match="model must be one of"):
        mi.curve(d, model="coupled")


def test_a_registered_model_works_in_design_and_curve(monkeypatch):
    class Stiff(mi.Independent):
        """The paper's model at half the area: a test double."""

        name = "stiff"

        def sweep(self, gamma, h, settings, **kw):
            from dataclasses import replace

            sw = super().sweep(gamma, h, settings, **kw)
            return replace(sw, alpha=0.5 * sw.alpha, stiffness=2 * sw.stiffness)

    monkeypatch.setitem(mi.MODELS, "stiff", Stiff())
    d = mi.Design(gamma=[2.0] * 4, h=[0.0] * 4)
    np.testing.assert_allclose(
        mi.curve(d, model="stiff").alpha, 0.5 * mi.curve(d).alpha, rtol=1e-12
    )
    t = mi.Target(p_star=[0, 1e-4, 2e-4, 3e-4], alpha=[0, 0.004, 0.007, 0.009], name="x")
    r = mi.design(
        t,
        method="multistart",
        model="stiff",
        settings=d.settings,
        verify=False,
        effort=mi.Effort(starts=2),
    )
    assert r.model.name == "stiff" and np.isfinite(r.error)


def test_design_save_load_round_trip(tmp_path):
    d = mi.Design(gamma=np.linspace(1.8, 4.0, 9), h=np.linspace(0, 0.01, 9))
    path = d.save(tmp_path / "d.json", note="kept")
    back = mi.Design.load(path)
    np.testing.assert_array_equal(back.gamma, d.gamma)
    assert back.extras["note"] == "kept" and "N=9" in repr(back)
    assert json.loads(path.read_text())["format"] == "metainterface/design-v1"


def test_design_of_one_target_and_of_a_list(tmp_path):
    r = mi.design(
        "saturating", method="multistart", verify=False, effort=mi.Effort(starts=3, seed=1)
    )
    assert isinstance(r, mi.DesignResult) and isinstance(r.design, mi.Design)
    assert r.error < 0.05 and "saturating" in repr(r)
    both = mi.design(
        [mi.Target.builtin("bilinear"), "linear"],
        method="hertz",
        verify=False,
        effort=mi.Effort(starts=2),
    )
    assert [x.target.name for x in both] == ["bilinear", "linear"]
    assert all(np.all(x.design.gamma == 2.0) for x in both)  # the Hertz parameterisation
    ax = r.plot()
    assert ax.get_title() == "saturating" and len(ax.lines) == 2
    folder = tmp_path / "sat"
    r.save(folder)
    assert {p.name for p in folder.iterdir()} >= {"design.json", "curve.csv", "design.png"}


def test_another_design_space_falls_back_to_multistart():
    s = mi.CellSettings(n_asperities=4, gamma_min=1.5, gamma_max=3.0)
    src = mi.Design(gamma=[1.6, 2.9, 2.0, 2.5], h=[0.0, 0.004, 0.008, 0.012], settings=s)
    c = mi.curve(src, steps=64)
    t = mi.Target(p_star=c.p_star, alpha=c.alpha, name="four")
    with pytest.warns(UserWarning, match="trained for another cell"):
        r = mi.design(t, settings=s, verify=False, effort=mi.Effort(starts=4, seed=0))
    assert r.method == "multistart" and r.design.n_asperities == 4
    assert r.notes and "multistart" in r.notes[0]
    assert r.error < 0.05


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        (dict(method="gradient"), "method must be one of surrogate, multistart, hertz"),
        (dict(effort=mi.Effort(starts=0)), r"starts must be a whole number in \[1, 10000\]"),
        (dict(effort=mi.Effort(hedge=-1)), "hedge must be a whole number"),
        (dict(effort=mi.Effort(seed=2**70)), "seed must be a whole number"),
        (dict(effort=mi.Effort(seed=1.5)), "seed must be a whole number"),
        (dict(model="coupled"), "model must be one of"),
        (dict(max_pressure="50MPa"), "is a stress: give modulus"),
    ],
)
def test_design_bad_options_are_one_line_errors(kwargs, fragment):
    with pytest.raises(mi.MetainterfaceError, match=fragment) as exc:
        mi.design("saturating", **kwargs)
    assert "\n" not in str(exc.value)


def test_bad_curve_and_design_input():
    with pytest.raises(mi.MetainterfaceError, match="gamma and h must have the same length"):
        mi.curve(gamma=[2.0, 2.0, 2.0, 2.0], h=[0.0])
    with pytest.raises(mi.MetainterfaceError, match=r"gamma\[0\] = 9 is outside"):
        mi.curve(gamma=[9.0] * 4, h=[0.0] * 4)
    with pytest.raises(mi.MetainterfaceError, match="perfect square"):
        mi.curve(gamma=[2.0] * 3, h=[0.0] * 3)
    with pytest.raises(mi.MetainterfaceError, match="steps must be a whole number"):
        mi.curve(gamma=[2.0] * 4, h=[0.0] * 4, steps=10**9)
    with pytest.raises(mi.MetainterfaceError, match="give a design, or both gamma and h"):
        mi.curve()


def test_validate_and_export_as_a_user_calls_them(tmp_path):
    d = mi.Design(gamma=[2.0], h=[0.0], settings=mi.CellSettings(n_asperities=1))
    v = mi.validate(d, grid=64, loads=2)
    assert v.p_star.shape == v.alpha_bem.shape == v.alpha_model.shape == (2,)
    assert np.abs(v.rel_err).max() < 0.1
    rec = mi.export(d, tmp_path / "cell.stl", radius="0.5mm", tiles=(2, 2))
    assert rec["watertight"] and (tmp_path / "cell.stl").stat().st_size > 0
