"""The BEM check's own accuracy: Richardson's extrapolation from the check's grid and its half
against a closed-form grid error and against a finer grid; the correction stops at it, the
auto correction starts above it, and a corrected design's error is read at loads it did not
fit (test_verify.py's test_the_correction_lowers_the_bem_error)."""

import json
from dataclasses import replace

import numpy as np
import pytest

import metainterface as mi
from metainterface.cli import main
from metainterface.verify import Verify, bem_check, correct
from metainterface.verify.accuracy import ORDER, ORDER_RANGE, accuracy, coarse_grid, extrapolate
from metainterface.verify.check import AUTO_CORRECT_MARGIN
from metainterface.verify.correct import STOP_ERROR, settled, stop_error

# 192^2: the coarsest grid whose half (96^2, 32 points per asperity) is on the area's h^p
# course; 4 loads keep each solve about a second
QUICK = Verify(grid=192, loads=4, correct=False, max_error=0.1)


@pytest.fixture(scope="module")
def design():
    return mi.design("bilinear", verify=False)


@pytest.fixture(scope="module")
def checked(design):
    return bem_check(design.design, design.target, QUICK, design.model)


def test_the_coarse_grid_is_half_on_the_lattice():
    assert coarse_grid(384, 3) == 192 and coarse_grid(192, 3) == 96
    assert coarse_grid(201, 3) == 99  # 100.5 rounded down to a multiple of n = 3
    assert coarse_grid(768, 4) == 384
    # below 32 points per asperity pitch the grid cannot estimate its own error
    assert coarse_grid(96, 3) is None and coarse_grid(190, 3) is None


def test_a_grid_too_coarse_says_so(design):
    b = bem_check(design.design, design.target, replace(QUICK, grid=96), design.model)
    assert b.accuracy is None and b.coarse_grid is None and b.alpha_coarse is None
    np.testing.assert_array_equal(b.alpha_bem, b.alpha_grid)  # not extrapolated
    assert any("too coarse to estimate its own error" in n for n in b.notes)
    assert "+-" not in repr(b) and b.to_dict()["accuracy"] is None


@pytest.mark.parametrize("p", [ORDER_RANGE[0], ORDER, ORDER_RANGE[1]])
def test_the_accuracy_bounds_a_grid_error_of_any_order_in_its_range(p):
    # closed form: alpha_M = alpha + c h^p, h = 1 / M; the extrapolation (at ORDER) is exact
    # for p = ORDER and off by at most the stated accuracy for p in ORDER_RANGE (met at the
    # slower end, hence a margin of rounding only)
    exact = np.array([0.01, 0.02, 0.03, 0.04, 0.05])
    c = np.array([40.0, 35.0, 20.0, 25.0, 10.0])
    fine, coarse = exact + c / 384.0**p, exact + c / 192.0**p
    off = np.linalg.norm(extrapolate(fine, coarse, 2.0) - exact) / np.linalg.norm(exact)
    acc = accuracy(fine, coarse, 2.0, exact)
    assert off <= acc * (1 + 1e-9)
    if p == ORDER:
        assert off == pytest.approx(0.0, abs=1e-15)
    elif p == ORDER_RANGE[0]:  # the slower end moves it most: there the bound is met
        assert off == pytest.approx(acc, rel=1e-9)


def test_the_check_states_its_accuracy_from_two_grids(checked):
    assert checked.coarse_grid == 96 and checked.accuracy is not None and not checked.notes
    np.testing.assert_allclose(
        checked.alpha_bem, extrapolate(checked.alpha_grid, checked.alpha_coarse, 2.0)
    )
    # the grid's own error is what the accuracy measures: 96^2 reads this design 3.8 points
    # further off its target than 192^2 does, so the accuracy is of a point's size, not 0
    assert 1e-3 < checked.accuracy < 0.05
    record = checked.to_dict()
    assert record["accuracy"] == checked.accuracy and record["coarse_grid"] == 96
    assert record["load_set"] == "k / K" and len(record["alpha_grid"]) == 4
    assert f"+- {100 * checked.accuracy:.2g} %" in repr(checked)


