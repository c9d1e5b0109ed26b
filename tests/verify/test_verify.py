"""Designs checked and corrected in BEM: mi.design(verify=...), the CLI's exit status 3, the
design.json block and the figure. Small grids (96^2, 4 loads) keep each solve well under a
second; what the check measures at the paper's resolution is benchmarks/bench_verified.py's."""

import json
from dataclasses import replace

import numpy as np
import pytest

import metainterface as mi
from metainterface.cli import main
from metainterface.physics.registry import get_model
from metainterface.verify import BemCheck, Verify, bem_check
from metainterface.verify.check import curve_error
from metainterface.verify.correct import (
    curve_fit_error,
    fresh_design,
    model_error,
    shifted_target,
)

# at 96^2 the BEM reads the bilinear design ~5 % high by itself (the grid), hence max_error
QUICK = Verify(grid=96, loads=4, correct=False, max_error=0.1)


@pytest.fixture(scope="module")
def unchecked():
    return mi.design("bilinear", verify=False)


@pytest.fixture(scope="module")
def checked():
    return mi.design("bilinear", verify=QUICK)


@pytest.fixture(scope="module")
def corrected():
    return mi.design("bilinear", verify=Verify(grid=96, loads=4, correct=True, iterations=2))


def test_the_check_reports_the_bem_error_to_the_target(checked, unchecked):
    b = checked.bem
    assert isinstance(b, BemCheck) and b.grid == 96 and b.p_star.size == 4
    # uniform loads over the target's range, the target interpolated there
    t = checked.target
    np.testing.assert_allclose(b.p_star, t.p_star_max * np.arange(1, 5) / 4, rtol=1e-5)
    # it reaches the end of the target (to 2e-6); 96^2 is too coarse to estimate its own
    # error (test_accuracy.py measures that on 192^2), and says so
    assert len(b.notes) == 1 and "too coarse to estimate its own error" in b.notes[0]
    np.testing.assert_allclose(b.alpha_target, np.interp(b.p_star, t.p_star, t.alpha))
    assert checked.bem_error == pytest.approx(curve_error(b.alpha_bem, b.alpha_target))
    # the design meets this target in the model
    assert b.model_error < 1e-3
    # 96^2 states no accuracy of its own: the reference is the check on 192^2, whose half is
    # this very solve, extrapolated from the two with its accuracy (0.66 % +- 0.57 % here)
    fine = bem_check(checked.design, checked.target, replace(QUICK, grid=192), checked.model)
    np.testing.assert_allclose(fine.alpha_coarse, b.alpha_bem, rtol=1e-9)
    # grid-free, the design is within the 2 % a design is trusted at (Verify.max_error)
    # wherever in its accuracy the error lies; 96^2 reads it off by more (5.1 %): the grid's
    assert fine.bem_error + fine.accuracy <= Verify().max_error
    assert b.bem_error > fine.bem_error + fine.accuracy
    # per load, the BEM reads the model's cell within those 2 % (1.3 % at most grid-free)
    # plus 96^2's own grid error, bounded by the two-grid 2 |alpha_96 - alpha_192| for any
    # order p >= 1 (2^p / (2^p - 1) <= 2; 1.4 at the measured 1.7-1.8): no further margin
    grid_error = 2 * np.abs(b.alpha_bem - fine.alpha_grid) / b.alpha_model
    assert (np.abs(b.rel_err) <= grid_error + Verify().max_error).all()
    assert checked.bem_ok is True and checked.bem_before is None and not checked.corrections
    # not corrected: the design is the unchecked one, and verify=False adds nothing
    np.testing.assert_array_equal(checked.design.gamma, unchecked.design.gamma)
    assert unchecked.bem is None and unchecked.bem_error is None and unchecked.bem_ok is None
    assert "BEM error" in repr(checked) and "BEM" not in repr(unchecked)


