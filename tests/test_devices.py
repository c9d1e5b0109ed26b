"""The ``device`` option on every torch path, run on the CPU ("cpu", and "auto" on a machine
without CUDA): same results as before the option, numpy out, one-line errors.

tests/test_cuda.py runs the same paths on a GPU where there is one.
"""

from __future__ import annotations

import math
import subprocess
import sys
from importlib.resources import files

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
from metainterface.surrogate.config import TrainConfig
from metainterface.surrogate.data import split_of
from metainterface.surrogate.loss import param_loss, physics_loss
from metainterface.surrogate.model import InverseMLP
from metainterface.surrogate.run_state import read_metrics
from metainterface.surrogate.schedules import Schedules
from metainterface.surrogate.train import train

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


DEVICES = ["cpu", "auto"] if NO_CUDA else ["cpu"]


def test_training_api_and_model_file_on_cpu(tiny, tmp_path):
    cfg = TrainConfig(epochs=1, batch_size=64, physics_steps=16)
    runs = [mi.train_surrogate(tiny, tmp_path / d, cfg, progress=False, device=d) for d in DEVICES]
    ckpt = load_torch(runs[0].run_dir / "checkpoint.pt")
    assert all(v.device.type == "cpu" for v in ckpt["model"].values())
    model, _, _ = load_model(runs[0].run_dir / "model.pt")
    for r in runs[1:]:  # "auto" without CUDA is the CPU: the same model
        other, _, _ = load_model(r.run_dir / "model.pt")
        theirs = other.state_dict()
        for k, a in model.state_dict().items():
            assert torch.equal(a, theirs[k]), k


def test_dataset_on_cpu_and_auto(tmp_path):
    files = [tmp_path / f"{d}.npz" for d in DEVICES]
    for d, f in zip(DEVICES, files, strict=True):
        mi.generate_dataset(120, f, seed=2, progress=False, device=d)
    a = load_dataset(files[0])
    for f in files[1:]:
        b = load_dataset(f)
        for name in ("gamma", "alpha_hat", "stiffness_hat", "p_star_max", "alpha_max"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name))


def _same_designs(a, b):
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x.design.gamma, y.design.gamma)
        np.testing.assert_array_equal(x.design.h, y.design.h)
        assert x.error == y.error


@pytest.mark.parametrize("method", ["surrogate", "multistart", "hertz"])
def test_design_many_targets_on_cpu_and_auto(method):
    names = ["saturating", "bilinear", "linear"]
    options = dict(
        method=method, effort=mi.Effort(starts=3, hedge=2, fallback=0, refine_settings=QUICK)
    )
    # the BEM check on the design's device, on a small grid (not corrected: at 96^2 the BEM
    # reads ~5 % high by itself): the device plumbing, not the check at 384^2, is under test
    runs = [mi.design(names, device=d, verify=_check(d), **options) for d in DEVICES]
    for r in runs:
        assert [x.target.name for x in r] == names
        assert all(isinstance(x.design.gamma, np.ndarray) and math.isfinite(x.error) for x in r)
    for other in runs[1:]:
        _same_designs(runs[0], other)
    # one batch of three targets gives each the design it gets alone
    alone = mi.design("bilinear", device="cpu", verify=_check("cpu"), **options)
    _same_designs([runs[0][1]], [alone])
    for a, b in zip(runs[0], runs[-1], strict=True):  # the check ran, alike on each device
        assert a.bem is not None and a.bem.grid == 96 and a.bem.device == b.bem.device == "cpu"
        np.testing.assert_array_equal(a.bem.alpha_bem, b.bem.alpha_bem)


def _check(device: str) -> mi.Verify:
    """An uncorrected BEM check on ``device``, 96^2 and 4 loads (each solve under a second)."""
    return mi.Verify(grid=96, loads=4, correct=False, device=device)


def test_robust_printable_design_on_cpu_and_auto():
    options = dict(
        method="multistart",
        verify=False,  # the BEM check's device: test_design_many_targets_on_cpu_and_auto
        effort=mi.Effort(starts=2, refine_settings=QUICK),
        robust=mi.Robust(sigma_h=0.001, samples=4),
        z_step=0.001,
    )
    runs = [mi.design("saturating", device=d, **options) for d in DEVICES]
    for r in runs[1:]:
        _same_designs([runs[0]], [r])
        assert r.robust == runs[0].robust and r.printable == runs[0].printable


def test_tolerance_min_radius_curve_on_cpu_and_auto():
    d = mi.design(
        "saturating",
        method="multistart",
        verify=False,  # the BEM check's device: test_design_many_targets_on_cpu_and_auto
        effort=mi.Effort(starts=2, refine_settings=QUICK),
    )
    tols = [mi.tolerance(d, sigma_h=0.001, samples=64, device=x) for x in DEVICES]
    for t in tols[1:]:
        np.testing.assert_array_equal(t.errors, tols[0].errors)
        np.testing.assert_array_equal(t.alpha_sd_linear, tols[0].alpha_sd_linear)
    sizes = [
        mi.min_radius(d, printer_sigma="1um", max_error=0.05, samples=32, device=x) for x in DEVICES
    ]
    assert len({(s.radius_m, s.error_p95) for s in sizes}) == 1
    curves = [mi.curve(d.design, steps=32, device=x) for x in DEVICES]
    curves.append(mi.curve(d.design, steps=32, smooth=1e4, device="cpu"))
    for c in curves:
        assert isinstance(c.alpha, np.ndarray) and c.alpha.shape == (32,)
    for c in curves[1:-1]:
        np.testing.assert_array_equal(c.alpha, curves[0].alpha)


