"""One curve error everywhere: sqrt(fit^2 + (1 - coverage)^2), the same figure in design,
tolerance, validate's model column and design.json."""

import json

import numpy as np
import pytest
import torch

import metainterface as mi
from metainterface.physics.curves import idle_mask
from metainterface.physics.metrics import coverage, curve_error


def test_curve_error_closed_forms():
    p = np.linspace(0.0, 1.0, 101)
    ref = 2.0 * p
    # met exactly over the whole range: 0
    assert curve_error(ref[None], ref[None], p[None], np.array([1.0]))[0] == 0.0
    # met exactly up to 0.6, nothing beyond: the missed 40 % of the load range, whatever the
    # curve does past its reach
    wild = np.where(p <= 0.6, ref, 50.0)
    assert curve_error(wild[None], ref[None], p[None], np.array([0.6]))[0] == pytest.approx(0.4)
    # off by 10 % everywhere it reaches, all of it reached: the plain relative L2 error
    assert curve_error(1.1 * ref[None], ref[None], p[None], np.array([2.0]))[0] == pytest.approx(
        0.1
    )
    # both: sqrt(0.1^2 + 0.5^2)
    half = curve_error(1.1 * ref[None], ref[None], p[None], np.array([0.5]))[0]
    assert half == pytest.approx(np.hypot(0.1, 0.5))
    # torch in, torch out; coverage clipped to [0, 1]
    t = torch.as_tensor(p)[None]
    assert torch.is_tensor(curve_error(t, t, t, torch.tensor([3.0])))
    assert float(coverage(t, torch.tensor([3.0]))[0]) == 1.0
    assert float(coverage(t, torch.tensor([-1.0]))[0]) == 0.0


def test_idle_mask_counts_asperities_past_delta_max_and_past_the_range():
    s = mi.CellSettings(n_asperities=4)
    g = torch.full((1, 4), 2.0, dtype=torch.float64)
    h = torch.tensor([[0.0, 0.2, 0.9, 1.5]], dtype=torch.float64) * s.delta_max
    assert idle_mask(g, h, s)[0].tolist() == [False, False, False, True]
    # a target that ends at the load where the third touches: it carries nothing within it
    from metainterface.physics.curves import sweep

    p_third = sweep(g, h, s, delta=torch.tensor([[0.9 * s.delta_max]])).p_star[:, 0]
    assert idle_mask(g, h, s, p_third)[0].tolist() == [False, False, True, True]


@pytest.fixture(scope="module")
def stopped(tmp_path_factory):
    """A design that stops at 2/3 of its target's load range (built-in bilinear scaled)."""
    t = mi.Target.builtin("saturating")
    longer = mi.Target(
        p_star=np.concatenate([t.p_star, t.p_star[-1] * np.linspace(1.01, 1.5, 50)]),
        alpha=np.concatenate([t.alpha, t.alpha[-1] * np.linspace(1.005, 1.2, 50)]),
        name="longer",
    )
    folder = tmp_path_factory.mktemp("stopped")
    return mi.design(
        longer, out=folder, verify=False, effort=mi.Effort(hedge=0, fallback=0)
    ), folder


def test_design_reports_coverage_and_carrying(stopped):
    r, folder = stopped
    assert r.coverage < 0.8 and r.error >= 1 - r.coverage
    assert r.carrying == r.design.n_asperities - len(r.idle)
    text = repr(r)
    assert "coverage=" in text and f"carrying {r.carrying} of 9" in text
    assert "np.int" not in text and "np.float" not in text
    rec = json.loads((folder / "design.json").read_text())
    assert rec["relative_error"] == r.error and rec["coverage"] == pytest.approx(r.coverage)
    assert rec["error_definition"] == "sqrt(fit^2 + (1 - coverage)^2)"
    assert any("coverage" in n for n in r.notes)


def test_the_same_error_in_design_tolerance_and_validate(stopped):
    r, folder = stopped
    tol = mi.tolerance(r, sigma_h=0.0, samples=16)
    assert tol.error_nominal == pytest.approx(r.error, rel=1e-9)
    assert tol.coverage == pytest.approx(r.coverage) and tol.carrying == r.carrying
    # from the design file, as a user re-measures it later: its stored target is this
    # one's 1067 points decimated to 1024, which moves the error by ~1e-5 of itself
    tol_file = mi.tolerance(folder / "design.json", sigma_h=0.0, samples=16)
    assert tol_file.error_nominal == pytest.approx(r.error, rel=1e-4)
    pytest.importorskip("tamaas")
    v = mi.validate(folder / "design.json", grid=48, loads=3)
    bem, model = v.target_errors()
    assert bem > 0 and bem == pytest.approx(model, abs=0.05)  # the BEM agrees to ~grid error
    assert model == pytest.approx(tol_file.error_nominal, rel=1e-9)
    assert v.coverage == pytest.approx(r.coverage, rel=1e-6)
    assert v.summary()["target_error_model"] == model and v.carrying == r.carrying
