"""The device paths on a GPU: the same answers as on the CPU, to floating-point rounding.

Marked ``cuda``; every test skips, saying why, where torch sees no CUDA device (CI, and any
machine without a GPU). Run them alone with ``pytest -m cuda tests/test_cuda.py``.
"""

from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface.data import load_dataset
from metainterface.inverse.refine import RefineSettings
from metainterface.surrogate.checkpoint import load_model, load_torch
from metainterface.surrogate.config import TrainConfig

pytestmark = [
    pytest.mark.cuda,
    pytest.mark.skipif(not torch.cuda.is_available(), reason="torch sees no CUDA device here"),
]

QUICK = RefineSettings(stages=2, steps_per_stage=2, iterations=10, polish_iterations=20)


def test_auto_is_cuda():
    from metainterface._device import resolve_device

    assert resolve_device("auto").type == "cuda"
    # a design's refinement is launch-bound on a GPU: "auto" keeps it on the CPU
    assert resolve_device("auto", small=True).type == "cpu"


def test_dataset_on_cuda_matches_cpu(tmp_path):
    for d in ("cpu", "cuda"):
        mi.generate_dataset(600, tmp_path / f"{d}.npz", seed=1, progress=False, device=d)
    a, b = load_dataset(tmp_path / "cpu.npz"), load_dataset(tmp_path / "cuda.npz")
    np.testing.assert_array_equal(a.gamma, b.gamma)  # drawn on the CPU either way
    for name in ("alpha_hat", "stiffness_hat", "p_star_max", "alpha_max"):
        x, y = getattr(a, name), getattr(b, name)  # float32, reduced in another order
        assert np.linalg.norm(y - x) <= 1e-3 * np.linalg.norm(x), name


def test_training_on_cuda_loads_and_resumes_on_cpu(tmp_path):
    mi.generate_dataset(600, tmp_path / "d.npz", seed=1, progress=False, device="cpu")
    cfg = TrainConfig(epochs=3, batch_size=64, physics_steps=32, curriculum_epochs=1)
    run = mi.train_surrogate(
        tmp_path / "d.npz", tmp_path / "run", cfg, progress=False, device="cuda"
    )
    assert run.epochs_run == 3 and np.isfinite(run.best_val_loss)
    ckpt = load_torch(run.run_dir / "checkpoint.pt")
    assert all(v.device.type == "cpu" for v in ckpt["model"].values())
    model, _, _ = load_model(run.run_dir / "model.pt")  # on the CPU
    assert next(model.parameters()).device.type == "cpu"
    d = mi.design(
        "saturating",
        device="cpu",
        effort=mi.Effort(surrogate=run.run_dir / "model.pt", refine=False),
    )
    assert np.isfinite(d.error)
    # its checkpoint (optimiser state made on the GPU) resumes on the CPU
    again = mi.train_surrogate(
        tmp_path / "d.npz", tmp_path / "run", cfg, resume=True, progress=False, device="cpu"
    )
    assert again.epochs_run == 3


def test_cpu_and_cuda_runs_of_one_seed_are_each_repeatable(tmp_path):
    mi.generate_dataset(600, tmp_path / "d.npz", seed=1, progress=False, device="cpu")
    cfg = TrainConfig(epochs=2, batch_size=64, physics_steps=32)
    losses = []
    for i in range(2):
        run = mi.train_surrogate(
            tmp_path / "d.npz", tmp_path / f"r{i}", cfg, progress=False, device="cuda"
        )
        losses.append(run.best_val_loss)
    # atomic adds in CUDA's scatter and index backward passes make a run repeatable to
    # rounding there, not bit for bit (docs/concepts/devices.md); two epochs amplify that
    # rounding to a few 1e-4 of the loss (4.7e-4 on an H200)
    assert losses[0] == pytest.approx(losses[1], rel=1e-2)


