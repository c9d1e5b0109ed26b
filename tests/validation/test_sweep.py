"""Sweeps over many designs on local processes: summary table, whole folders, resume after a
kill, a dead worker process; BEM fields as a NetCDF file; the package without Dask."""

import json
import os
import signal
import subprocess
import sys
import threading
import time
from importlib.resources import files
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import metainterface as mi
from metainterface.cli import main

EXAMPLE = files("metainterface") / "examples" / "example_design.json"
SRC = str(Path(mi.__file__).parents[1])


def one_asperity(gamma: float) -> mi.Design:
    return mi.Design(
        gamma=np.array([gamma]), h=np.array([0.0]), settings=mi.CellSettings(n_asperities=1)
    )


def example_family(folder: Path, n: int) -> list[Path]:
    """n 9-asperity designs (the example, its heights scaled), saved in ``folder``."""
    base = mi.Design.load(EXAMPLE)
    paths = []
    for i in range(n):
        d = mi.Design(gamma=base.gamma, h=base.h * (1 + 0.1 * i), settings=base.settings)
        paths.append(d.save(folder / f"cell{i}.json"))
    return paths


def table(out: Path) -> pd.DataFrame:
    return pd.read_csv(out / "summary.csv", comment="#")


def test_fields_file_opens_with_xarray_and_carries_units(tmp_path):
    xr = pytest.importorskip("xarray")
    design = one_asperity(2.0)
    res = mi.validate(design, grid=64, loads=3, jobs=1, fields=True, out=tmp_path)
    ds = xr.open_dataset(tmp_path / "fields.nc")
    assert dict(ds.sizes) == {"load": 3, "y": 64, "x": 64}
    assert ds["pressure"].attrs["units"] == "1" and ds["gap"].attrs["units"] == "R"
    assert ds["x"].attrs["units"] == "R" and ds["p_star"].attrs["units"] == "1"
    side = design.settings.cell_side / design.settings.radius
    np.testing.assert_allclose(ds["x"].values, np.arange(64) * side / 64)
    np.testing.assert_allclose(ds["p_star"].values, res.p_star)
    np.testing.assert_array_equal(ds["pressure"].values[-1], res.pressure)
    # force balance: the mean contact pressure over the cell is the applied load P*
    np.testing.assert_allclose(ds["pressure"].mean(("x", "y")).values, res.p_star, rtol=1e-9)
    contact = ds["contact"].values.astype(bool)
    np.testing.assert_array_equal(contact, ds["pressure"].values > 0)
    gap = ds["gap"].values
    assert np.abs(gap[contact]).max() < 1e-9 and (gap[~contact] > 0).all()
    # contact grows with the load; its count is the BEM's plain pixel count
    np.testing.assert_allclose(contact.mean((1, 2)), res.alpha_bem_pixels)
    # the figure's pressure panel is drawn from this file; result.json records the fields
    assert json.loads((tmp_path / "result.json").read_text())["fields"] is True


def test_fields_in_metres_when_the_design_has_a_radius(tmp_path):
    xr = pytest.importorskip("xarray")
    design = mi.Design.load(EXAMPLE)
    physical = mi.physical(design, radius="0.5mm", modulus="2MPa")
    design = mi.Design(
        gamma=design.gamma, h=design.h, settings=design.settings, extras={"physical": physical}
    )
    mi.validate(design, grid=48, loads=2, jobs=1, fields=True, out=tmp_path)
    ds = xr.open_dataset(tmp_path / "fields.nc")
    assert ds["x"].attrs["units"] == "m" and ds["gap"].attrs["units"] == "m"
    pitch = ds["x"].values[1] * 48  # the cell side [m]
    assert pitch == pytest.approx(physical["cell_side_m"], rel=1e-9)