@pytest.mark.long
def test_the_correction_lowers_the_bem_error(corrected):
    before, after = corrected.bem_before, corrected.bem
    assert before is not None and after.bem_error < before.bem_error
    assert 1 <= len(corrected.corrections) <= 2
    kept = [c.bem_error for c in corrected.corrections if c.accepted]
    assert all(b < a for a, b in zip([before.bem_error, *kept], kept, strict=False))
    # the iterations fit the loads k / K; the result's error is read at the interleaved
    # (k - 1/2) / K, which none of them fitted
    s = Verify(grid=96, loads=4)
    fitted = bem_check(corrected.design, corrected.target, s)
    assert kept and kept[-1] == pytest.approx(fitted.bem_error, rel=1e-6)
    assert not before.held_out and not fitted.held_out and after.held_out
    top = fitted.p_star[-1]
    np.testing.assert_allclose(after.p_star, top * (np.arange(1, 5) - 0.5) / 4, rtol=1e-12)
    # the result is the corrected design: its BEM check and model error are its own
    again = bem_check(corrected.design, corrected.target, s, held_out=True)
    assert again.bem_error == pytest.approx(after.bem_error, rel=1e-6)
    assert corrected.error > 1e-3  # it now misses the target in the model, on purpose


def test_the_shifted_target_adds_the_defect():
    t = mi.Target(p_star=[0.0, 1.0, 2.0, 3.0], alpha=[0.0, 0.1, 0.2, 0.3])
    check = BemCheck(
        p_star=np.array([1.0, 2.0]),
        alpha_bem=np.array([0.11, 0.22]),
        alpha_model=np.array([0.10, 0.20]),
        alpha_target=np.array([0.1, 0.2]),
        bem_error=0.1,
        model_error=0.0,
        grid=96,
        engine="tamaas",
        device="cpu",
        seconds=0.0,
    )
    p, a = shifted_target(t, check, 0.5)
    # defect model - BEM: 0 at P* = 0, -0.01 and -0.02 at the loads, held beyond
    np.testing.assert_allclose(a, [0.0, 0.095, 0.19, 0.29])
    np.testing.assert_array_equal(p, t.p_star)


def test_the_shifted_target_takes_the_correction_models_alpha():
    t = mi.Target(p_star=[0.0, 1.0, 2.0, 3.0], alpha=[0.0, 0.1, 0.2, 0.3])
    check = BemCheck(
        p_star=np.array([1.0, 2.0]),
        alpha_bem=np.array([0.11, 0.22]),
        alpha_model=np.array([0.10, 0.20]),
        alpha_target=np.array([0.1, 0.2]),
        bem_error=0.1,
        model_error=0.0,
        grid=96,
        engine="tamaas",
        device="cpu",
        seconds=0.0,
    )
    # the correction's own model reads 0.105 and 0.23 there: defect -0.005 and +0.01
    _, a = shifted_target(t, check, 1.0, alpha_model=np.array([0.105, 0.23]))
    np.testing.assert_allclose(a, [0.0, 0.095, 0.21, 0.31])


@pytest.mark.long
def test_the_correction_runs_on_the_model_asked_for(corrected):
    # corrected: the default, re-refined on the interacting model; "independent" and None
    # (the design's own model, here independent) re-refine on the paper's model alike
    s = Verify(grid=96, loads=4, correct=True, iterations=1, inner="independent")
    paper = mi.design("bilinear", verify=s)
    own = mi.design("bilinear", verify=replace(s, inner=None))
    assert paper.bem.bem_error < paper.bem_before.bem_error
    np.testing.assert_allclose(paper.design.gamma, own.design.gamma)
    np.testing.assert_allclose(paper.design.h, own.design.h)
    assert not np.allclose(paper.design.gamma, corrected.design.gamma)
    # whichever model corrects, the result's model error is on the design's model
    on_design_model = model_error(corrected.design, corrected.target, get_model(corrected.model))
    assert corrected.error == pytest.approx(on_design_model, rel=1e-9)


