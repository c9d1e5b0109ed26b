"""The friction-law network: how targets without stiffness are read, the targets it is
trained on, its training from the shipped surrogate, and what it does for friction laws."""

import json
import shutil

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface.cli import main
from metainterface.data import load_dataset
from metainterface.errors import MetainterfaceError
from metainterface.inverse.reseed import RESEED_FLOOR, RESEED_SLACK
from metainterface.physics import CellSettings
from metainterface.physics.curves import normalised_from_points
from metainterface.physics.pressures import alpha_at
from metainterface.surrogate.checkpoint import (
    default_laws_model_path,
    default_model_path,
    load_model,
)
from metainterface.surrogate.data import split_of
from metainterface.surrogate.laws import KINDS, LawTargets, law_split
from metainterface.units.friction import FrictionLaw, friction_target, friction_target_in_units

S = CellSettings()
TAU, E_STAR, RADIUS, AREA = 0.25e6, 2e6, 0.5e-3, 4e-4


def test_points_read_as_closed_forms():
    # alpha = c P*: S* = 1/c, so S_hat = S* alpha_max / P*_max = 1 everywhere
    p = torch.linspace(0, 2e-3, 7, dtype=torch.float64)[None]
    a_hat, s_hat, p_max, a_max = normalised_from_points(p, 30 * p, 128)
    torch.testing.assert_close(a_hat[0], torch.linspace(0, 1, 128, dtype=torch.float64))
    torch.testing.assert_close(s_hat[0], torch.ones(128, dtype=torch.float64))
    assert float(p_max) == pytest.approx(2e-3) and float(a_max) == pytest.approx(0.06)
    # alpha = P*^m: S_hat = (1/m) (P*/P*_max)^(1 - m), away from the ends
    p = torch.linspace(0, 1e-3, 2001, dtype=torch.float64)[None]
    m = 0.6
    _, s_hat, _, _ = normalised_from_points(p, p**m, 128)
    x = torch.linspace(0, 1, 128, dtype=torch.float64)[10:-1]
    torch.testing.assert_close(s_hat[0, 10:-1], x ** (1 - m) / m, rtol=2e-3, atol=0)
    # flat stretches have no finite stiffness: S_hat 0 there, never inf or NaN
    flat = torch.tensor([[0.0, 0.01, 0.01, 0.02]], dtype=torch.float64)
    p = torch.tensor([[0.0, 1e-3, 2e-3, 3e-3]], dtype=torch.float64)
    _, s_hat, _, _ = normalised_from_points(p, flat, 64)
    assert torch.isfinite(s_hat).all() and float(s_hat.max()) == 20.0


@pytest.fixture(scope="module")
def cells(tmp_path_factory):
    path = tmp_path_factory.mktemp("ds") / "ds.npz"
    mi.generate_dataset(500, path, seed=2, progress=False, device="cpu")
    return path, split_of(load_dataset(path), "train")


def test_law_targets_are_cut_curves_of_the_cells(cells):
    _, split = cells
    made = law_split(split, S, seed=4)
    again = law_split(split, S, seed=4)
    assert len(made) == 2 * len(split)
    assert torch.equal(made.features, again.features)  # seeded
    assert not torch.equal(made.features, law_split(split, S, seed=5).features)
    assert set(made.category) == set(KINDS)
    t = made.targets
    assert torch.isfinite(made.features).all()
    assert (t.alpha_hat.diff(dim=-1) >= 0).all() and (t.alpha_hat[:, -1] == 1).all()
    # a cut target is the cell's own curve up to an end at or below its Delta_max
    cut = torch.from_numpy(made.category == "cut")
    g, h = made.gamma[cut].double(), made.h[cut].double()
    grid = torch.linspace(0, 1, S.n_steps, dtype=torch.float64)
    p = grid[None] * t.p_star_max[cut].double()[:, None]
    alpha, p_reach = alpha_at(g, h, S, p, exact=True)
    assert (t.p_star_max[cut].double() <= p_reach * (1 + 1e-5)).all()
    ref = t.alpha_hat[cut].double() * t.alpha_max[cut].double()[:, None]
    err = torch.linalg.vector_norm(alpha - ref, dim=-1) / torch.linalg.vector_norm(ref, dim=-1)
    # the points are joined by straight lines (6 to 80 of them): close, not exact
    assert float(err.median()) < 0.02 and float(err.max()) < 0.1
    with pytest.raises(MetainterfaceError, match="min_end must be in"):
        LawTargets(min_end=0)
    with pytest.raises(MetainterfaceError, match="reads must be one of"):
        mi.TrainConfig(reads="pictures")


def test_training_the_law_network_from_the_cli(cells, tmp_path, capsys):
    path, _ = cells
    run = tmp_path / "run"
    args = ["train", "--dataset", str(path), "--laws", "--epochs", "2", "--out", str(run)]
    assert main([*args, "--batch-size", "64"]) == 0
    _, settings, config = load_model(run / "model.pt")
    assert settings == S and config["train"]["reads"] == "laws"
    assert config["train"]["init"] == str(default_model_path())
    assert config["init_sha256"].startswith("sha256:")  # which file, wherever it lies
    assert config["train"]["w_shape"] == 0 and config["train"]["w_curve"] == 100
    capsys.readouterr()
    assert main(["evaluate", "--model", str(run / "model.pt"), "--dataset", str(path)]) == 0
    table = capsys.readouterr().out
    assert all(f"| {kind} |" in table for kind in KINDS) and "n/a" in table
    plot = ["--plot", str(tmp_path / "f.png")]
    assert main(["evaluate", "--model", str(run / "model.pt"), "--dataset", str(path), *plot]) == 2
    assert "friction-law network" in capsys.readouterr().err
    bad = ["train", "--dataset", str(path), "--laws", "--init", str(tmp_path / "no.pt")]
    assert main([*bad, "--out", str(tmp_path / "r2")]) == 2
    assert "no.pt: file not found" in capsys.readouterr().err
    four = tmp_path / "four.npz"  # another cell than the shipped surrogate's
    mi.generate_dataset(200, four, seed=1, settings=CellSettings(n_asperities=4), progress=False)
    four_args = ["train", "--dataset", str(four), "--laws", "--batch-size", "32"]
    assert main([*four_args, "--out", str(tmp_path / "r4")]) == 2
    assert "trained for another cell" in capsys.readouterr().err