def test_many_targets_pass_the_memory_check(monkeypatch):
    """The check counts the rows refined together: the surrogate's 1 + hedge per target,
    or its fallback's starts afterwards, not their sum with ``starts``."""
    from metainterface import _checks
    from metainterface.designer.run import affordable_rows

    monkeypatch.setattr(_checks, "memory_total", lambda: 16 * 2**30)
    cpu = torch.device("cpu")
    affordable_rows("surrogate", 50, 8, 50, 1000, 9, cpu)  # 7.4 GB: under 8 GiB
    with pytest.raises(MetainterfaceError, match=r"starts = 50 .* for 10000 targets") as e:
        affordable_rows("multistart", 50, 8, 50, 10_000, 9, cpu)
    assert "\n" not in str(e.value)


def test_the_memory_check_counts_a_robust_designs_copies(monkeypatch):
    """A robust design refines each start on its perturbed copies as well."""
    from metainterface import _checks

    monkeypatch.setattr(_checks, "memory_total", lambda: 16 * 2**30)
    t = mi.Target.builtin("saturating")
    # 300 x 9 rows x 9 asperities: 0.4 GB alone, 26 GB robust
    many = [mi.Target(p_star=t.p_star, alpha=t.alpha, name=f"t{i}") for i in range(300)]
    robust = mi.Robust(sigma_h=0.001, samples=64)
    with pytest.raises(MetainterfaceError, match=r"with 64 robust samples each") as e:
        mi.design(many, robust=robust, verify=False, effort=mi.Effort(hedge=8, fallback=0))
    assert "\n" not in str(e.value)


BAD = "gpu"


@pytest.mark.parametrize(
    "call",
    [
        lambda tmp: mi.generate_dataset(10, tmp / "d.npz", device=BAD),
        lambda tmp: mi.train_surrogate(tmp / "d.npz", tmp / "run", device=BAD),
        lambda tmp: mi.design("saturating", device=BAD),
        lambda tmp: mi.curve(gamma=[2.0] * 9, h=[0.0] * 9, device=BAD),
        lambda tmp: mi.tolerance(
            mi.Design(gamma=np.full(9, 2.0), h=np.zeros(9)), sigma_h=0.001, device=BAD
        ),
        lambda tmp: mi.min_radius(
            mi.Design(gamma=np.full(9, 2.0), h=np.zeros(9)),
            printer_sigma="1um",
            max_error=0.05,
            device=BAD,
        ),
    ],
    ids=["generate_dataset", "train_surrogate", "design", "curve", "tolerance", "min_radius"],
)
def test_bad_device_is_one_line(call, tmp_path):
    with pytest.raises(MetainterfaceError, match="device must be one of auto, cpu, cuda") as e:
        call(tmp_path)
    assert "\n" not in str(e.value) and e.value.argument == "device"
    assert not (tmp_path / "d.npz").exists()


@pytest.mark.skipif(not NO_CUDA, reason="this machine has CUDA")
def test_cuda_without_a_gpu_is_one_line():
    with pytest.raises(MetainterfaceError, match="no CUDA device") as e:
        mi.curve(gamma=[2.0] * 9, h=[0.0] * 9, device="cuda")
    assert "\n" not in str(e.value)


EXAMPLE = str(files("metainterface") / "examples" / "example_design.json")


@pytest.mark.parametrize(
    "argv",
    [
        ["generate", "--samples", "10", "--seed", "0", "--out", "{tmp}/d.npz"],
        ["train", "--dataset", "{tmp}/d.npz", "--out", "{tmp}/run"],
        ["design", "--target", "saturating", "--out", "{tmp}/d"],
        ["curve", "{example}", "--out", "{tmp}/c.csv"],
        ["tolerance", "{example}", "--sigma-h", "0.001", "--out", "{tmp}/t"],
        [
            "tolerance",
            "{example}",
            "--printer-sigma",
            "1um",
            "--max-error",
            "5%",
            "--out",
            "{tmp}/t",
        ],
    ],
    ids=["generate", "train", "design", "curve", "tolerance", "tolerance-sizing"],
)
def test_cli_bad_device_exits_2_in_one_line(argv, tmp_path, capsys):
    args = [a.format(tmp=tmp_path, example=EXAMPLE) for a in argv] + ["--device", BAD]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--device must be one of auto, cpu, cuda" in err
    assert not any(tmp_path.iterdir())


def test_cli_device_cpu_runs(tmp_path, capsys):
    for device in DEVICES:
        out = tmp_path / f"{device}.csv"
        assert main(["curve", EXAMPLE, "--steps", "16", "--out", str(out), "--device", device]) == 0
    texts = [(tmp_path / f"{d}.csv").read_text().splitlines()[1:] for d in DEVICES]
    assert all(t == texts[0] for t in texts)
    assert (
        "--device"
        in subprocess.run(
            [sys.executable, "-m", "metainterface", "design", "--help"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
    )