@pytest.mark.long
def test_each_iteration_says_where_its_design_came_from(corrected):
    # the default also designs afresh against the shifted target; restart=False only
    # re-refines the kept design
    assert {c.start for c in corrected.corrections} <= {"current", "fresh"}
    s = Verify(grid=96, loads=4, correct=True, iterations=2, restart=False)
    r = mi.design("bilinear", verify=s)
    assert [c.start for c in r.corrections] == ["current"] * len(r.corrections)
    assert r.corrections[0].to_dict()["start"] == "current"


@pytest.mark.long
def test_a_fresh_design_meets_a_realisable_shifted_target(unchecked):
    # realisable: a design's own curve on the correction's default model (the module's
    # bilinear design, not one made for this test)
    fm = get_model("interacting")
    curve = fm.model_curve(unchecked.design)
    fresh = fresh_design((curve.p_star, curve.alpha), unchecked.design.settings, fm, seed=0)
    assert fresh is not None
    assert curve_fit_error(fresh, (curve.p_star, curve.alpha), fm) < 0.01


def test_cli_correct_model_reaches_the_correction(tmp_path, capsys, monkeypatch):
    # --correct-model reaches the correction as its Verify.inner ("design": the design's own
    # model, None); what each inner does there is test_the_correction_runs_on_the_model_asked_for's,
    # a whole CLI correction test_cli_reports_each_correction_iteration's. The spy checks the
    # settings the correction gets, then runs the check alone (no correction iterations).
    from metainterface.designer import verified as verified_module

    real, seen = verified_module.verified, []

    def spy(r, settings, **kw):
        seen.append((settings.correct, settings.inner, settings.grid, settings.loads))
        return real(r, replace(settings, correct=False), **kw)

    monkeypatch.setattr(verified_module, "verified", spy)
    args = ["design", "--target", "bilinear", "--verify-grid", "96", "--verify-loads", "4"]
    args += ["--correct", "--max-bem-error", "10"]
    for name in ("independent", "design"):
        assert main([*args, "--out", str(tmp_path / name), "--correct-model", name]) == 0
        assert json.loads((tmp_path / name / "design.json").read_text())["bem_check"]["ok"]
    capsys.readouterr()
    assert seen == [(True, "independent", 96, 4), (True, None, 96, 4)]
    with pytest.raises(SystemExit) as done:
        main([*args, "--out", str(tmp_path / "x"), "--correct-model", "fem"])
    assert done.value.code == 2 and "--correct-model" in capsys.readouterr().err


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"loads": 1}, "loads"),
        ({"grid": 2}, "grid"),
        ({"iterations": 0}, "iterations"),
        ({"max_error": 0.0}, "max_error"),
        ({"max_error": 2.0}, "max_error"),
        ({"engine": "fem"}, "engine"),
        ({"correct": "yes"}, "correct"),
        ({"device": 3}, "device"),
        ({"inner": "fem"}, "inner"),
        ({"restart": "yes"}, "restart"),
    ],
)
def test_bad_settings_give_one_line_naming_the_field(kwargs, name):
    with pytest.raises(mi.MetainterfaceError) as err:
        Verify(**kwargs)
    assert str(err.value).startswith(name) and "\n" not in str(err.value)


def test_bad_verify_arguments_fail_before_the_design():
    with pytest.raises(mi.MetainterfaceError, match="verify must be True, False or a Verify"):
        mi.design("bilinear", verify="yes")
    with pytest.raises(mi.MetainterfaceError, match="grid must be a multiple of the lattice"):
        mi.design(
            "bilinear",
            verify=Verify(grid=97),
            method="hertz",
            effort=mi.Effort(starts=1, refine=False),
        )


def test_design_json_and_figure_carry_the_check(checked, tmp_path):
    checked.save(tmp_path)
    block = json.loads((tmp_path / "design.json").read_text())["bem_check"]
    assert block["bem_error"] == pytest.approx(checked.bem_error)
    assert block["grid"] == 96 and block["loads"] == 4 and block["ok"] is True
    assert len(block["alpha_bem"]) == 4 and "uncorrected" not in block
    fig = checked.figure()
    labels = [line.get_label() for line in fig.axes[0].get_lines()]
    assert any(label.startswith("BEM 96") for label in labels)
    assert "BEM" in fig._suptitle.get_text()


