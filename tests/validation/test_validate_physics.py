"""The interacting model's dense curve for BEM, and every model at one set of loads."""

from importlib.resources import files

import numpy as np
import pytest
import torch

from metainterface.physics import Design
from metainterface.physics.interaction import sweep_interacting
from metainterface.physics.registry import MODELS, get_model, models_at

EXAMPLE = str(files("metainterface") / "examples" / "example_design.json")


def test_interacting_model_curve():
    design = Design.load(EXAMPLE)
    assert {"independent", "interacting"} <= set(MODELS)
    curve = get_model("interacting").model_curve(design)
    np.testing.assert_allclose(curve.asperity_alpha.sum(axis=1), curve.alpha, rtol=1e-12)
    sw = sweep_interacting(*design.tensors(torch.float64), design.settings)
    assert curve.p_star_max == pytest.approx(float(sw.p_star[0, -1]), rel=1e-12)
    both = models_at(design, curve.p_star[[2000, 8192]])
    np.testing.assert_allclose(both["interacting"], curve.alpha[[2000, 8192]], rtol=1e-4)
    assert both["independent"][-1] != both["interacting"][-1]


def test_an_adhesive_model_is_refused_not_compared_with_a_bem_without_adhesion(tmp_path):
    """This BEM leaves adhesion out: against an adhesive model every load would read
    adhesion's own effect (tens of per cent at low load) as the model's error. (One
    design's ``mi.validate`` runs the adhesive BEM instead: test_adhesive_validate.py.)"""
    import metainterface as mi

    model = mi.Independent(adhesion=4e-5)
    with pytest.raises(mi.MetainterfaceError, match="has adhesion, which this BEM leaves out"):
        mi.validate_many([EXAMPLE], tmp_path / "many", grid=48, loads=2, model=model)