def test_cuda_training_is_bitwise_repeatable_with_deterministic_algorithms(tmp_path):
    """What docs/concepts/devices.md tells a user who needs bit-for-bit runs on a GPU."""
    mi.generate_dataset(600, tmp_path / "d.npz", seed=1, progress=False, device="cpu")
    script = (
        "import sys, torch, metainterface as mi\n"
        "from metainterface.surrogate.config import TrainConfig\n"
        "torch.use_deterministic_algorithms(True)\n"
        "cfg = TrainConfig(epochs=2, batch_size=64, physics_steps=32)\n"
        "r = mi.train_surrogate(sys.argv[1], sys.argv[2], cfg, progress=False, device='cuda')\n"
        "print(repr(r.best_val_loss))\n"
    )
    env = {**os.environ, "CUBLAS_WORKSPACE_CONFIG": ":4096:8"}
    out = [
        subprocess.run(
            [sys.executable, "-c", script, str(tmp_path / "d.npz"), str(tmp_path / f"r{i}")],
            env=env,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.split()[-1]
        for i in range(2)
    ]
    assert out[0] == out[1]


@pytest.mark.parametrize("method", ["surrogate", "multistart"])
def test_design_on_cuda_matches_cpu(method):
    names = ["saturating", "bilinear", "linear"]
    options = dict(method=method, effort=mi.Effort(starts=4, hedge=2, refine_settings=QUICK))
    cpu = mi.design(names, device="cpu", **options)
    gpu = mi.design(names, device="cuda", **options)
    for a, b in zip(cpu, gpu, strict=True):
        assert isinstance(b.design.gamma, np.ndarray)
        # rounding can send a refinement to a neighbouring optimum: compare the errors
        assert b.error == pytest.approx(a.error, abs=0.02)


def test_many_targets_on_cuda():
    builtins = [mi.Target.builtin(n) for n in ("saturating", "bilinear", "linear")] * 34
    targets = [replace(t, name=f"{t.name}-{i}") for i, t in enumerate(builtins)]
    # the batched refinement on the GPU is what is tested; each design's BEM check (102
    # checks and corrections, minutes) is left to the tests of the BEM on CUDA below
    results = mi.design(
        targets, device="cuda", verify=False, effort=mi.Effort(refine_settings=QUICK)
    )
    assert len(results) == 102 and all(np.isfinite(r.error) for r in results)


def test_tolerance_and_curve_on_cuda_match_cpu():
    d = mi.design(
        "saturating",
        method="multistart",
        device="cpu",
        effort=mi.Effort(starts=2, refine_settings=QUICK),
    )
    a = mi.tolerance(d, sigma_h=0.001, samples=512, device="cpu")
    b = mi.tolerance(d, sigma_h=0.001, samples=512, device="cuda")
    np.testing.assert_allclose(b.errors, a.errors, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(b.alpha_sd_linear, a.alpha_sd_linear, rtol=1e-6, atol=1e-12)
    ca, cb = mi.curve(d.design, device="cpu"), mi.curve(d.design, device="cuda")
    np.testing.assert_allclose(cb.alpha, ca.alpha, rtol=1e-9, atol=1e-12)
    r = mi.design(
        "saturating",
        method="multistart",
        robust=mi.Robust(sigma_h=0.001, samples=4),
        z_step=0.001,
        device="cuda",
        effort=mi.Effort(starts=2, refine_settings=QUICK),
    )
    assert r.robust is not None and r.printable is not None
    s = mi.min_radius(d, printer_sigma="1um", max_error=0.05, samples=64, device="cuda")
    assert s.radius_m > 0


def test_adhesive_training_loss_on_cuda_matches_cpu():
    """The adhesive network's loss (each target at its own work of adhesion) is the same on
    CUDA as on the CPU, gradients included."""
    from metainterface.physics import CellSettings
    from metainterface.surrogate.adhesive import adhesive_error
    from metainterface.surrogate.loss import CurveTargets

    s = CellSettings()
    gen = torch.Generator().manual_seed(3)
    g = 1.8 + 2.2 * torch.rand(16, 9, generator=gen, dtype=torch.float64)
    h = 0.5 * s.delta_max * torch.rand(16, 9, generator=gen, dtype=torch.float64)
    w = 10 ** (-6 + 2.5 * torch.rand(16, generator=gen, dtype=torch.float64))
    t = CurveTargets(
        torch.linspace(0.1, 1, s.n_steps).expand(16, -1),
        torch.zeros(16, s.n_steps),
        torch.full((16,), 1e-4),
        torch.full((16,), 0.05),
    )
    out = {}
    for dev in ("cpu", "cuda"):
        gd = g.detach().to(dev).requires_grad_()
        moved = CurveTargets(
            *(x.to(dev) for x in (t.alpha_hat, t.stiffness_hat, t.p_star_max, t.alpha_max))
        )
        err = adhesive_error(gd, h.to(dev), moved, s, w.to(dev))
        err.sum().backward()
        out[dev] = (err.detach().cpu(), gd.grad.cpu())
    assert torch.allclose(out["cpu"][0], out["cuda"][0], rtol=1e-9, atol=1e-12)
    assert torch.allclose(out["cpu"][1], out["cuda"][1], rtol=1e-6, atol=1e-9)


def test_bem_check_on_cuda_matches_cpu(tmp_path):
    """The torch BEM engine solves the same contacts on CUDA as on the CPU: one design, and
    a batch of designs solved together (``validate_many(batch=...)``, a GPU's default)."""
    designs = [
        r.design
        for r in mi.design(
            ["saturating", "bilinear"],
            verify=False,
            device="cpu",
            effort=mi.Effort(refine_settings=QUICK),
        )
    ]
    a = mi.validate(designs[0], grid=96, loads=4, device="cpu")
    b = mi.validate(designs[0], grid=96, loads=4, device="cuda")
    np.testing.assert_allclose(b.p_star, a.p_star, rtol=1e-12)
    np.testing.assert_allclose(b.alpha_bem, a.alpha_bem, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(b.p_max, a.p_max, rtol=1e-5)
    out = mi.validate_many(
        designs, tmp_path / "many", grid=96, loads=4, device="cuda", batch=2, progress=False
    )
    assert len(out) == 2 and not any("error" in s for s in out.values())
    first = out[sorted(out)[0]]
    assert first["max_rel_err"] == pytest.approx(a.max_rel_err, rel=1e-4, abs=1e-9)


def test_adhesive_bem_check_on_cuda_matches_cpu():
    """An adhesive design's check (the JKR-limit BEM under a rising force) reads the same
    contact on CUDA as on the CPU, to a point of the grid (the detachment criterion is a
    comparison on the mesh, which rounding may tip at one boundary point)."""
    from metainterface.physics import CellSettings

    s, w = CellSettings(), 0.05 / (2.4e6 * 0.5e-3)  # PDMS on glass at R = 0.5 mm
    rng = np.random.default_rng(3)
    g, h = rng.uniform(1.8, 4.0, 9), rng.uniform(0, 0.6, 9) * s.delta_max
    model = mi.Independent(adhesion=w)
    with torch.no_grad():
        gt, ht = torch.as_tensor(g)[None], torch.as_tensor(h - h.min())[None]
        top = 0.9 * float(model.sweep(gt, ht, s).p_star[0, -1])
        p = np.linspace(1e-12 * top, top, 16)
        a = model.alpha_at_loads(gt, ht, s, torch.as_tensor(p)[None])[0].numpy()
    target = mi.Target(p_star=p, alpha=a, name="sticky")
    checks = {
        dev: mi.design(
            target,
            model=model,
            verify=mi.Verify(grid=48, loads=4, correct=False, device=dev),
            effort=mi.Effort(refine=False, seed=0),
        ).bem
        for dev in ("cpu", "cuda")
    }
    cpu, gpu = checks["cpu"], checks["cuda"]
    assert gpu.device.startswith("cuda") and cpu.device == "cpu"
    np.testing.assert_allclose(gpu.p_star, cpu.p_star, rtol=1e-6)
    np.testing.assert_allclose(gpu.alpha_bem, cpu.alpha_bem, atol=2 / 48**2)
    assert gpu.bem_error == pytest.approx(cpu.bem_error, abs=5e-3)


def test_adhesive_disc_check_on_cuda_matches_cpu():
    """The default adhesive check (the disc criterion over three grids) reads the same curve
    and error estimate on CUDA as on the CPU: its families and coupled solves are float64
    conjugate gradients to 1e-9 and 1e-10, its edges fits of their sums."""
    from metainterface.physics import CellSettings

    s, w = CellSettings(), 0.05 / (2.4e6 * 0.5e-3)  # PDMS on glass at R = 0.5 mm
    rng = np.random.default_rng(5)
    g, h = rng.uniform(1.8, 4.0, 9), rng.uniform(0, 0.6, 9) * s.delta_max
    design = mi.Design(gamma=g, h=h - h.min(), settings=s)
    model = mi.Independent(adhesion=w)
    with torch.no_grad():
        gt, ht = design.tensors(torch.float64)
        top = 0.9 * float(model.sweep(gt, ht, s).p_star[0, -1])
        p = np.linspace(1e-12 * top, top, 16)
        a = model.alpha_at_loads(gt, ht, s, torch.as_tensor(p)[None])[0].numpy()
    target = mi.Target(p_star=p, alpha=a, name="sticky")
    from metainterface.verify import bem_check

    checks = {
        dev: bem_check(design, target, mi.Verify(loads=6, correct=False, device=dev), model)
        for dev in ("cpu", "cuda")
    }
    cpu, gpu = checks["cpu"], checks["cuda"]
    assert gpu.device.startswith("cuda") and cpu.device == "cpu"
    assert any("family of bonded discs" in n for n in gpu.notes)
    np.testing.assert_allclose(gpu.p_star, cpu.p_star, rtol=1e-5)
    np.testing.assert_allclose(gpu.alpha_bem, cpu.alpha_bem, rtol=1e-5)
    assert gpu.accuracy == pytest.approx(cpu.accuracy, rel=1e-3)
