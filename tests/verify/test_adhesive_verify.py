"""Adhesive designs checked and corrected in the adhesive (JKR-limit) BEM, as a user calls
it (issue 38): the check compares under a rising force, the correction runs, design.json
records it, and the command line's exit status follows the BEM error."""

import json
import warnings

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface.cli import main
from metainterface.physics import CellSettings

# PDMS on glass: w = 50 mJ/m^2, E* = 2.4 MPa, R = 0.5 mm
W = 0.05 / (2.4e6 * 0.5e-3)
QUICK = mi.Effort(refine=False, seed=0)


def _held_back(seed: int, spread: float, loads: int, top: float):
    """A random adhesive cell (heights in [0, spread] Delta_max) and its own loading curve
    under Independent(adhesion=W), ``loads`` loads from zero to ``top`` of its reach."""
    from metainterface.physics import Design

    s = CellSettings()
    rng = np.random.default_rng(seed)
    g = rng.uniform(1.8, 4.0, 9)
    h = rng.uniform(0, spread, 9) * s.delta_max
    h -= h.min()
    model = mi.Independent(adhesion=W)
    gt, ht = torch.as_tensor(g)[None], torch.as_tensor(h)[None]
    with torch.no_grad():
        p_max = float(model.sweep(gt, ht, s).p_star[0, -1])
        p = np.linspace(0, top * p_max, loads)
        p[0] = 1e-12 * p_max
        a = model.alpha_at_loads(gt, ht, s, torch.as_tensor(p)[None])[0].numpy()
    return Design(gamma=g, h=h, settings=s), mi.Target(p_star=p, alpha=a, name="sticky")


@pytest.fixture(scope="module")
def sticky_target():
    """The loading curve of a held-back adhesive cell (16 loads from zero)."""
    return _held_back(3, 0.6, 16, 0.9)[1]


