"""The surrogate: architecture, output mapping, schedules, training that learns and resumes."""

import math

import numpy as np
import pytest
import torch

from metainterface.cli import main
from metainterface.data import generate_dataset, load_dataset
from metainterface.errors import MetainterfaceError
from metainterface.physics import CellSettings
from metainterface.surrogate.checkpoint import load_model
from metainterface.surrogate.config import TrainConfig
from metainterface.surrogate.data import split_of
from metainterface.surrogate.loss import LossWeights, weights_of
from metainterface.surrogate.model import Dropout, InverseMLP, outputs_to_design
from metainterface.surrogate.run_state import read_metrics
from metainterface.surrogate.schedules import Schedules
from metainterface.surrogate.train import train

S = CellSettings()


def test_architecture_matches_table_a1():
    m = InverseMLP(9, 128)
    linears = [x for x in m.net if isinstance(x, torch.nn.Linear)]
    assert [(x.in_features, x.out_features) for x in linears] == [
        (258, 512),
        (512, 256),
        (256, 128),
        (128, 18),
    ]
    assert [x.p for x in m.net if isinstance(x, Dropout)] == [0.1, 0.1]
    assert isinstance(m.net[-1], torch.nn.Sigmoid)


def test_dropout_rate_scale_and_seed():
    drop = Dropout(0.1)
    x = torch.ones(400, 1001)  # numel not a multiple of 4
    torch.manual_seed(3)
    y = drop(x)
    dropped = float((y == 0).float().mean())
    assert dropped == pytest.approx(0.1, abs=0.003)  # 400k draws: sd 0.0005
    assert torch.allclose(y[y != 0], torch.tensor(1 / 0.9))
    torch.manual_seed(3)
    assert torch.equal(drop(x), y)
    assert not torch.equal(drop(x), y)
    drop.eval()
    assert drop(x) is x
    with pytest.raises(ValueError, match="dropout probability"):
        Dropout(1.0)


def test_output_mapping_sorted_and_bounded():
    y = torch.rand(64, 18)
    gamma, h = outputs_to_design(y, S)
    assert float(gamma.min()) >= 1.8 and float(gamma.max()) <= 4.0
    assert torch.all(h[:, 0] == 0) and torch.all(h.diff(dim=-1) >= 0)
    paper = outputs_to_design(torch.ones(1, 18), S, max_gap=None)[1]
    assert float(paper[0, -1]) == pytest.approx(2 * S.delta_max)
    wide = outputs_to_design(torch.ones(1, 18), S, max_gap=1.1)[1]
    assert float(wide[0, 1]) == pytest.approx(1.1 * S.delta_max)


def test_default_gap_scale_reaches_truncated_designs():
    # a truncated cell: one active asperity, the rest beyond Delta_max
    m = InverseMLP(9, 128)
    y = torch.zeros(1, 18)
    y[0, 10] = 1.0
    h = outputs_to_design(y, S, m.max_gap)[1]
    assert float(h[0, 1]) > S.delta_max


def test_curve_error_term():
    # a linear law alpha = c P*: the relative error on the target's grid is known in closed form
    from metainterface.physics.curves import Curve
    from metainterface.surrogate.loss import CurveTargets, LossWeights, curve_error, physics_loss

    n = 129
    p_hat = torch.linspace(0, 1, n, dtype=torch.float64)[None]
    target = CurveTargets(p_hat, torch.ones(1, n), torch.tensor([2.0]), torch.tensor([0.5]))

    def linear(p_max: float, slope: float) -> Curve:
        alpha = slope * p_hat * p_max
        return Curve(alpha, torch.full_like(alpha, 1 / slope), torch.tensor([p_max]), alpha[:, -1])

    same = linear(2.0, 0.25)
    assert float(curve_error(same, target)) == pytest.approx(0.0, abs=1e-12)
    # 10 % too much area at every pressure
    assert float(curve_error(linear(2.0, 0.275), target)) == pytest.approx(0.1, rel=1e-9)
    # stops at P* = 1 and is held at alpha = 0.25 beyond: the error is the integral's ratio
    short = float(curve_error(linear(1.0, 0.25), target))
    p = p_hat[0] * 2.0
    expected = torch.linalg.vector_norm((0.25 * p - 0.25).clamp_min(0)) / torch.linalg.vector_norm(
        0.25 * p
    )
    assert short == pytest.approx(float(expected), rel=1e-9)
    # the term adds w_curve times the batch mean, and nothing with the paper's weights
    base = physics_loss(short_curve := linear(1.0, 0.25), target, LossWeights())
    with_term = physics_loss(short_curve, target, LossWeights(curve=5.0))
    assert float(with_term - base) == pytest.approx(5.0 * short, rel=1e-9)