def test_sweep_on_the_command_line_writes_a_summary_table(tmp_path, capsys):
    designs = tmp_path / "designs"
    for gamma in (1.8, 2.5, 4.0):
        one_asperity(gamma).save(designs / f"g{gamma}.json")
    target = json.loads((designs / "g2.5.json").read_text())
    target["target"] = {"p_star": [0.0, 0.002], "alpha": [0.0, 0.03]}
    (designs / "g2.5.json").write_text(json.dumps(target))
    out = tmp_path / "sweep"
    args = ["validate", str(designs), "--grid", "32", "--loads", "2", "--workers", "2"]
    # --chunks 2: every design's two loads as two tasks, joined again in its folder
    assert main([*args, "--chunks", "2", "--fields", "--out", str(out)]) == 0
    t = table(out)
    assert list(t.columns) == [
        "name",
        "status",
        "max_rel_err_upper_half",
        "target_error_bem",
        "target_error_model",
        "error",
    ]
    assert list(t["name"]) == ["g1.8", "g2.5", "g4.0"] and set(t["status"]) == {"ok"}
    for name in t["name"]:
        summary = json.loads((out / name / "result.json").read_text())["summary"]
        row = t.set_index("name").loc[name]
        assert row["max_rel_err_upper_half"] == summary["max_rel_err_upper_half"]  # exact
        assert (out / name / "fields.nc").exists() and (out / name / "validation.png").exists()
        bem = pd.read_csv(out / name / "bem.csv", comment="#")
        assert len(bem) == 2 and (np.diff(bem["alpha_bem"]) > 0).all()
    assert t["target_error_bem"].notna().tolist() == [False, True, False]
    assert "3 designs validated, 0 failed" in capsys.readouterr().out
    # a list of files, and a design that fails (Tamaas on a one-point contact on an 8 x 8 grid)
    bad = mi.Design(gamma=np.full(4, 2.0), h=np.zeros(4)).save(tmp_path / "bad.json")
    files_ = [str(designs / "g1.8.json"), str(bad)]
    cmd = ["validate", *files_, "--grid", "8", "--loads", "20", "--engine", "tamaas"]
    assert main([*cmd, "--out", str(out)]) == 1
    t = table(out)
    assert t.set_index("name").loc["bad", "status"] == "failed"
    assert "BEM failed" in t.set_index("name").loc["bad", "error"]
    assert (out / "bad" / "error.txt").exists() and not (out / "bad" / "result.json").exists()


def test_a_folder_of_design_runs_is_swept_by_their_folder_names(tmp_path, capsys):
    """`design` writes RUN/<target>/design.json: a sweep over such files (or over RUN)
    names each result after its folder, and only colliding names take more of the path."""
    runs = tmp_path / "runs"
    one_asperity(2.0).save(runs / "soft" / "design.json")
    one_asperity(3.0).save(runs / "blunt" / "design.json")
    one_asperity(4.0).save(tmp_path / "other" / "soft" / "design.json")
    args = ["--grid", "16", "--loads", "2", "--workers", "1"]
    assert main(["validate", str(runs), *args, "--out", str(tmp_path / "a")]) == 0
    assert sorted(table(tmp_path / "a")["name"]) == ["blunt", "soft"]
    listed = [str(p) for p in sorted(tmp_path.glob("*/*/design.json"))]
    assert main(["validate", *listed, *args, "--out", str(tmp_path / "b")]) == 0
    assert sorted(table(tmp_path / "b")["name"]) == ["blunt", "other-soft", "runs-soft"]
    capsys.readouterr()
    same = [listed[0], listed[0]]
    assert main(["validate", *same, *args, "--out", str(tmp_path / "c")]) == 2
    assert "must be unique" in capsys.readouterr().err


