"""Friction laws with adhesion (issue 38): an offset F_f(0) > 0 accepted and kept, the fit's
free offset, the adhesive reach, and a law from a held-back adhesive cell designed."""

import importlib
import math
import warnings

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface._testing import adhesive_cell_curve
from metainterface.errors import MetainterfaceError
from metainterface.physics import CellSettings
from metainterface.physics.adhesion import touch_grid
from metainterface.physics.metrics import interp
from metainterface.units._lawfit import fit_law
from metainterface.units.friction import (
    FrictionLaw,
    friction_target,
    friction_target_from_options,
)
from metainterface.units.quantities import parse_work_of_adhesion
from metainterface.units.reach import alpha_bounds

# PDMS on glass: w = 50 mJ/m^2, E* = 2.4 MPa, R = 0.5 mm; tau 0.3 MPa over 4 cm^2
E, R, W_J, TAU, AREA = 2.4e6, 0.5e-3, 0.05, 0.3e6, 4e-4
W = W_J / (E * R)
UNITS = dict(shear_strength="0.3MPa", modulus="2.4MPa", radius="0.5mm")


def _held_back_law(seed=11, rows=24):
    """An adhesive cell's loading curve as a friction law [N] (rows from zero load)."""
    p, a = adhesive_cell_curve(W, seed=seed, rows=rows)
    return p * AREA * E, a * TAU * AREA


def _write(tmp_path, fn, ff):
    path = tmp_path / "pdms.csv"
    path.write_text(
        "normal_force,friction_force\n"
        + "".join(f"{x:.12g},{y:.12g}\n" for x, y in zip(fn, ff, strict=True))
    )
    return path


@pytest.mark.parametrize("fit", ["auto", "always"])
def test_a_fit_does_not_pin_an_adhesive_offset_to_zero_unasked(tmp_path, fit):
    """Without w, a fit pins F_f(0) at 0: a law whose zero-load friction is a real share of
    it is refused, naming the row and the option, not designed as another law; a sensor's
    offset (below 5 % of the largest friction) is fitted away as before."""
    fn, ff = _held_back_law()
    path = _write(tmp_path, fn, ff)
    opts = dict(shear_strength=TAU, e_star=E, radius=R, area=AREA, fit=fit)
    with pytest.raises(MetainterfaceError, match=r"row 1: friction .* zero normal force \(1"):
        friction_target(path, **opts)
    with pytest.raises(MetainterfaceError, match="--work-of-adhesion"):  # its fit is "auto"
        mi.reachability(path, area="4cm2", **UNITS)
    assert friction_target(path, work_of_adhesion=W_J, **opts).law.friction_force[0] > 0
    small = ff - ff[0] + 0.02 * ff[-1]  # an offset of 2 % of the largest friction
    ft = friction_target(_write(tmp_path, fn, small), **opts)
    assert ft.law.friction_force[0] == 0.0


def test_units():
    assert parse_work_of_adhesion("50mJ/m2") == pytest.approx(0.05)
    assert parse_work_of_adhesion("0.05 N/m") == pytest.approx(0.05)
    with pytest.raises(MetainterfaceError, match="--work-of-adhesion"):
        parse_work_of_adhesion("2MPa", option="--work-of-adhesion")


def test_offset_law_accepted_only_with_adhesion(tmp_path):
    fn, ff = _held_back_law()
    path = _write(tmp_path, fn, ff)
    opts = dict(shear_strength=TAU, e_star=E, radius=R, area=AREA, fit="never")
    with pytest.raises(MetainterfaceError, match="work-of-adhesion"):
        friction_target(path, **opts)
    ft = friction_target(path, work_of_adhesion=W_J, **opts)
    assert ft.alpha[0] == pytest.approx(ff[0] / (TAU * AREA))  # kept, not forced to 0
    assert ft.adhesion == pytest.approx(W)
    assert ft.record()["work_of_adhesion_j_m2"] == W_J
    # without a zero-load row, the origin added carries the extrapolated offset
    ft2 = friction_target(
        FrictionLaw(fn[3:], ff[3:], np.arange(3, 24)), work_of_adhesion=W_J, **opts
    )
    slope = (ff[4] - ff[3]) / (fn[4] - fn[3])
    assert ft2.law.friction_force[0] == pytest.approx(ff[3] - slope * fn[3])
    assert 0 < ft2.law.friction_force[0] < ff[3]
    cli = friction_target_from_options(
        path,
        shear_strength="0.3MPa",
        modulus="2.4MPa",
        radius="0.5mm",
        area="4cm2",
        work_of_adhesion="50mJ/m2",
        fit="never",
    )
    assert cli.adhesion == pytest.approx(W)
    with pytest.raises(MetainterfaceError, match="work of adhesion"):
        friction_target(path, work_of_adhesion=-1.0, **opts)


