"""The refinement's loss: the fused interpolated loss against autograd through its parts, and
the closed-form gradients (``physics.tape``) against autograd's."""

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface.inverse import builtin_target
from metainterface.inverse.losses import InterpolatedLoss, TargetGrid, masked_loss
from metainterface.inverse.params import FULL, HERTZ, FixedHeights, snap_heights
from metainterface.inverse.refine import RefineSettings, polish, refine
from metainterface.physics import CellSettings, Independent
from metainterface.physics.pressures import alpha_at

F64 = torch.float64


def test_interpolated_loss_gradcheck():
    # knots with a repeated point (a zero-width interval) and queries beyond the last knot
    gen = torch.Generator().manual_seed(0)
    p = torch.rand(2, 12, generator=gen, dtype=F64).cumsum(-1)
    p[:, 5] = p[:, 4]
    alpha = torch.rand(2, 12, generator=gen, dtype=F64).cumsum(-1)
    q = torch.linspace(0.05, 1.3, 40, dtype=F64).expand(2, -1).contiguous() * p[:, -1:]
    target = torch.rand(2, 40, generator=gen, dtype=F64)

    def loss(p_, a_):
        return InterpolatedLoss.apply(p_, a_, q, target, 0.1)

    assert torch.autograd.gradcheck(loss, (p.requires_grad_(), alpha.requires_grad_()))


def test_stage_loss_equals_the_masked_mse_of_the_interpolated_curve():
    # appendix C: weight 1 where the curve reaches the target's pressure, 0.1 beyond, over
    # the weights' sum, relative to mean(alpha_t^2); alpha by linear interpolation in the
    # sweep with a (0, 0) knot first, written out with autograd
    s = CellSettings()
    targets = [builtin_target(n) for n in ("saturating", "bilinear", "linear")]
    grid = TargetGrid.from_curves([(t.p_star, t.alpha) for t in targets], 64)
    gen = torch.Generator().manual_seed(1)
    raw = (torch.randn(3, 17, generator=gen, dtype=F64) - 1.0).requires_grad_(True)
    g, h = FULL.to_design(raw, s)
    fused = masked_loss(g, h, s, grid, 1e3)
    (grad,) = torch.autograd.grad(fused.sum(), raw, retain_graph=True)
    a, p_max = alpha_at(g, h, s, grid.p, smooth=1e3)
    w = torch.where(grid.p <= p_max[:, None], 1.0, 0.1)
    plain = (w * (a - grid.alpha) ** 2).sum(-1) / w.sum(-1) / (grid.alpha**2).mean(-1)
    (grad_plain,) = torch.autograd.grad(plain.sum(), raw)
    torch.testing.assert_close(fused, plain, rtol=1e-12, atol=0)
    torch.testing.assert_close(grad, grad_plain, rtol=1e-10, atol=1e-16)


class _AutogradOnly(Independent):
    """The paper's model without its closed-form pullback: the refinement takes autograd."""

    def load_area_pullback(self, settings, smooth=None):
        return None


@pytest.mark.parametrize("param", ["full", "hertz", "fixed heights"])
def test_closed_form_refinement_takes_autograds_steps(param):
    # The stages, the Levenberg-Marquardt polish and the exact-law L-BFGS, each by hand
    # (physics.tape) and through autograd, from the same starts: the same gradients to the
    # bit, so the same iterates (a gradient off in its last bits would part them within a
    # few dozen steps on the exact law's kinks)
    s = CellSettings()
    targets = [builtin_target(n) for n in ("saturating", "bilinear", "linear")]
    grid = TargetGrid.from_curves([(t.p_star, t.alpha) for t in targets], 64)
    gen = torch.Generator().manual_seed(3)
    gamma, h = FULL.random(3, s, gen)
    p = {
        "full": FULL,
        "hertz": HERTZ,
        "fixed heights": FixedHeights(h=snap_heights(h, s.delta_max / 20)),
    }[param]
    raw = p.from_design(gamma, h, s)
    rs = RefineSettings(stages=2, steps_per_stage=2, iterations=10, polish_iterations=15)
    runs = []
    for model in (Independent(), _AutogradOnly()):
        x = refine(raw, s, grid, rs, p, model=model)
        y = polish(x, s, grid, rs, p, model=model)  # LM, then L-BFGS where it stalls
        z = refine(x, s, grid, rs.polishing(), p, model=model)  # L-BFGS on the exact law
        runs.append((x, y, z))
    for closed, autograd in zip(*runs, strict=True):
        assert torch.equal(closed, autograd)
    assert not torch.equal(runs[0][0], raw)  # the steps moved


def test_a_design_is_the_same_without_the_closed_form():
    # the public call, as a user with a model of their own (no closed form) makes it
    effort = mi.Effort(hedge=0, fallback=0)
    fast = mi.design("saturating", verify=False, effort=effort)
    slow = mi.design("saturating", verify=False, effort=effort, model=_AutogradOnly())
    assert fast.error == slow.error
    np.testing.assert_array_equal(fast.design.gamma, slow.design.gamma)
    np.testing.assert_array_equal(fast.design.h, slow.design.h)
