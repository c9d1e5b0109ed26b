"""An interrupt at any moment of writing a set of files: the set is whole or absent, and no
temporary is left. A helper process writes one three-file set after another while a thread
of its own signals it after a random delay of up to 1.5 ms: the signal lands at every point
of the writes, the renames and the context managers' own code, hundreds of times a run.

The in-process stress sees what a timed signal to ``metainterface design`` sees once in a
while (CI once left a lone ``.curve.csv...tmp`` there, ``test_faults``)."""

from __future__ import annotations

import json
import signal
import subprocess
import sys

import pytest

HELPER = r"""
import json, os, random, signal, sys, tempfile, threading, time
from collections import Counter
from pathlib import Path

from metainterface._files import (
    atomic_path, output_set, terminate_as_interrupt, write_bytes, write_text,
)

sig, runs, seed = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
rng = random.Random(seed)
root = Path(tempfile.mkdtemp())
count = Counter()
go, done, delay = threading.Event(), threading.Event(), [0.0]


def signaller():
    while True:
        go.wait()
        go.clear()
        time.sleep(delay[0])
        os.kill(os.getpid(), sig)
        done.set()


threading.Thread(target=signaller, daemon=True).start()
names = ["curve.csv", "design.json", "design.png"]
with terminate_as_interrupt():
    for i in range(runs):
        folder = root / f"run{i}"
        done.clear()
        delay[0] = rng.uniform(0.0, 0.0015)
        try:
            go.set()  # inside: a signal at once is this run's interrupt too
            with output_set():
                write_text(folder / "curve.csv", "p_star,alpha\n" * 50)
                write_bytes(folder / "design.png", bytes(2000))
                write_text(folder / "design.json", "{}")
            with atomic_path(folder / "field.nc") as tmp:
                tmp.write_bytes(bytes(500))
            while not done.is_set():
                pass
        except KeyboardInterrupt:
            count["interrupted"] += 1
        while True:  # a signal still on its way lands here, not in the next run
            try:
                while not done.is_set():
                    time.sleep(0.0002)
                time.sleep(0.002)
                break
            except KeyboardInterrupt:
                count["interrupted"] += 1
        found = sorted(p.name for p in folder.iterdir()) if folder.exists() else []
        count["temporaries"] += sum(n.endswith(".tmp") for n in found)
        kept = [n for n in found if n in names]
        count["partial sets"] += kept not in ([], names)
print(json.dumps(count))
"""


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_an_interrupt_anywhere_leaves_a_whole_set_or_none(tmp_path, sig):
    script = tmp_path / "stress.py"
    script.write_text(HELPER)
    runs = 600
    out = subprocess.run(
        [sys.executable, str(script), str(int(sig)), str(runs), str(int(sig))],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr[-2000:]
    count = json.loads(out.stdout.strip().splitlines()[-1])
    assert count["interrupted"] == runs  # each run's signal was taken as an interrupt
    assert count.get("temporaries", 0) == 0, count
    assert count.get("partial sets", 0) == 0, count