def test_the_accuracy_covers_a_grid_twice_as_fine(design, checked):
    # a finer reference: the same design on 384^2 (extrapolated with 192^2) at the same
    # loads; each estimate is within its accuracy of the grid-free answer, so they differ
    # by no more than the sum of the two (no margin: the bound is the claim)
    fine = bem_check(design.design, design.target, replace(QUICK, grid=384), design.model)
    np.testing.assert_allclose(fine.p_star, checked.p_star)
    assert fine.accuracy < checked.accuracy  # the finer pair resolves more
    assert abs(fine.bem_error - checked.bem_error) <= fine.accuracy + checked.accuracy


def test_the_correction_stops_where_the_check_cannot_show_a_gain(design, checked):
    assert stop_error(replace(checked, accuracy=None)) == STOP_ERROR
    assert stop_error(replace(checked, accuracy=1e-4)) == STOP_ERROR
    # a step takes off at most the error less the accuracy (the check's floor): settled
    # once that is within the accuracy, i.e. the error within twice it
    e = checked.bem_error
    assert settled(replace(checked, accuracy=0.55 * e))
    assert not settled(replace(checked, accuracy=0.45 * e))
    within = replace(checked, accuracy=0.55 * e)
    assert stop_error(within) == within.accuracy
    s = replace(QUICK, correct=True)
    out = correct(design.design, design.target, within, s, design.model)
    assert out.corrections == () and out.check is within and out.design is design.design


def test_the_auto_correction_starts_above_the_accuracy(checked):
    auto = Verify()
    acc = 4e-3  # above AUTO_CORRECT_MARGIN (2e-3): the accuracy is the margin
    at = replace(checked, model_error=1e-3, accuracy=acc)
    assert not auto.wants_correction(replace(at, bem_error=1e-3 + 0.99 * acc))
    assert auto.wants_correction(replace(at, bem_error=1e-3 + 1.01 * acc))
    fine = replace(at, accuracy=None)  # not estimated: the fixed margin
    assert not auto.wants_correction(replace(fine, bem_error=1e-3 + 0.99 * AUTO_CORRECT_MARGIN))
    assert auto.wants_correction(replace(fine, bem_error=1e-3 + 1.01 * AUTO_CORRECT_MARGIN))


def test_a_design_prints_and_records_its_error_with_its_accuracy(design, checked, tmp_path):
    r = replace(design, bem=checked)
    assert f"BEM error {checked.error_text()}" in repr(r)
    assert checked.error_text() == (
        f"{100 * checked.bem_error:.3g} % +- {100 * checked.accuracy:.2g} %"
    )
    r.save(tmp_path)
    block = json.loads((tmp_path / "design.json").read_text())["bem_check"]
    assert block["bem_error"] == pytest.approx(checked.bem_error)
    assert block["accuracy"] == pytest.approx(checked.accuracy)
    assert block["load_set"] == "k / K" and block["coarse_grid"] == 96


def test_cli_prints_the_accuracy_beside_the_error(tmp_path, capsys):
    args = ["design", "--target", "bilinear", "--out", str(tmp_path), "--verify-grid", "192"]
    args += ["--verify-loads", "4", "--no-correct", "--max-bem-error", "10"]
    assert main(args) == 0
    lines = capsys.readouterr().out.splitlines()
    block = json.loads((tmp_path / "design.json").read_text())["bem_check"]
    assert lines[0].split()[-4:] == ["BEM", "+-", "BEM", "s"]
    row = lines[1].split()
    assert row[-5:-1] == [
        f"{100 * block['bem_error']:.3g}",
        "%",
        f"{100 * block['accuracy']:.2g}",
        "%",
    ]
    assert any("+-: the check's own accuracy" in line for line in lines)
