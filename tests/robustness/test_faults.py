"""Faults: commands killed (SIGKILL) or interrupted (SIGINT, SIGTERM) at random moments.

After any of them: no file half-written under its final name, no temporary left once a later
run writes there, a training run resumes losing at most the epoch in progress, and no worker
process outlives its parent. Moments are drawn from a seeded generator (reproducible); the
tests marked slow draw many more.
"""

from __future__ import annotations

import csv
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import torch

import metainterface as mi
from metainterface.data import load_dataset

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="uses /proc")


def start(*args: str) -> subprocess.Popen:
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    return subprocess.Popen(
        [sys.executable, "-m", "metainterface", *args],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        env=env,
        text=True,
    )


def wait_until(condition, timeout: float = 60.0, step: float = 0.05) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(step)
    return False


def children(pid: int) -> set[int]:
    """Every live descendant of ``pid`` (from /proc)."""
    parents: dict[int, int] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2 :].split()
        if fields[0] != "Z":  # zombies are dead already
            parents[int(entry.name)] = int(fields[1])
    found, frontier = set(), {pid}
    while frontier:
        frontier = {c for c, p in parents.items() if p in frontier} - found
        found |= frontier
    return found


def temporaries(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if ".mi-" in p.name]


def catches(pid: int, sig: int) -> bool:
    """Whether process ``pid`` has a handler installed for ``sig`` (its SigCgt in /proc)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    caught = next(line for line in status.splitlines() if line.startswith("SigCgt:"))
    return bool(int(caught.split()[1], 16) >> (sig - 1) & 1)


def metrics_rows(run: Path) -> int:
    try:
        with open(run / "metrics.csv", encoding="utf-8") as fh:
            return sum(1 for row in csv.reader(fh) if row and row[0][0].isdigit())
    except FileNotFoundError:
        return 0


@pytest.fixture(scope="module")
def dataset(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("data") / "d.npz"
    mi.generate_dataset(400, path, seed=1, progress=False)
    return path


def _generate_killed(tmp_path: Path, sig: int, delay: float, writing: bool = False) -> None:
    """Signal a generation ``delay`` s after its start, or with ``writing`` that long after
    its temporary file appeared (the generation under way, whatever the machine's speed)."""
    out = tmp_path / "g" / "data.npz"
    proc = start("generate", "--samples", "400000", "--seed", "0", "--out", str(out), "--quiet")
    if writing:
        assert wait_until(lambda: temporaries(tmp_path) or proc.poll() is not None)
    time.sleep(delay)
    proc.send_signal(sig)
    rc = proc.wait(60)
    if out.exists():  # the run got past its final rename before the signal: a whole file
        assert len(load_dataset(out)) == 400_000
    if rc == 0:
        return
    if sig in (signal.SIGINT, signal.SIGTERM):  # -sig: signalled before Python was up
        assert rc in (130, -sig) and not temporaries(tmp_path)
    else:
        assert rc == -signal.SIGKILL
    # the next write in that folder removes what a killed run left
    mi.generate_dataset(5, out.parent / "small.npz", progress=False)
    assert not temporaries(tmp_path)


def test_generate_killed_or_interrupted(tmp_path):
    rng = random.Random(21)
    # inside the generation of 400,000 cells (tens of s): up to 1 s after its temporary file
    # appeared (about 1.5 s from the start, past the imports), rather than 2-4 s from the
    # start, most of which was a wait for the imports
    _generate_killed(tmp_path / "kill", signal.SIGKILL, rng.uniform(0.0, 1.0), writing=True)
    _generate_killed(tmp_path / "int", signal.SIGINT, rng.uniform(0.0, 1.0), writing=True)


def _train_killed(dataset: Path, run: Path, rng: random.Random) -> None:
    common = ["train", "--dataset", str(dataset), "--out", str(run), "--epochs", "12"]
    common += ["--batch-size", "32", "--patience", "12"]
    proc = start(*common)
    assert wait_until(lambda: metrics_rows(run) >= 2 or proc.poll() is not None)
    time.sleep(rng.uniform(0.0, 0.5))
    seen = metrics_rows(run)
    proc.kill()
    proc.wait(30)
    # the epoch's files go out together, renamed back to back checkpoint first: they agree,
    # or (a kill between the two renames, microseconds) metrics.csv is one epoch behind the
    # checkpoint, which holds the history and rewrites it on --resume
    state = torch.load(run / "checkpoint.pt", weights_only=True)
    kept = metrics_rows(run)
    assert kept >= seen  # nothing seen done was lost
    assert state["epoch"] - kept in (0, 1) and len(state["history"]) == state["epoch"]
    resumed = subprocess.run(
        [sys.executable, "-m", "metainterface", *common, "--resume"],
        capture_output=True,
        text=True,
        env={**os.environ, "OMP_NUM_THREADS": "1"},
        timeout=120,
    )
    assert resumed.returncode == 0, resumed.stderr
    assert metrics_rows(run) == 12
    assert not temporaries(run)


@pytest.mark.long
def test_train_killed_resumes_losing_at_most_the_epoch_in_progress(dataset, tmp_path):
    _train_killed(dataset, tmp_path / "run", random.Random(7))


def test_validate_workers_die_with_their_parent(tmp_path):
    pytest.importorskip("tamaas")
    design = tmp_path / "design.json"
    mi.Design(gamma=[2.0, 2.5, 3.0, 3.5], h=[0.0, 0.002, 0.004, 0.008]).save(design)
    proc = start(
        "validate",
        str(design),
        "--grid",
        "256",
        "--loads",
        "40",
        "--jobs",
        "2",
        "--out",
        str(tmp_path / "v"),
    )
    assert wait_until(lambda: len(children(proc.pid)) >= 2 or proc.poll() is not None)
    workers = children(proc.pid)
    assert len(workers) >= 2, "validate --jobs 2 started no workers"
    proc.kill()
    proc.wait(30)
    assert wait_until(lambda: not any(_alive(w) for w in workers), timeout=10), (
        "workers outlived their parent"
    )
    assert not (tmp_path / "v").exists()


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat[stat.rindex(")") + 2] != "Z"


@pytest.mark.parametrize(
    "sig", [signal.SIGTERM, pytest.param(signal.SIGINT, marks=pytest.mark.slow)]
)
def test_design_interrupted_writes_all_or_nothing(tmp_path, sig):
    out = tmp_path / "d"
    proc = start("design", "--target", "bilinear", "--out", str(out), "--no-verify")
    # once the command turns SIGTERM into an interrupt (its run under way: before it the
    # signal kills with the default action, not the command's), then a moment in the next
    # 1.5 s: the run's imports, design and writing take about 1.7 s here. A fixed 2-6 s from
    # the start fell after the end of the run: only the finished run's files were checked.
    assert wait_until(lambda: catches(proc.pid, signal.SIGTERM) or proc.poll() is not None)
    time.sleep(random.Random(int(sig)).uniform(0.0, 1.5))
    proc.send_signal(sig)
    rc = proc.wait(120)
    names = sorted(p.name for p in out.iterdir()) if out.exists() else []
    assert names in ([], ["curve.csv", "design.json", "design.png"]), names
    if names:  # the run finished first: a signal during the interpreter's shutdown, after
        # the files were whole, ends it with the default action (a loaded machine's timing);
        # one during the set's renames is held back and raised after them (130)
        assert rc in (0, -sig, 130), rc
    elif rc != 0:
        assert rc == 130
        assert proc.stderr.read().strip().endswith("interrupted")
    assert not temporaries(tmp_path)


@pytest.mark.slow
def test_train_killed_many_times(dataset, tmp_path):
    rng = random.Random(2026)
    for i in range(6):
        _train_killed(dataset, tmp_path / f"run{i}", rng)


@pytest.mark.slow
def test_generate_killed_many_times(tmp_path):
    rng = random.Random(5)
    for i in range(6):
        sig = rng.choice([signal.SIGKILL, signal.SIGINT, signal.SIGTERM])
        _generate_killed(tmp_path / str(i), sig, rng.uniform(0.5, 8.0))