def test_fit_keeps_the_offset():
    """F_f = F0 + k F_n^0.7 with 2 % noise: the offset fit finds F0; without, F_f(0) = 0."""
    rng = np.random.default_rng(0)
    fn = np.linspace(0, 2.0, 40)
    ff = 1.5 + 3.0 * fn**0.7
    noisy = ff * (1 + 0.02 * rng.standard_normal(fn.size))
    fit = fit_law(fn, noisy, offset=True)
    assert float(fit(np.array([0.0]))[0]) == pytest.approx(1.5, rel=0.1)
    _, y = fit.sample()
    assert y[0] > 1.2 and np.all(np.diff(y) >= 0)
    assert fit_law(fn, noisy).sample()[1][0] == 0.0


def test_adhesive_reach_holds_adhesive_cells():
    """Random adhesive cells lie within the adhesive bounds at their loads, and reach zero
    load with a positive area (the adhesionless bounds give none there)."""
    s = CellSettings()
    rng = np.random.default_rng(5)
    g = torch.as_tensor(rng.uniform(1.8, 4.0, (6, 9)))
    h = torch.as_tensor(rng.uniform(0, 1.0, (6, 9)) * s.delta_max)
    model = mi.Independent(adhesion=W)
    with torch.no_grad():
        sw = model.sweep(g, h, s, n_delta=513)
    for b in range(6):
        p = sw.p_star[b].numpy()
        keep = p > 0
        lo, hi, reach = alpha_bounds(p[keep], s, adhesion=W)
        a = sw.alpha[b].numpy()[keep]
        assert np.all(a >= lo * (1 - 1e-3)) and np.all(a <= hi * (1 + 1e-3))
        assert p.max() <= reach * (1 + 1e-9)
    lo, _, _ = alpha_bounds(np.array([1e-7]), s, adhesion=W)
    assert lo[0] > 0


@pytest.mark.long
def test_offset_law_designed_within_two_percent(tmp_path):
    """The issue's check: an offset law of a held-back adhesive cell (PDMS, 50 mJ/m^2)
    designed with the work of adhesion, within 2 %, and checked in the adhesive BEM."""
    fn, ff = _held_back_law()
    path = _write(tmp_path, fn, ff)
    scale = dict(shear_strength=TAU, modulus=E, radius=R, area=AREA, fit="never")
    target = mi.Target.from_friction(path, work_of_adhesion="50mJ/m2", **scale)
    assert mi.reachability(target).reachable
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        checks = mi.Verify(grid=96, correct=False)
        result = mi.design(target, verify=checks, effort=mi.Effort(seed=0))
    assert result.model.adhesion == pytest.approx(W)
    assert result.error < 0.02
    # checked in the adhesive BEM (a coarse grid here: a / dx ~ 5-10, see bench_adhesion),
    # which bounds its own error from 96^2 and 48^2: the BEM meets the target as the model
    # does, within that bound (a bound the JKR sphere holds, tests/verify/test_adhesive_bound)
    bem = result.bem
    assert bem is not None and bem.adhesion == pytest.approx(W)
    assert bem.p_star.size >= 2 and bem.grid == 96 and bem.coarse_grid == 48
    assert 0 < bem.accuracy < 0.2
    assert bem.bem_error <= bem.model_error + bem.accuracy
    # the offset F_0, one point of the curve error, is stated on its own: the law's is the
    # CSV's zero-load row; the last polish that weighs it (inverse.offset) brought it from
    # +74 % to within 1 % (benchmarks/results/adhesion.md)
    (zero,) = [n for n in result.notes if "friction at zero load" in n]
    assert f"the law's {ff[0]:.3g} N" in zero
    assert any("F_0 (the law's offset) weighed in a last polish" in n for n in result.notes)
    f0 = float(zero.split("friction at zero load ")[1].split(" N")[0])
    assert f0 == pytest.approx(ff[0], rel=0.01)


@pytest.mark.long
def test_an_extrapolated_offset_gets_no_offset_polish(tmp_path):
    """The F_0 polish is for laws that give their friction at zero load: a law from a
    positive load has its F_0 extrapolated from its first two rows, which the notes say, and
    not weighed above the rest."""
    fn, ff = _held_back_law()
    path = _write(tmp_path, fn[1:], ff[1:])
    scale = dict(shear_strength=TAU, modulus=E, radius=R, area=AREA, fit="never")
    target = mi.Target.from_friction(path, work_of_adhesion="50mJ/m2", **scale)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        effort = mi.Effort(seed=0, hedge=0, fallback=0)
        result = mi.design(target, verify=False, effort=effort)
    assert result.model.adhesion == pytest.approx(W)
    assert not any("last polish" in n for n in result.notes)
    assert target.meta["friction"]["offset"] == "extrapolated"
    (zero,) = [n for n in result.notes if "friction at zero load" in n]
    assert "extrapolated from its first two rows" in zero


