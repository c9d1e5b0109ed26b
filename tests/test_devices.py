"""The ``device`` option on every torch path, run on the CPU ("cpu", and "auto" on a machine
without CUDA): same results as before the option, numpy out, one-line errors.

tests/test_cuda.py runs the same paths on a GPU where there is one.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface import MetainterfaceError
from metainterface.cli import main
from metainterface.data import generate_dataset, load_dataset
from metainterface.inverse.refine import RefineSettings
from metainterface.physics.curves import curve
from metainterface.surrogate.checkpoint import load_model, load_torch
from metainterface.surrogate.data import split_of
from metainterface.surrogate.loss import param_loss, physics_loss
from metainterface.surrogate.model import InverseMLP
from metainterface.surrogate.schedules import Schedules
from metainterface.surrogate.train import TrainConfig, read_metrics, train

S = mi.CellSettings()
NO_CUDA = not torch.cuda.is_available()
#: A quick refinement: the device plumbing, not the optimum, is under test.
QUICK = RefineSettings(stages=2, steps_per_stage=2, iterations=10, polish_iterations=20)


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    path = tmp_path_factory.mktemp("ds") / "tiny.npz"
    generate_dataset(500, 5, S, path, progress=False)
    return path


def _reference_epochs(tr, cfg: TrainConfig, epochs: int):
    """The training loop as it was before the device option (a Python float summed per
    batch, everything on the CPU): the model's weights and the mean training loss of each
    epoch. The device-aware loop must give these bit for bit on the CPU."""
    torch.manual_seed(cfg.seed)
    model = InverseMLP(S.n_asperities, S.n_steps, cfg.max_gap)
    model.set_input_scaling(tr.features)
    opt = torch.optim.AdamW(
        model.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay, fused=True
    )
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, T_max=cfg.epochs)
    schedules: Schedules = cfg.schedules
    losses = []
    for epoch in range(epochs):
        kappa, lam = schedules.kappa(epoch), schedules.lam(epoch)
        model.train()
        order = torch.randperm(
            len(tr), generator=torch.Generator().manual_seed(cfg.seed * 100_003 + epoch)
        )
        run_loss, batches = 0.0, 0
        for lo in range(0, len(tr) - cfg.batch_size + 1, cfg.batch_size):
            feats, targets, g_t, h_t = tr.rows(order[lo : lo + cfg.batch_size])
            gamma, h = model.design(feats, S)
            pred = curve(gamma, h, S, smooth=kappa, n_delta=cfg.physics_steps)
            loss = physics_loss(pred, targets, cfg.weights)
            if lam > 0:
                loss = loss + lam * param_loss(gamma, h, g_t, h_t, S)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()
            run_loss += float(loss.detach())
            batches += 1
        sched.step()
        losses.append(run_loss / batches)
        # the validation pass of train() runs here in eval mode: no draws, no weight change
    return model.state_dict(), losses


@pytest.mark.parametrize("device", ["cpu", "auto"] if NO_CUDA else ["cpu"])
def test_training_on_cpu_is_bit_identical_to_the_loop_before_devices(tiny, tmp_path, device):
    ds = load_dataset(tiny)
    tr, va = split_of(ds, "train"), split_of(ds, "val")
    cfg = TrainConfig(epochs=3, batch_size=64, curriculum_epochs=2, physics_steps=32)
    run = train(tr, va, S, tmp_path / "run", cfg, progress=False, device=device)
    weights, losses = _reference_epochs(tr, cfg, 3)
    ckpt = load_torch(run.run_dir / "checkpoint.pt")
    for name, value in weights.items():
        assert torch.equal(ckpt["model"][name], value), name
    assert [row["train_loss"] for row in ckpt["history"]] == losses
    assert len(read_metrics(run.run_dir)["train_loss"]) == 3