def test_a_sweep_after_multithreaded_torch_work_does_not_hang(tmp_path):
    """Workers are forked (ours, and a user's ProcessPoolExecutor): one that ran torch on
    several threads after the parent had used torch's OpenMP threads would hang in its first
    torch operation (as the CI did, which runs without OMP_NUM_THREADS=1)."""
    script = f"""
import numpy as np, torch
import metainterface as mi
torch.set_num_threads(2)
x = torch.rand(1024, 1024, dtype=torch.float64)
(x @ x).exp().sum()  # the parent's OpenMP threads are up
cell = mi.CellSettings(n_asperities=1)
designs = [mi.Design(gamma=np.array([g]), h=np.array([0.0]), settings=cell) for g in (2.0, 3.0)]
mi.validate_many(designs, {str(tmp_path / "sweep")!r}, grid=16, loads=2, jobs=2, progress=False)
from concurrent.futures import ProcessPoolExecutor
with ProcessPoolExecutor(2) as ex:
    mi.validate_many(designs, {str(tmp_path / "own")!r}, grid=16, loads=2, executor=ex,
                     progress=False)
print("swept")
"""
    env = {k: v for k, v in os.environ.items() if k != "OMP_NUM_THREADS"}
    env["PYTHONPATH"] = SRC
    done = subprocess.run(
        [sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=180
    )
    assert done.returncode == 0 and "swept" in done.stdout, done.stderr[-2000:]


def _run_cli(args: list[str], **kw) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": SRC, "OMP_NUM_THREADS": "1"}
    return subprocess.Popen(
        [sys.executable, "-m", "metainterface", *args],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,  # its own process group: the kill reaches its workers too
        **kw,
    )


def test_a_killed_sweep_resumes_and_gives_the_same_table(tmp_path):
    designs = tmp_path / "designs"
    example_family(designs, 5)
    args = ["validate", str(designs), "--grid", "96", "--loads", "8", "--no-figures"]
    reference = tmp_path / "reference"
    assert main([*args, "--workers", "1", "--out", str(reference)]) == 0

    out = tmp_path / "killed"
    proc = _run_cli([*args, "--workers", "1", "--out", str(out)])
    try:
        deadline = time.monotonic() + 120
        while not (out / "cell0" / "result.json").exists():
            assert proc.poll() is None, "the sweep ended before it could be killed"
            assert time.monotonic() < deadline
            time.sleep(0.02)
        os.killpg(proc.pid, signal.SIGKILL)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    assert proc.returncode == -signal.SIGKILL
    done_before = sorted(p.parent.name for p in out.glob("*/result.json"))
    assert 1 <= len(done_before) < 5
    stamps = {n: (out / n / "result.json").stat().st_mtime_ns for n in done_before}

    assert main([*args, "--workers", "2", "--out", str(out)]) == 0
    pd.testing.assert_frame_equal(table(out), table(reference))
    for name, stamp in stamps.items():  # resumed: finished designs were not solved again
        assert (out / name / "result.json").stat().st_mtime_ns == stamp
    assert not list(out.glob(".*"))  # no half-written folder left behind


def test_any_executor_plugs_in(tmp_path):
    from concurrent.futures import ProcessPoolExecutor

    paths = [one_asperity(g).save(tmp_path / f"g{g}.json") for g in (2.0, 3.0)]
    kw = dict(grid=32, loads=2, progress=False)
    with ProcessPoolExecutor(2) as ex:
        mi.validate_many(paths, tmp_path / "pool", executor=ex, **kw)
    mi.validate_many(paths, tmp_path / "serial", **kw)
    pd.testing.assert_frame_equal(table(tmp_path / "pool"), table(tmp_path / "serial"))
    with pytest.raises(mi.MetainterfaceError, match="executor or scheduler, not both"):
        mi.validate_many(paths, tmp_path / "x", executor=ex, scheduler="local", **kw)


def test_a_dead_worker_process_has_its_task_retried(tmp_path):
    psutil = pytest.importorskip("psutil")
    designs = tmp_path / "designs"
    paths = example_family(designs, 4)
    kw = dict(grid=96, loads=8, progress=False)
    reference = mi.validate_many(paths, tmp_path / "reference", jobs=1, **kw)

    me = psutil.Process()
    killed: list[int] = []

    def kill_a_worker() -> None:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not killed:
            busy = [p for p in me.children() if p.cpu_percent(interval=0.05) > 10]
            if busy:
                busy[0].send_signal(signal.SIGKILL)
                killed.append(busy[0].pid)

    killer = threading.Thread(target=kill_a_worker)
    killer.start()
    try:
        result = mi.validate_many(paths, tmp_path / "sweep", jobs=2, **kw)
    finally:
        killer.join()
    assert killed, "no worker was seen working"

    def solved(summaries):  # all but the wall times
        return {n: {k: v for k, v in s.items() if k != "bem_seconds"} for n, s in summaries.items()}

    assert solved(result) == solved(reference)
    assert table(tmp_path / "sweep").equals(table(tmp_path / "reference"))


def test_no_dask_means_a_one_line_hint_and_local_runs_still_work(tmp_path, capsys, monkeypatch):
    for name in ("dask", "dask.distributed", "distributed"):
        monkeypatch.setitem(sys.modules, name, None)  # import -> ImportError
    designs = tmp_path / "designs"
    one_asperity(2.0).save(designs / "a.json")
    one_asperity(3.0).save(designs / "b.json")
    args = ["validate", str(designs), "--grid", "32", "--loads", "2"]
    assert main([*args, "--scheduler", "local", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pip install 'metainterface[distributed]'" in err[0]
    assert main([*args, "--workers", "2", "--out", str(tmp_path / "ok")]) == 0
    assert set(table(tmp_path / "ok")["status"]) == {"ok"}


def test_importing_the_package_imports_neither_dask_nor_xarray():
    code = (
        "import sys, metainterface, metainterface.cli, metainterface.validation; "
        "print(sorted(m for m in ('dask', 'distributed', 'xarray') if m in sys.modules))"
    )
    env = {**os.environ, "PYTHONPATH": SRC}
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == "[]"


def test_no_xarray_means_a_one_line_hint_before_any_solve(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "xarray", None)
    d = one_asperity(2.0).save(tmp_path / "a.json")
    out = tmp_path / "run"
    assert main(["validate", str(d), "--grid", "32", "--fields", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pip install 'metainterface[fields]'" in err[0]
    assert not out.exists()
