"""`metainterface generate`: a run end to end, and one-line errors (exit 2) for bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from metainterface.cli import main
from metainterface.data import load_dataset
from metainterface.physics import CellSettings


def test_generate_writes_dataset_and_plot(tmp_path, capsys):
    out, fig = tmp_path / "d.npz", tmp_path / "d.png"
    argv = ["generate", "--samples", "120", "--seed", "5", "--out", str(out), "--quiet"]
    assert main([*argv, "--n-asperities", "4", "--delta-max", "0.01", "--plot", str(fig)]) == 0
    ds = load_dataset(out, CellSettings(n_asperities=4, delta_max=0.01))
    assert len(ds) == 120 and ds.gamma.shape == (120, 4)
    assert json.loads(json.dumps(ds.meta))["settings"]["seed"] == 5
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    line = capsys.readouterr().out.strip()
    assert line.startswith(str(out)) and "120 samples" in line


def test_generate_same_seed_same_file_content(tmp_path):
    for name in ("a", "b"):
        out = str(tmp_path / f"{name}.npz")
        assert main(["generate", "--samples", "50", "--seed", "9", "--out", out, "--quiet"]) == 0
    a, b = load_dataset(tmp_path / "a.npz"), load_dataset(tmp_path / "b.npz")
    np.testing.assert_array_equal(a.alpha_hat, b.alpha_hat)
    np.testing.assert_array_equal(a.split, b.split)


@pytest.mark.parametrize(
    ("extra", "named"),
    [
        (["--samples", "0"], "0"),
        (["--samples", "-3"], "-3"),
        (["--samples", "many"], "'many'"),
        (["--n-asperities", "8"], "8"),
        (["--gamma-min", "1.0"], "1.0"),
        (["--gamma-min", "0.5"], "0.5"),
        (["--gamma-min", "4.0"], "4.0"),
        (["--gamma-min", "3", "--gamma-max", "2"], "2.0"),
        (["--delta-max", "0"], "0.0"),
        (["--delta-max", "-0.1"], "-0.1"),
        (["--delta-max", "nan"], "nan"),
        (["--seed", "-1"], "-1"),
        (["--plot", "fig.gif"], ".gif"),
    ],
)
def test_bad_input_is_one_line_exit_2_no_file(tmp_path, capsys, extra, named):
    out = tmp_path / "d.npz"
    argv = ["generate", "--samples", "20", "--seed", "1", "--out", str(out), "--quiet"]
    assert main([*argv, *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith("metainterface generate: error:")
    assert named in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("where", ["under_a_file", "a_folder"])
def test_unwritable_output_is_one_line_exit_2(tmp_path, capsys, where):
    blocker = tmp_path / "file.txt"
    blocker.write_text("x")
    out = blocker / "d.npz" if where == "under_a_file" else tmp_path
    before = sorted(tmp_path.rglob("*"))
    argv = ["generate", "--samples", "20", "--seed", "1", "--out", str(out), "--quiet"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and str(out) in err
    assert sorted(tmp_path.rglob("*")) == before
