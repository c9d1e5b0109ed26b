"""The adhesive network (issue 38, item 2): the targets it is trained on against JKR's closed
forms, its training (w as an input or not) from the CLI, its evaluation, and the design path
that reads adhesive targets with it."""

import math
import shutil

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface.cli import main
from metainterface.data import load_dataset
from metainterface.errors import MetainterfaceError
from metainterface.physics import CellSettings
from metainterface.physics.sneddon import log_kc
from metainterface.surrogate.adhesive import AdhesiveTargets, adhesive_error, adhesive_split
from metainterface.surrogate.checkpoint import (
    default_adhesive_model_path,
    default_laws_model_path,
    default_model_path,
    load_model,
)
from metainterface.surrogate.data import Split, split_of
from metainterface.surrogate.loss import CurveTargets

S = CellSettings()


@pytest.fixture(scope="module")
def cells(tmp_path_factory):
    path = tmp_path_factory.mktemp("ds") / "ds.npz"
    mi.generate_dataset(400, path, seed=3, progress=False, device="cpu")
    return path, split_of(load_dataset(path), "train")


def _coplanar(gamma: float, rows: int = 2) -> Split:
    n = S.n_asperities
    zeros = torch.zeros(rows, S.n_steps)
    t = CurveTargets(zeros, zeros, torch.ones(rows), torch.ones(rows))
    return Split(
        torch.zeros(rows, 2 * S.n_steps + 2),
        t,
        torch.full((rows, n), gamma),
        torch.zeros(rows, n),
        np.array(["coplanar"] * rows),
    )


@pytest.mark.parametrize("gamma", [2.0, 3.5])
def test_an_adhesive_target_starts_at_the_jkr_zero_load_contact(gamma):
    # N identical asperities at one height, loaded from zero: each snaps in and the flat
    # jumps to zero force, where 2 g/(g+1) kc a^(g+1) = sqrt(8 pi w R a^3), i.e.
    # a^(g - 1/2) = (g + 1)/g sqrt(2 pi w R) / kc (JKR, any power-law punch)
    w = 3e-5
    spec = AdhesiveTargets(adhesion=(w, w), min_end=1.0)
    made = adhesive_split(_coplanar(gamma), S, seed=1, adhesion_input=True, spec=spec)
    kc = math.exp(float(log_kc(torch.tensor(gamma, dtype=torch.float64), S.radius)))
    a = ((gamma + 1) / gamma * math.sqrt(2 * math.pi * w * S.radius) / kc) ** (1 / (gamma - 0.5))
    alpha0 = S.n_asperities * math.pi * a**2 / S.nominal_area
    t = made.targets
    first = (t.alpha_hat[:, 0] * t.alpha_max).double()
    # the jump is placed by linear interpolation in the force between the 256 approaches of
    # the sweep (second order in the step): 1e-5, not round-off
    torch.testing.assert_close(first, torch.full_like(first, alpha0), rtol=2e-5, atol=0)
    # the last column is the adhesion input, log10 w; the work of adhesion rides along
    torch.testing.assert_close(made.features[:, -1], torch.full((2,), math.log10(w)))
    torch.testing.assert_close(made.adhesion, torch.full((2,), w, dtype=torch.float64))


def test_adhesive_targets_are_seeded_and_checked(cells):
    _, split = cells
    made = adhesive_split(split, S, seed=4, adhesion_input=False)
    again = adhesive_split(split, S, seed=4, adhesion_input=False)
    assert torch.equal(made.features, again.features) and made.features.shape[1] == 258
    assert 0.5 * len(split) < len(made) <= len(split)  # those held by adhesion alone drop
    lo, hi = AdhesiveTargets().adhesion
    assert float(made.adhesion.min()) >= lo and float(made.adhesion.max()) <= hi
    assert (made.targets.alpha_hat[:, 0] > 0).all()  # in contact at zero load
    assert all(c.startswith("w 1e-") for c in made.category)
    with pytest.raises(MetainterfaceError, match="adhesion must be a range"):
        AdhesiveTargets(adhesion=(1e-4, 2.0))
    with pytest.raises(MetainterfaceError, match="adhesion_input needs reads='adhesive'"):
        mi.TrainConfig(adhesion_input=True)


@pytest.mark.parametrize("with_w", [True, False])
def test_training_an_adhesive_network_from_the_cli(cells, tmp_path, capsys, with_w):
    path, _ = cells
    run = tmp_path / "run"
    args = ["train", "--dataset", str(path), "--adhesive", "--epochs", "1", "--out", str(run)]
    assert main([*args, "--batch-size", "64", *([] if with_w else ["--no-adhesion-input"])]) == 0
    net, settings, config = load_model(run / "model.pt")
    assert settings == S and config["train"]["reads"] == "adhesive"
    assert config["train"]["init"] == str(default_laws_model_path())
    assert net.adhesion_input is with_w and net.in_mean.numel() == 258 + with_w
    capsys.readouterr()
    assert main(["evaluate", "--model", str(run / "model.pt"), "--dataset", str(path)]) == 0
    table = capsys.readouterr().out
    assert "| w 1e-05 |" in table and "| all |" in table
    both = ["train", "--dataset", str(path), "--adhesive", "--laws", "--out", str(tmp_path / "b")]
    assert main(both) == 2
    assert "--laws or --adhesive" in capsys.readouterr().err
    alone = ["train", "--dataset", str(path), "--adhesion-input", "--out", str(tmp_path / "c")]
    assert main(alone) == 2
    assert "--adhesion-input needs --adhesive" in capsys.readouterr().err


