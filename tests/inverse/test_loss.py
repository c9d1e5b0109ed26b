"""The refinement's loss: the fused interpolated loss against autograd through its parts."""

import torch

from metainterface.inverse import builtin_target
from metainterface.inverse.params import FULL
from metainterface.inverse.refine import InterpolatedLoss, TargetGrid, masked_loss
from metainterface.physics import CellSettings
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