def _law_targets():
    """Four friction laws in newtons (0.2-8 N), as alpha(P*) targets at a feasible scale."""
    fn = np.linspace(0.2, 8.0, 40)
    laws = {
        "saturating": 3.0 * (1 - np.exp(-fn / 2.5)),
        "power": 0.6 * fn**0.7,
        "amontons-offset": 0.3 * fn + 0.8 * (1 - np.exp(-fn / 0.6)),
        "bilinear": np.where(fn < 3, 0.5 * fn, 1.5 + 0.15 * (fn - 3)),
    }
    out = []
    for name, ff in laws.items():
        law = FrictionLaw(fn, ff, rows=np.arange(1, 41), source=name)
        fs = mi.feasible_scale(
            law, shear_strength=TAU, modulus=E_STAR, radius=RADIUS, area=AREA, fit="never"
        )
        assert any(fs.ranges.values()), name  # reachable at some scale
        t = friction_target_in_units(law, **fs.suggest(), fit="never")
        out.append(mi.Target(p_star=t.p_star, alpha=t.alpha, name=name))
    return out


@pytest.mark.skipif(not default_laws_model_path().is_file(), reason="no shipped laws network")
def test_design_reads_friction_laws_with_the_law_network(tmp_path):
    targets = _law_targets()
    alone = tmp_path / "surrogate.pt"  # the shipped surrogate under another name: no laws net
    shutil.copy(default_model_path(), alone)
    quick = dict(refine=False, hedge=0, fallback=0)
    verify = False
    before = np.array(
        [
            r.error
            for r in mi.design(targets, verify=verify, effort=mi.Effort(surrogate=alone, **quick))
        ]
    )
    made = mi.design(targets, verify=verify, effort=mi.Effort(**quick))
    after = np.array([r.error for r in made])
    assert any(r.zero_shot_from.startswith("friction-law network") for r in made)
    assert all(r.record()["zero_shot_from"] == r.zero_shot_from for r in made)
    assert (after <= before + 1e-12).all()
    assert np.median(after) < 0.05 and np.median(after) < 0.5 * np.median(before)
    # a target with its stiffness is read by the shipped surrogate alone, as before
    with_s = mi.Target(
        p_star=targets[0].p_star, alpha=targets[0].alpha, stiffness=np.ones_like(targets[0].p_star)
    )
    a = mi.design(with_s, verify=verify, effort=mi.Effort(surrogate=alone, **quick))
    b = mi.design(with_s, verify=verify, effort=mi.Effort(**quick))
    np.testing.assert_array_equal(a.design.gamma, b.design.gamma)
    assert b.zero_shot_from == "surrogate"
    assert (
        mi.design(
            with_s, method="multistart", verify=verify, effort=mi.Effort(starts=2, **quick)
        ).zero_shot_from
        == ""
    )


def test_a_refined_design_is_never_worse_than_its_start():
    # A strongly saturating law at a small area: the refinement's loss forgives a design that
    # stops short of the law, the reported error does not; design keeps the better start.
    fn = np.linspace(0.2, 8.0, 40)
    law = FrictionLaw(fn, 20 * (1 - np.exp(-fn / 3)), rows=np.arange(1, 41), source="sat")
    t = friction_target(
        law, shear_strength=TAU, e_star=E_STAR, radius=RADIUS, area=17.6e-4, fit="never"
    )
    target = mi.Target(p_star=t.p_star, alpha=t.alpha, name="sat")
    r = mi.design(target, verify=False, force=True, effort=mi.Effort(hedge=0, fallback=0))
    # (re-seeding idle asperities may trade a little error for a cell that uses them)
    assert r.error <= max(r.initial_error * (1 + RESEED_SLACK), r.initial_error + RESEED_FLOOR)


@pytest.mark.skipif(not default_laws_model_path().is_file(), reason="no shipped laws network")
def test_the_cli_says_which_reading_of_a_law_made_the_zero_shot_design(tmp_path, capsys):
    fn = np.linspace(0.2, 8.0, 40)
    csv = tmp_path / "law.csv"
    rows = "".join(f"{x:.6g},{20 * (1 - np.exp(-x / 3)):.6g}\n" for x in fn)
    csv.write_text("normal_force,friction_force\n" + rows)
    out = tmp_path / "d"
    args = ["design", "--friction-csv", str(csv), "--shear-strength", "0.25MPa", "--modulus"]
    args += ["2MPa", "--radius", "0.5mm", "--area", "30cm2", "--no-verify", "--out", str(out)]
    # the zero-shot reading is made before any search: none is run after it
    args += ["--refine", "none", "--hedge", "0", "--fallback", "0"]
    assert main(args) == 0
    said = capsys.readouterr().out
    record = json.loads((out / "design.json").read_text())
    assert record["zero_shot_from"].startswith("friction-law network")
    assert f"zero-shot read by: law: {record['zero_shot_from']}" in said
