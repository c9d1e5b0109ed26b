"""`metainterface validate --physics`: the interacting model, and both models reported."""

from importlib.resources import files

import numpy as np
import pytest
import torch

from metainterface.cli import main
from metainterface.io import load_design
from metainterface.physics.forward import PHYSICS
from metainterface.physics.interaction import sweep_interacting
from metainterface.validation.models import MODELS, model_curve, models_at

EXAMPLE = str(files("metainterface") / "examples" / "example_design.json")


def test_interacting_model_curve():
    design = load_design(EXAMPLE)
    assert set(PHYSICS) <= set(MODELS)
    curve = model_curve(design, "interacting")
    np.testing.assert_allclose(curve.asperity_alpha.sum(axis=1), curve.alpha, rtol=1e-12)
    sw = sweep_interacting(*design.tensors(torch.float64), design.settings)
    assert curve.p_star_max == pytest.approx(float(sw.p_star[0, -1]), rel=1e-12)
    both = models_at(design, curve.p_star[[2000, 8192]])
    np.testing.assert_allclose(both["interacting"], curve.alpha[[2000, 8192]], rtol=1e-4)
    assert both["independent"][-1] != both["interacting"][-1]


def test_validate_physics_reports_both(tmp_path, capsys):
    out = tmp_path / "run"
    args = ["validate", EXAMPLE, "--grid", "96", "--loads", "2", "--jobs", "1"]
    assert main([*args, "--physics", "interacting", "--out", str(out)]) == 0
    bem = np.genfromtxt(out / "bem.csv", delimiter=",", names=True, skip_header=1)
    both = np.genfromtxt(out / "models.csv", delimiter=",", names=True, skip_header=1)
    assert both.dtype.names == (
        "p_star",
        "alpha_bem",
        "alpha_independent",
        "alpha_interacting",
        "rel_err_independent",
        "rel_err_interacting",
    )
    np.testing.assert_allclose(both["p_star"], bem["p_star"])
    np.testing.assert_allclose(both["alpha_interacting"], bem["alpha_model"], rtol=1e-4)
    np.testing.assert_allclose(
        both["rel_err_independent"], both["alpha_bem"] / both["alpha_independent"] - 1
    )
    printed = capsys.readouterr().out
    assert "by model (loads from the interacting model): independent" in printed
    assert '"loads_from": "interacting"' in (out / "models.csv").read_text().splitlines()[0]
