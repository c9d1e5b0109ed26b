"""`metainterface curve`: output columns, plot, exit status 2 with one line on bad input."""

import json
from importlib.resources import files

import numpy as np

from metainterface.cli import main

EXAMPLE = str(files("metainterface") / "examples" / "example_design.json")


def test_curve_writes_csv_and_plot(tmp_path, capsys):
    out, fig = tmp_path / "c.csv", tmp_path / "c.png"
    assert main(["curve", EXAMPLE, "--steps", "64", "--out", str(out), "--plot", str(fig)]) == 0
    data = np.genfromtxt(out, delimiter=",", names=True, skip_header=1)
    assert data.dtype.names == ("delta", "p_star", "alpha", "stiffness")
    assert len(data) == 64 and data["p_star"][0] == 0 and np.all(np.diff(data["alpha"]) >= 0)
    assert fig.stat().st_size > 10_000
    assert "P*_max" in capsys.readouterr().out
    assert out.read_text().startswith("# {")


def test_curve_smooth_differs_from_exact(tmp_path):
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    main(["curve", EXAMPLE, "--out", str(a)])
    main(["curve", EXAMPLE, "--smooth", "1000", "--out", str(b)])
    ea = np.genfromtxt(a, delimiter=",", names=True, skip_header=1)
    eb = np.genfromtxt(b, delimiter=",", names=True, skip_header=1)
    assert eb["alpha"][0] > 0 == ea["alpha"][0]


def test_bad_input_is_one_line_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"gamma": [2.0] * 4, "h": [0, 0, 0, -1]}))
    out = tmp_path / "c.csv"
    assert main(["curve", str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "h[3]" in err
    assert not out.exists()
    assert main(["curve", str(tmp_path / "missing.json"), "--out", str(out)]) == 2
    assert main(["curve", EXAMPLE, "--out", str(tmp_path / "x.png.csv"), "--plot", "a.bmp"]) == 2
