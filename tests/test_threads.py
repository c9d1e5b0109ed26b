"""torch's threads as a user meets them: what ``import metainterface`` sets, the count a
library call runs on, and that a user's own choice always wins.

Each scenario runs in a fresh process: the wait policy is read once, when torch loads, and the
thread count is a setting of the whole process. A forward model of the user's own records the
count torch has while ``mi.curve`` runs it.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

import metainterface as mi

SRC = os.path.join(os.path.dirname(__file__), "..", "src")

RECORDER = """
import json, sys, warnings
import metainterface as mi
import torch

seen = []

class Recording(mi.Independent):
    name = "recording"
    def sweep(self, *args, **kwargs):
        seen.append(torch.get_num_threads())
        return super().sweep(*args, **kwargs)

def threads_in_curve():
    seen.clear()
    mi.curve(gamma=[2.0] * 9, h=[0.0] * 9, model=Recording())
    return max(seen)
"""


def _run(body: str, *, first: str = "", env: dict[str, str] | None = None) -> dict:
    base = {
        k: v
        for k, v in os.environ.items()
        if k not in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OMP_WAIT_POLICY")
    }
    code = first + RECORDER + body
    done = subprocess.run(
        [sys.executable, "-c", code],
        env={**base, "PYTHONPATH": SRC, **(env or {})},
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1]) | {"stderr": done.stderr}


def test_defaults_one_thread_in_a_call_passive_waits_and_the_users_choice_wins():
    out = _run(
        """
import os
base = torch.get_num_threads()
policy = os.environ.get("OMP_WAIT_POLICY")
default = threads_in_curve()
after = torch.get_num_threads()
mi.set_threads(2)
chosen = threads_in_curve()
mi.set_threads(None)
torch.set_num_threads(base + 1)      # the user's own torch setting
users = threads_in_curve()
print(json.dumps(dict(policy=policy, default=default, after=after, base=base,
                      chosen=chosen, users=users, end=torch.get_num_threads())))
"""
    )
    assert out["policy"] == "PASSIVE"  # set before torch loaded
    assert out["default"] == 1  # a curve's small kernels run on one thread
    assert out["after"] == out["base"]  # and torch is as it was afterwards
    assert out["chosen"] == 2  # mi.set_threads wins
    assert out["users"] == out["base"] + 1  # torch.set_num_threads wins
    assert out["end"] == out["base"] + 1
    assert "ThreadWarning" not in out["stderr"]


def test_the_environment_wins():
    out = _run(
        """
import os
base = torch.get_num_threads()   # torch's reading of OMP_NUM_THREADS (capped at the cores)
print(json.dumps(dict(policy=os.environ.get("OMP_WAIT_POLICY"), base=base,
                      count=threads_in_curve())))
""",
        env={"OMP_NUM_THREADS": "2", "OMP_WAIT_POLICY": "ACTIVE"},
    )
    assert out["policy"] == "ACTIVE"  # the user's policy is left alone
    assert out["count"] == out["base"]  # and the user's count is used as it is


def test_torch_loaded_first_one_thread_and_a_warning_once_where_threads_would_spin():
    out = _run(
        """
import os
policy = os.environ.get("OMP_WAIT_POLICY")
default = threads_in_curve()
mi.set_threads(2)
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    threads_in_curve()
    threads_in_curve()
print(json.dumps(dict(policy=policy, default=default,
                      warned=[str(w.message) for w in caught
                              if w.category.__name__ == "ThreadWarning"])))
""",
        first="import torch\n",
    )
    assert out["policy"] is None  # too late to take effect: left unset
    assert out["default"] == 1  # one thread never spins
    assert len(out["warned"]) == 1  # said once
    message = out["warned"][0]
    assert "\n" not in message and "OMP_WAIT_POLICY=PASSIVE" in message


@pytest.mark.parametrize("bad", [0, -1, 2.5, "2", True])
def test_set_threads_refuses_bad_counts_in_one_line(bad):
    with pytest.raises(mi.MetainterfaceError, match=r"^threads must be a whole number in"):
        mi.set_threads(bad)


def test_the_cli_takes_threads_and_refuses_a_bad_count(tmp_path):
    env = {**os.environ, "PYTHONPATH": SRC}
    design = os.path.join(SRC, "metainterface", "examples", "example_design.json")
    out = str(tmp_path / "c.csv")
    ok = subprocess.run(
        [sys.executable, "-m", "metainterface", "curve", design, "--threads", "1", "--out", out],
        env=env,
        capture_output=True,
        text=True,
    )
    assert ok.returncode == 0, ok.stderr
    bad = subprocess.run(
        [sys.executable, "-m", "metainterface", "curve", design, "--threads", "0"],
        env=env,
        capture_output=True,
        text=True,
    )
    assert bad.returncode == 2
    assert bad.stderr.strip().count("\n") == 0 and "--threads" in bad.stderr
