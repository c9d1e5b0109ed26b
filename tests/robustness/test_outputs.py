"""Outputs: all of a command's files or none, only regular files replaced, strict JSON,
temporaries of killed runs swept."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from robust_helpers import run_cli, snapshot, strict_json

import metainterface as mi


@pytest.fixture
def design_file(tmp_path):
    path = tmp_path / "design.json"
    mi.Design(gamma=[2.0, 2.5, 3.0, 3.5], h=[0.0, 0.002, 0.004, 0.008]).save(path)
    return path


def test_a_failed_plot_leaves_no_csv(tmp_path, design_file, capsys):
    out = tmp_path / "out"
    rc, lines = run_cli(
        ["curve", str(design_file), "--out", str(out / "c.csv"), "--plot", str(out / "c.bogus")],
        capsys,
    )
    assert rc == 2 and len(lines) == 1
    assert not out.exists()  # neither the CSV nor the folder made for it


def test_export_writes_file_and_sidecar_together(tmp_path, design_file, capsys):
    out = tmp_path / "p.stl"
    rc, _ = run_cli(["export", str(design_file), "--radius", "0.5mm", "--out", str(out)], capsys)
    assert rc == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["design.json", "p.stl", "p.stl.json"]
    record = strict_json(tmp_path / "p.stl.json")
    assert record["watertight"] is True and record["triangles"] > 0


@pytest.mark.parametrize("kind", ["symlink", "fifo", "folder"])
def test_only_regular_files_are_replaced(tmp_path, design_file, capsys, kind):
    victim = tmp_path / "victim"
    target = tmp_path / "precious.txt"
    target.write_text("keep me\n")
    if kind == "symlink":
        victim.symlink_to(target)
    elif kind == "fifo":
        os.mkfifo(victim)
    else:
        victim.mkdir()
    before = snapshot(tmp_path)
    rc, lines = run_cli(["curve", str(design_file), "--out", str(victim)], capsys)
    assert rc == 2 and len(lines) == 1 and "victim" in lines[0]
    assert snapshot(tmp_path) == before
    assert target.read_text() == "keep me\n"


def test_stale_temporaries_of_dead_processes_are_swept(tmp_path, design_file, capsys):
    """A run killed outright leaves its temporary; the next write in that folder removes it
    (and leaves a live process's temporary alone)."""
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        capture_output=True,
        text=True,
        check=True,
    )
    stale = tmp_path / f".c.csv.mi-{int(dead.stdout)}-abc123.tmp"
    live = tmp_path / f".c.csv.mi-{os.getppid()}-def456.tmp"
    stale.write_bytes(b"x" * 1000)
    live.write_bytes(b"y")
    rc, _ = run_cli(["curve", str(design_file), "--out", str(tmp_path / "c.csv")], capsys)
    assert rc == 0
    assert not stale.exists() and live.exists()


def test_design_outputs_are_strict_json(tmp_path, capsys):
    rc, _ = run_cli(
        [
            "design",
            "--target",
            "linear",
            "--method",
            "hertz",
            "--starts",
            "2",
            "--out",
            str(tmp_path / "d"),
            "--verify-grid",
            "96",
            "--verify-loads",
            "3",
            "--max-bem-error",
            "100",
        ],
        capsys,
    )
    assert rc == 0
    record = strict_json(tmp_path / "d" / "design.json")
    assert record["format"] == "metainterface/design-v1"
    assert record["bem_check"]["grid"] == 96
    assert not [p for p in (tmp_path / "d").iterdir() if p.name.startswith(".")]


def test_a_non_finite_figure_is_written_as_null(tmp_path):
    """A result holding a non-finite number still gives standard JSON: null, not NaN."""
    d = mi.Design(gamma=[2.0] * 4, h=[0.0] * 4, extras={"note": {"score": float("nan")}})
    path = d.save(tmp_path / "d.json")
    assert strict_json(path)["note"]["score"] is None
    json.loads(path.read_text())  # and it loads back


def test_validate_writes_its_set_and_strict_json(tmp_path, design_file, capsys):
    pytest.importorskip("tamaas")
    out = tmp_path / "v"
    rc, _ = run_cli(
        ["validate", str(design_file), "--grid", "32", "--loads", "2", "--out", str(out)], capsys
    )
    assert rc == 0
    names = sorted(p.name for p in out.iterdir())
    assert "result.json" in names and "bem.csv" in names
    assert not [n for n in names if n.startswith(".")]
    record = strict_json(out / "result.json")
    assert record


def test_generate_refuses_a_dataset_of_non_finite_curves(tmp_path):
    """A cell whose curves leave float32's range is refused, not written as NaN."""
    with pytest.raises(mi.MetainterfaceError) as info:
        mi.generate_dataset(
            20,
            tmp_path / "d.npz",
            settings=mi.CellSettings(radius=1e-12, delta_max=1e-21),
            progress=False,
        )
    assert "\n" not in str(info.value)
    assert not list(tmp_path.iterdir())


def test_a_dataset_with_a_nan_is_refused(tmp_path):
    good = tmp_path / "good.npz"
    mi.generate_dataset(60, good, progress=False)
    with np.load(good) as npz:
        arrays = dict(npz)
    arrays["p_star_max"][7] = np.inf
    np.savez(tmp_path / "bad.npz", **arrays)
    with pytest.raises(mi.MetainterfaceError, match="row 7 of p_star_max"):
        mi.train_surrogate(tmp_path / "bad.npz", tmp_path / "run")
    assert not (tmp_path / "run").exists()