def test_cli_defaults_match_train_config():
    from metainterface.cli.train import DEFAULTS

    cfg = TrainConfig()
    assert {k: getattr(cfg, k) for k in DEFAULTS} == DEFAULTS


def test_schedules():
    s = Schedules(epochs=100, curriculum_epochs=10)
    assert s.kappa(0) == pytest.approx(1e3) and s.kappa(25) == pytest.approx(1e5)
    assert s.kappa(99) == pytest.approx(1e5)
    assert s.kappa(12) == pytest.approx(math.sqrt(1e3 * 1e5), rel=0.1)
    assert s.lam(0) == 1.0 and s.lam(5) == pytest.approx(0.5) and s.lam(10) == 0.0


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    path = tmp_path_factory.mktemp("ds") / "tiny.npz"
    generate_dataset(600, 3, S, path, progress=False)
    ds = load_dataset(path)
    return path, split_of(ds, "train"), split_of(ds, "val")


def test_loss_falls_and_resume_is_bit_for_bit(tiny, tmp_path):
    _, tr, va = tiny
    cfg = TrainConfig(epochs=4, batch_size=64, curriculum_epochs=2, physics_steps=32)
    full = train(tr, va, S, tmp_path / "full", cfg, progress=False)
    m = read_metrics(full.run_dir)
    assert m["val_loss"][-1] < m["val_loss"][0] and m["train_loss"][-1] < m["train_loss"][0]
    # a run stopped after 2 epochs and resumed ends exactly where the full run ends
    half = TrainConfig(**{**cfg.__dict__})
    part = tmp_path / "part"
    # emulate a kill after epoch 2: train 2 epochs with the same config, then resume
    from metainterface.surrogate import run_state

    calls = {"n": 0}
    orig = run_state.write_metrics

    def killer(path, history):
        orig(path, history)
        calls["n"] += 1
        if calls["n"] == 2:
            raise KeyboardInterrupt

    run_state.write_metrics = killer
    try:
        with pytest.raises(KeyboardInterrupt):
            train(tr, va, S, part, half, progress=False)
    finally:
        run_state.write_metrics = orig
    train(tr, va, S, part, half, resume=True, progress=False)
    a = read_metrics(full.run_dir)
    b = read_metrics(part)
    np.testing.assert_array_equal(a["val_loss"], b["val_loss"])
    ma, _, config = load_model(full.run_dir / "model.pt")
    mb, _, _ = load_model(part / "model.pt")
    # the gap scale and loss weights travel with the model file
    assert ma.max_gap == cfg.max_gap and weights_of(config) == cfg.weights
    for (ka, va_), (_, vb) in zip(ma.state_dict().items(), mb.state_dict().items(), strict=True):
        assert torch.equal(va_, vb), ka


def test_bad_inputs(tiny, tmp_path):
    path, tr, va = tiny
    with pytest.raises(MetainterfaceError, match="larger than the training split"):
        train(tr, va, S, tmp_path / "r", TrainConfig(epochs=1, batch_size=10_000), progress=False)
    junk = tmp_path / "junk.pt"
    junk.write_bytes(b"not a model")
    with pytest.raises(MetainterfaceError, match="not a readable weights file"):
        load_model(junk)
    assert (
        main(
            [
                "train",
                "--dataset",
                str(path),
                "--out",
                str(tmp_path / "r2"),
                "--batch-size",
                "100000",
                "--epochs",
                "1",
            ]
        )
        == 2
    )


def test_model_files_keep_the_gap_scale(tmp_path):
    from metainterface.surrogate.checkpoint import save_model

    paper = InverseMLP(9, 128, max_gap=None)
    save_model(tmp_path / "p.pt", paper, {"settings": S.to_dict(), "model": paper.architecture()})
    assert load_model(tmp_path / "p.pt")[0].max_gap is None
    # files written before the gap scale was a setting hold the paper's network
    save_model(tmp_path / "old.pt", paper, {"settings": S.to_dict()})
    model, _, config = load_model(tmp_path / "old.pt")
    assert model.max_gap is None and weights_of(config) == LossWeights(10, 1, 10)
    with pytest.raises(MetainterfaceError, match="max_gap"):
        InverseMLP(9, 128, max_gap=0.0)


def test_shipped_model_loads():
    from metainterface.surrogate.checkpoint import default_model_path

    _, settings, config = load_model(default_model_path())
    assert settings == CellSettings()
    assert "train" in config and config["epoch"] >= 1
