"""BEM sweeps on a real dask.distributed cluster on this machine: a LocalCluster of two
processes, and a scheduler and workers started as separate processes that the sweep joins by
address (from the command line and from Python); a worker killed mid-task."""

import importlib
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

distributed = pytest.importorskip("distributed")

EXAMPLE = files("metainterface") / "examples" / "example_design.json"
SRC = str(Path(mi.__file__).parents[1])


def _dask_cli(*args: str) -> list[str]:
    """The `dask` command of this interpreter's environment."""
    return [str(Path(sys.executable).with_name("dask")), *args]


def one_asperity(gamma: float) -> mi.Design:
    return mi.Design(
        gamma=np.array([gamma]), h=np.array([0.0]), settings=mi.CellSettings(n_asperities=1)
    )


def small_designs(folder: Path) -> list[Path]:
    return [one_asperity(g).save(folder / f"g{g}.json") for g in (1.8, 2.5, 4.0)]


def table(out: Path) -> pd.DataFrame:
    return pd.read_csv(out / "summary.csv", comment="#")


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    """The same sweep in this process, to compare with."""
    root = tmp_path_factory.mktemp("serial")
    paths = small_designs(root / "designs")
    mi.validate_many(paths, root / "out", grid=32, loads=3, progress=False)
    return paths, table(root / "out")


def test_a_local_cluster_of_two_processes(serial, tmp_path):
    paths, reference = serial
    out = tmp_path / "out"
    mi.validate_many(paths, out, grid=32, loads=3, scheduler="local", jobs=2, progress=False)
    pd.testing.assert_frame_equal(table(out), reference)


class Cluster:
    """`dask scheduler` and `dask worker` as separate processes; the address comes from the
    scheduler file. Every process is killed on close."""

    def __init__(self, folder: Path, workers: int):
        self.procs: list[subprocess.Popen] = []
        try:
            self._start(folder, workers)
        except BaseException:
            self.close()
            raise

    def _start(self, folder: Path, workers: int) -> None:
        self.file = folder / "scheduler.json"
        env = {**os.environ, "PYTHONPATH": SRC, "OMP_NUM_THREADS": "1"}
        log = open(folder / "dask.log", "w")  # noqa: SIM115 (closed in close())
        self.log = log
        common = dict(env=env, stdout=log, stderr=log, start_new_session=True)
        self.procs.append(
            subprocess.Popen(
                _dask_cli(
                    "scheduler",
                    "--port",
                    "0",
                    "--no-dashboard",
                    "--scheduler-file",
                    str(self.file),
                ),
                **common,
            )
        )
        deadline = time.monotonic() + 60
        while not self.file.exists():
            assert time.monotonic() < deadline, "the scheduler did not start"
            time.sleep(0.1)
        self.address = json.loads(self.file.read_text())["address"]
        self.procs.append(
            subprocess.Popen(
                _dask_cli(
                    "worker",
                    self.address,
                    "--nworkers",
                    str(workers),
                    "--nthreads",
                    "1",
                    "--no-dashboard",
                ),
                **common,
            )
        )
        with distributed.Client(self.address, timeout=30, set_as_default=False) as client:
            client.wait_for_workers(workers, timeout=60)
            # every worker imports the package once, side by side
            client.run(importlib.import_module, "metainterface.validation.executors")

    def close(self) -> None:
        for proc in reversed(self.procs):
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        if hasattr(self, "log"):
            self.log.close()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    c = Cluster(tmp_path_factory.mktemp("cluster"), workers=2)
    try:
        yield c
    finally:
        c.close()


def test_a_running_cluster_joined_by_address(serial, cluster, tmp_path, capsys):
    paths, reference = serial
    out = tmp_path / "cli"
    args = ["validate", *map(str, paths), "--grid", "32", "--loads", "3", "--no-figures"]
    assert main([*args, "--scheduler", cluster.address, "--out", str(out)]) == 0
    pd.testing.assert_frame_equal(table(out), reference)
    assert "3 designs validated" in capsys.readouterr().out
    # from Python, one design, its load path in two warm-started chunks on the two workers
    res = mi.validate(paths[1], grid=64, loads=4, jobs=2, scheduler=cluster.address)
    ref = mi.validate(paths[1], grid=64, loads=4, jobs=1)
    np.testing.assert_allclose(res.alpha_bem, ref.alpha_bem, rtol=1e-3)
    np.testing.assert_allclose(res.p_max, ref.p_max, rtol=1e-6)
    # any concurrent.futures.Executor plugs in: here the cluster's, from its own client
    with distributed.Client(cluster.address, timeout=30) as client:
        again = mi.validate(paths[1], grid=64, loads=4, jobs=2, executor=client.get_executor())
    np.testing.assert_array_equal(again.alpha_bem, res.alpha_bem)


def test_an_unreachable_scheduler_is_one_line(tmp_path, capsys):
    d = one_asperity(2.0).save(tmp_path / "a.json")
    out = tmp_path / "out"
    args = ["validate", str(d), str(d.with_name("b.json")), "--grid", "32", "--loads", "2"]
    d.with_name("b.json").write_text(d.read_text())
    mi_args = [*args, "--scheduler", "tcp://127.0.0.1:9", "--out", str(out)]
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr("metainterface.validation.cluster.CONNECT_TIMEOUT", 0.5)
        assert main(mi_args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot reach the Dask scheduler at tcp://127.0.0.1:9" in err[0]
    assert main([*args, "--scheduler", "somehost:8786", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "scheduler must be 'local' or an address like tcp://" in err[0]
    assert not out.exists()


def test_a_worker_killed_mid_task_has_its_task_retried(cluster, tmp_path):
    base = mi.Design.load(EXAMPLE)
    paths = [
        mi.Design(gamma=base.gamma, h=base.h * (1 + 0.1 * i), settings=base.settings).save(
            tmp_path / "designs" / f"cell{i}.json"
        )
        for i in range(4)
    ]
    kw = dict(grid=96, loads=8, progress=False)
    reference = mi.validate_many(paths, tmp_path / "reference", **kw)

    killed: list[int] = []

    def kill_a_busy_worker() -> None:
        with distributed.Client(cluster.address, timeout=30, set_as_default=False) as client:
            pids = client.run(os.getpid)
            deadline = time.monotonic() + 60
            while time.monotonic() < deadline:
                busy = [w for w, keys in client.processing().items() if keys]
                if busy:
                    time.sleep(0.1)  # into the task
                    os.kill(pids[busy[0]], signal.SIGKILL)
                    killed.append(pids[busy[0]])
                    return
                time.sleep(0.01)

    killer = threading.Thread(target=kill_a_busy_worker)
    killer.start()
    try:
        result = mi.validate_many(paths, tmp_path / "sweep", scheduler=cluster.address, **kw)
    finally:
        killer.join()
    assert killed, "no worker was seen working"
    with pytest.raises(ProcessLookupError):
        os.kill(killed[0], 0)  # that worker is gone; its nanny started another

    def solved(summaries):  # all but the wall times
        return {n: {k: v for k, v in s.items() if k != "bem_seconds"} for n, s in summaries.items()}

    assert solved(result) == solved(reference)
    pd.testing.assert_frame_equal(table(tmp_path / "sweep"), table(tmp_path / "reference"))
    # the sweep's client never became Dask's default: the caller's settings are untouched
    assert importlib.import_module("dask").config.get("scheduler", None) is None