@pytest.mark.long
def test_a_corrected_design_records_its_iterations(corrected, tmp_path):
    corrected.save(tmp_path)
    block = json.loads((tmp_path / "design.json").read_text())["bem_check"]
    assert block["uncorrected"]["bem_error"] == pytest.approx(corrected.bem_before.bem_error)
    assert [c["iteration"] for c in block["corrections"]] == list(
        range(1, len(corrected.corrections) + 1)
    )


def test_cli_exits_3_above_max_bem_error(tmp_path, capsys):
    out = tmp_path / "d"
    args = ["design", "--target", "bilinear", "--out", str(out), "--verify-grid", "96"]
    args += ["--verify-loads", "4", "--no-correct", "--max-bem-error", "0.001"]
    assert main(args) == 3
    text = capsys.readouterr().out
    assert "BEM" in text.splitlines()[0]
    assert "is above --max-bem-error 0.001 %" in text
    block = json.loads((out / "design.json").read_text())["bem_check"]
    assert block["ok"] is False
    # beside it, the model's own error at the same loads: the design's miss or the mechanics
    assert f"the model's error at the same loads: {100 * block['model_error']:.3g} %" in text


def test_cli_no_verify_and_bad_options(tmp_path, capsys):
    assert main(["design", "--target", "bilinear", "--out", str(tmp_path), "--no-verify"]) == 0
    assert "BEM" not in capsys.readouterr().out
    assert "bem_check" not in json.loads((tmp_path / "design.json").read_text())
    bad = ["design", "--target", "bilinear", "--out", str(tmp_path / "x"), "--verify-grid", "97"]
    assert main(bad) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--verify-grid must be a multiple" in err
    assert main([*bad[:-2], "--max-bem-error", "150"]) == 2
    assert "--max-bem-error must be a percentage" in capsys.readouterr().err


def test_the_engine_and_device_reach_the_solver_and_fail_early(unchecked):
    s = Verify(grid=96, loads=3, engine="tamaas")
    tam = bem_check(unchecked.design, unchecked.target, s, unchecked.model)
    ours = bem_check(unchecked.design, unchecked.target, Verify(grid=96, loads=3, device="cpu"))
    assert (tam.engine, tam.device) == ("tamaas", "cpu") and (ours.engine, ours.device) == (
        "torch",
        "cpu",
    )
    np.testing.assert_allclose(ours.alpha_bem, tam.alpha_bem, rtol=1e-6)
    with pytest.raises(mi.MetainterfaceError, match="device"):
        mi.design(
            "bilinear", verify=Verify(device="tpu"), method="hertz", effort=mi.Effort(refine=False)
        )


def test_cli_engine_option_names_itself(tmp_path, capsys):
    args = ["design", "--target", "bilinear", "--out", str(tmp_path), "--verify-engine", "fem"]
    with pytest.raises(SystemExit) as done:  # argparse's own one-line error
        main(args)
    assert done.value.code == 2 and "--verify-engine" in capsys.readouterr().err


@pytest.mark.long
def test_cli_reports_each_correction_iteration(tmp_path, capsys):
    # corrected on the paper's model: the report is what is under test, and its fresh
    # designs cost two thirds of the interacting model's
    args = ["design", "--target", "bilinear", "--out", str(tmp_path), "--verify-grid", "96"]
    args += ["--verify-loads", "4", "--correct", "--max-bem-error", "10"]
    args += ["--correct-model", "independent"]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "bilinear corrected in BEM:" in text and "iterations, at the loads they fit: " in text
    # the error it reports is read between the loads the iterations fitted
    assert "% at 4 loads between those" in text
    block = json.loads((tmp_path / "design.json").read_text())["bem_check"]
    assert len(block["corrections"]) == 3 and block["bem_error"] < block["uncorrected"]["bem_error"]