@pytest.fixture(scope="module")
def corrected():
    """A design whose check reads an error well outside its own accuracy (a cell taller
    than ``sticky_target``'s, loaded to its reach: 7.2 % +- 0.6 % at 144^2, the model's
    6.2 %), so that the correction runs; at 48^2 and 4 loads the check's accuracy is as
    large as its error, and the correction rightly stops there."""
    model = mi.Independent(adhesion=W)
    target = _held_back(5, 1.0, 16, 1.0)[1]
    checks = mi.Verify(grid=144, loads=6, correct=True, iterations=1, restart=False, inner=None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mi.design(target, model=model, verify=checks, effort=QUICK)


def test_an_adhesive_design_is_checked_under_a_rising_force(corrected):
    sticky_target = _held_back(5, 1.0, 16, 1.0)[1]
    check = corrected.bem
    assert check is not None and check.adhesion == pytest.approx(W)
    # the loads are the BEM path's states a rising force reaches, inside the target's range
    assert check.p_star.size >= 2 and np.all(np.diff(check.p_star) > 0)
    assert check.p_star[0] > 0 and check.p_star[-1] <= sticky_target.p_star_max
    # the model is compared at those loads under load control (its own loading curve)
    gamma, h = corrected.design.tensors(torch.float64)
    with torch.no_grad():
        model = corrected.model.alpha_at_loads(
            gamma, h, corrected.design.settings, torch.as_tensor(check.p_star)[None]
        )[0].numpy()
    np.testing.assert_allclose(check.alpha_model, model, rtol=1e-12)
    np.testing.assert_allclose(
        check.alpha_target, np.interp(check.p_star, sticky_target.p_star, sticky_target.alpha)
    )
    # adhesion in the BEM: at the lowest load the contact is larger than without it (snap-in)
    plain = (
        mi.Independent()
        .alpha_at_loads(
            gamma, h, corrected.design.settings, torch.as_tensor(check.p_star[:1])[None]
        )[0, 0]
        .item()
    )
    assert check.alpha_bem[0] > 1.5 * plain
    err = np.linalg.norm(check.alpha_bem - check.alpha_target) / np.linalg.norm(check.alpha_target)
    assert check.bem_error == pytest.approx(err, rel=1e-12)
    assert any(n.startswith("adhesive BEM: the JKR limit") for n in check.notes)


def test_an_adhesive_design_is_corrected_and_recorded(corrected, tmp_path):
    assert corrected.bem_before is not None and len(corrected.corrections) == 1
    assert corrected.bem_before.adhesion == pytest.approx(W)
    # a correction is kept only where its BEM error fell
    assert corrected.bem.bem_error <= corrected.bem_before.bem_error
    assert corrected.corrections[0].accepted == (corrected.bem is not corrected.bem_before)
    corrected.save(tmp_path)
    block = json.loads((tmp_path / "design.json").read_text())["bem_check"]
    assert block["adhesion"] == pytest.approx(W)
    assert block["bem_error"] == pytest.approx(corrected.bem.bem_error)
    assert block["uncorrected"]["bem_error"] == pytest.approx(corrected.bem_before.bem_error)
    assert len(block["corrections"]) == 1


def test_cli_exit_status_follows_the_adhesive_bem_error(sticky_target, tmp_path, capsys):
    csv = tmp_path / "sticky.csv"
    pairs = zip(sticky_target.p_star.tolist(), sticky_target.alpha.tolist(), strict=True)
    rows = "\n".join(f"{p!r},{a!r}" for p, a in pairs)
    csv.write_text("p_star,alpha\n" + rows + "\n")
    args = ["design", "--target-csv", str(csv), "--modulus", "2.4MPa", "--radius", "0.5mm"]
    args += ["--work-of-adhesion", "50mJ/m2", "--refine", "none", "--verify-grid", "96"]
    args += ["--verify-loads", "6", "--no-correct"]
    out = tmp_path / "tight"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main([*args, "--out", str(out), "--max-bem-error", "0.001"]) == 3
        assert "is above --max-bem-error 0.001 %" in capsys.readouterr().out
        block = json.loads((out / "design.json").read_text())["bem_check"]
        assert block["ok"] is False and block["adhesion"] == pytest.approx(W)
        loose = tmp_path / "loose"
        assert main([*args, "--out", str(loose), "--max-bem-error", "100"]) == 0
    block = json.loads((loose / "design.json").read_text())["bem_check"]
    assert block["ok"] is True and block["bem_error"] < 1


def test_states_a_rising_force_jumps_over_are_not_compared():
    # A cell whose BEM path (by approach) meets, just after a snap-in, a state with one more
    # asperity in contact at a load below the one the cell carried before that touch: a
    # rising force jumps over it. The samples' running maximum misses that peak; the check
    # must not compare there (it read +70 % against the model at 96^2 before).
    from metainterface.verify.check import bem_check

    design, target = _held_back(0, 0.3, 24, 0.95)
    model = mi.Independent(adhesion=W)
    check = bem_check(design, target, mi.Verify(grid=96, loads=12, correct=False), model)
    assert check.p_star.size >= 10
    # every compared state is on the model's loading curve to within the 96^2 grid's error
    assert np.abs(check.alpha_bem / check.alpha_model - 1).max() < 0.2


@pytest.mark.long
def test_a_correction_in_bem_does_not_trade_an_offset_laws_f0(tmp_path):
    # A held-out gripper law (the cell of adhesive_cell_curve(seed=43) as a friction law over
    # 4 cm^2, tau 0.3 MPa, E* 2.4 MPa, R 0.5 mm, w 50 mJ/m^2), designed with --area auto and
    # the check: its design meets F_0 within 0.42 %, and a correction towards the BEM's
    # states (all above zero load) once moved F_0 to 33.5 %. F_0 is part of what a design
    # meets (issue 52, item 2), so no correction may take it past 2 %.
    from metainterface._testing import adhesive_cell_curve

    e, r, w, tau, area = 2.4e6, 0.5e-3, 0.05, 0.3e6, 4e-4
    p, a = adhesive_cell_curve(w / (e * r), seed=43, rows=24)
    law = tmp_path / "law43.csv"
    rows = "".join(
        f"{x:.12g},{y:.12g}\n" for x, y in zip(p * area * e, a * tau * area, strict=True)
    )
    law.write_text("normal_force,friction_force\n" + rows)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = mi.design_scale(
            law,
            area="auto",
            verify=True,
            effort=mi.Effort(seed=0),
            shear_strength=tau,
            modulus=e,
            radius=r,
            work_of_adhesion=w,
            fit="never",
        )
    assert result.f0_error is not None and result.f0_error <= 0.02
    tried = result.corrections
    assert tried, "the check calls for a correction on this law"
    assert all(c.f0_error is not None for c in tried)
    assert all(c.f0_error <= 0.02 for c in tried if c.accepted)