@pytest.mark.skipif(not default_adhesive_model_path().is_file(), reason="no shipped network")
def test_the_shipped_adhesive_network_reads_adhesive_targets_better(tmp_path):
    # held-back adhesive cells (PDMS on glass at R = 0.5 mm: w = 4.2e-5 E* R), designed
    # zero-shot (no refinement): with the shipped networks, the adhesive one among them,
    # against the shipped surrogate alone (a copy is a user's own file: used alone)
    alone = tmp_path / "mine.pt"
    shutil.copy(default_model_path(), alone)
    fm = mi.Independent(adhesion=4.2e-5)
    errs = {"shipped": [], "alone": []}
    labels = []
    for seed in range(100, 106):
        r = np.random.default_rng(seed)
        g = r.uniform(1.8, 4.0, 9)
        h = r.uniform(0, 0.6, 9) * S.delta_max
        h -= h.min()
        sw = fm.sweep(torch.as_tensor(g)[None], torch.as_tensor(h)[None], S, n_delta=2049)
        p = np.linspace(0, float(sw.p_star[0, -1]), 30)
        a = np.interp(p, sw.p_star[0].numpy(), sw.alpha[0].numpy())
        target = mi.Target(p_star=p, alpha=a, name=f"adhesive {seed}")
        for key, surrogate in (("shipped", None), ("alone", str(alone))):
            effort = mi.Effort(refine=False, hedge=0, fallback=0, seed=0, surrogate=surrogate)
            res = mi.design(target, model=fm, verify=False, effort=effort)
            errs[key].append(res.error)
            if key == "shipped":
                labels.append(res.zero_shot_from)
    assert np.median(errs["shipped"]) < 0.5 * np.median(errs["alone"])  # 3.2 % against 10 %
    assert any(label.startswith("adhesive network") for label in labels)


@pytest.mark.skipif(not default_adhesive_model_path().is_file(), reason="no shipped network")
def test_an_adhesive_network_given_for_an_adhesionless_design_is_refused():
    effort = mi.Effort(refine=False, surrogate=str(default_adhesive_model_path()))
    with pytest.raises(MetainterfaceError, match="reads a work of adhesion"):
        mi.design("bilinear", verify=False, effort=effort)
    # with an adhesive model it designs (the network told the model's w)
    r = mi.design("bilinear", model=mi.Independent(adhesion=4.2e-5), verify=False, effort=effort)
    assert np.isfinite(r.error)


def test_the_training_loss_sees_where_an_asperity_snaps_in():
    # a design against a target whose later pair snaps in at a higher load: with the snap-in
    # window the loss falls as that pair is raised (a central difference agrees with the
    # gradient); without it the loss is blind there (the target's loads straddle the jump)
    s = CellSettings(n_asperities=4)
    w = torch.tensor([4.2e-5], dtype=torch.float64)
    gamma = torch.full((1, 4), 2.0, dtype=torch.float64)
    sweep_at = lambda h2: mi.Independent(adhesion=float(w)).sweep(  # noqa: E731
        gamma, torch.tensor([[0.0, 0.0, h2, h2]], dtype=torch.float64), s, n_delta=4097
    )
    ref = sweep_at(0.0056)
    p_max = float(ref.p_star[0, -1])
    p = torch.linspace(0, p_max, s.n_steps, dtype=torch.float64)
    alpha = torch.as_tensor(np.interp(p.numpy(), ref.p_star[0].numpy(), ref.alpha[0].numpy()))
    a_max = alpha.max()
    target = CurveTargets(
        (alpha / a_max)[None], torch.zeros(1, s.n_steps), torch.tensor([p_max]), a_max[None]
    )

    def loss(h2: float, window: float) -> tuple[float, float]:
        h = torch.tensor([[0.0, 0.0, h2, h2]], dtype=torch.float64, requires_grad=True)
        e = adhesive_error(gamma, h, target, s, w, n_delta=256, window=window)
        (g,) = torch.autograd.grad(e.sum(), h)
        return float(e), float(g[0, 2:].sum())

    h2, step = 0.0050, 1e-7
    _, grad = loss(h2, 0.02)
    central = (loss(h2 + step, 0.02)[0] - loss(h2 - step, 0.02)[0]) / (2 * step)
    assert grad < 0 and grad == pytest.approx(central, rel=1e-3)
    # the plain read (the error itself) fits the target's own heights, but its gradient
    # sees only the branches either side of the jump: 2.4 against the window's 21
    e_plain, g_plain = loss(h2, 0.0)
    assert loss(0.0056, 0.0)[0] < 1e-3 * e_plain
    assert abs(g_plain) < 0.25 * abs(grad)


def test_the_snap_in_window_is_checked_and_falls_over_its_epochs():
    with pytest.raises(MetainterfaceError, match="snap_window needs reads='adhesive'"):
        mi.TrainConfig(snap_window=0.02)
    with pytest.raises(MetainterfaceError, match="snap_window"):
        mi.TrainConfig.adhesive(snap_window=0.8)
    falls = mi.TrainConfig.adhesive(epochs=10, snap_window=0.05, snap_window_epochs=10).schedules
    assert [falls.window(e) for e in (0, 5, 10)] == pytest.approx([0.05, 0.025, 0.0])
    held = mi.TrainConfig.adhesive().schedules
    assert held.window(0) == held.window(100) == 0.02