def test_friction_law_designs_say_what_adhesion_would_change(tmp_path):
    """Item 6: a friction-law design without adhesion states how much a typical w would
    change its law; one with adhesion states its pull-off force."""
    fn = np.linspace(0.2, 2.0, 12)
    path = _write(tmp_path, fn, 0.9 * fn**0.8)
    scale = dict(shear_strength="0.06MPa", modulus=E, radius=R, area=AREA)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plain = mi.design(
            mi.Target.from_friction(path, **scale), verify=False, effort=mi.Effort(refine=False)
        )
        sticky = mi.design(
            mi.Target.from_friction(path, work_of_adhesion=W_J, **scale),
            verify=False,
            effort=mi.Effort(refine=False),
        )
    note = [n for n in plain.notes if n.startswith("adhesion:")]
    assert len(note) == 1 and "at w = 50 mJ/m^2" in note[0] and "at zero load" in note[0]
    assert any(n.startswith("adhesion: pull-off force") for n in sticky.notes)


def test_design_takes_a_work_of_adhesion_with_its_scale():
    quick = dict(method="multistart", effort=mi.Effort(starts=2, refine=False), verify=False)
    sticky = mi.Scale(modulus="2.4MPa", radius="0.5mm", work_of_adhesion="50mJ/m2")
    r = mi.design("bilinear", scale=sticky, **quick)
    assert r.model.adhesion == pytest.approx(W)
    assert np.isfinite(r.error)
    with pytest.raises(MetainterfaceError, match="work_of_adhesion needs the modulus"):
        mi.design("bilinear", scale=mi.Scale(work_of_adhesion="50mJ/m2"), **quick)


def test_the_notes_are_of_the_design_the_bem_corrected(tmp_path, monkeypatch):
    """A design corrected in BEM is another design: its friction at zero load and pull-off
    force are stated for it, not for the design before the correction."""
    # on this coarse grid the check's own error is within half its BEM error, where the
    # correction rightly stops before a step (tests/verify/test_accuracy.py): one is forced
    correct_module = importlib.import_module("metainterface.verify.correct")
    monkeypatch.setattr(correct_module, "settled", lambda check: False)
    # and kept whatever its F_0 (the guard that holds F_0 within 2 % rejects this coarse
    # grid's step: tests/verify/test_adhesive_verify.py tests the guard)
    monkeypatch.setattr(correct_module, "f0_error", lambda *args: None)
    path = _write(tmp_path, *_held_back_law())
    scale = dict(shear_strength=TAU, modulus=E, radius=R, area=AREA, fit="never")
    target = mi.Target.from_friction(path, work_of_adhesion="50mJ/m2", **scale)
    quick = mi.Effort(refine=False, seed=0)
    checks = mi.Verify(grid=48, loads=4, correct=True, iterations=1, restart=False, inner=None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        before = mi.design(target, verify=False, effort=quick)
        after = mi.design(target, verify=checks, effort=quick)
    assert after.corrections and not np.allclose(after.design.h, before.design.h)
    gamma, h = after.design.tensors(torch.float64)
    # F_0 read another way than the note's Newton solve: a fine sweep with a knot at every
    # touch, at the zero-load state (the end of the snap-in's plateau)
    s, model = after.design.settings, after.model
    loads = torch.tensor([[0.0, float(target.p_star_max)]], dtype=torch.float64)
    zero_load = model.loads_read(loads)
    with torch.no_grad():
        fine = model.load_area(gamma, h, s, delta=touch_grid(h, s, 65537)[0])
        alpha0 = float(interp(zero_load, fine.p_star, fine.alpha)[0, 0])
    (zero,) = [n for n in after.notes if "friction at zero load" in n]
    stated = float(zero.split("friction at zero load ")[1].split(" N")[0])
    # the note gives 3 significant digits: half a unit of the third is its rounding
    half_unit = 0.5 * 10 ** (math.floor(math.log10(stated)) - 2)
    assert stated == pytest.approx(alpha0 * TAU * AREA, abs=half_unit * (1 + 1e-9))
    (zero_before,) = [n for n in before.notes if "friction at zero load" in n]
    assert zero != zero_before
    assert "corrected in BEM" in zero and "corrected in BEM" not in zero_before


def test_a_work_of_adhesion_without_a_unit_warns_like_the_modulus():
    """'5' is read as 5 J/m^2, above any soft contact's (issue 52): a unit-slip warning
    with the likely unit, as --modulus 2.4 gets; a plausible one says nothing."""
    import warnings

    from metainterface.errors import UnitSlipWarning
    from metainterface.units.plausible import unit_slips

    said = unit_slips(work_of_adhesion=5.0)
    assert len(said) == 1 and "5 J/m^2" in said[0] and "(5mJ/m2)" in said[0]
    assert unit_slips(work_of_adhesion=0.05) == []
    assert "mJ/m2" in unit_slips(work_of_adhesion=5e-6)[0]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        from metainterface.designer.adhesion import given_adhesion

        given_adhesion(5, "2.4MPa", "0.5mm")
    assert [w for w in caught if issubclass(w.category, UnitSlipWarning)]
