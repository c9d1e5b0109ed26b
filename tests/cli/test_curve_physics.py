"""`metainterface curve --physics`: the interacting model through the command line."""

from importlib.resources import files

import numpy as np
import pytest

import metainterface as mi
from metainterface.cli import main

EXAMPLE = str(files("metainterface") / "examples" / "example_design.json")


def read(path):
    return np.genfromtxt(path, delimiter=",", names=True, skip_header=1)


def test_curve_physics_option(tmp_path, capsys):
    ind, inter = tmp_path / "i.csv", tmp_path / "j.csv"
    assert main(["curve", EXAMPLE, "--steps", "64", "--out", str(ind)]) == 0
    assert "(independent)" in capsys.readouterr().out
    args = ["curve", EXAMPLE, "--steps", "64", "--physics", "interacting", "--out", str(inter)]
    assert main(args) == 0
    assert "(interacting)" in capsys.readouterr().out
    a, b = read(ind), read(inter)
    assert a.dtype.names == b.dtype.names == ("delta", "p_star", "alpha", "stiffness")
    np.testing.assert_array_equal(a["delta"], b["delta"])
    assert b["alpha"][0] == 0 and np.all(np.diff(b["alpha"]) >= 0)
    assert np.all(np.isfinite(b["stiffness"]))
    assert np.abs(b["alpha"] - a["alpha"]).max() > 1e-4 * a["alpha"].max()
    assert '"model": "interacting"' in inter.read_text().splitlines()[0]


def test_curve_physics_choices(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["curve", EXAMPLE, "--physics", "coupled", "--out", str(tmp_path / "c.csv")])
    assert exc.value.code == 2
    assert "independent" in capsys.readouterr().err
    # the command's choices are the dispatcher's
    from metainterface.cli import build_parser

    sub = build_parser()._subparsers._group_actions[0].choices["curve"]
    (opt,) = [a for a in sub._actions if a.dest == "physics"]
    # no default of its own: the design file's model (tests/physics/test_model_labels.py)
    assert tuple(opt.choices) == tuple(mi.MODELS) and opt.default is None
