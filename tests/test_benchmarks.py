"""The benchmark suite (benchmarks/run.py): it lists every benchmark script, each has a quick
mode, one quick run is recorded with its command and machine, and every results page names
benchmarks that exist. CI runs every quick mode (``python benchmarks/run.py run --quick``
in .ci/run); here one cheap one runs, to keep the README's test command short."""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
BENCH = ROOT / "benchmarks"
sys.path.insert(0, str(BENCH))
import run as runner  # noqa: E402  (benchmarks/run.py, not a package)


def _scripts() -> set[str]:
    """Every script of benchmarks/ with a main(), found by reading the files here (not by
    the runner's own discovery)."""
    return {
        p.stem
        for p in BENCH.glob("*.py")
        if p.name != "run.py" and re.search(r"^def main\(", p.read_text(), re.M)
    }


def test_runner_lists_every_benchmark_with_a_quick_mode():
    found = runner.discover()
    assert {b.name for b in found} == _scripts()
    assert len(found) >= 30
    for b in found:
        assert b.summary, f"{b.name}: no docstring summary"
    out = subprocess.run(
        [sys.executable, str(BENCH / "run.py"), "list"], capture_output=True, text=True, check=True
    ).stdout
    for name in _scripts():
        assert re.search(rf"^{name}\s", out, re.M), name


def test_a_script_without_quick_is_refused(tmp_path):
    (tmp_path / "bench_x.py").write_text('"""X."""\n\ndef main():\n    pass\n')
    with pytest.raises(ValueError, match=r"bench_x\.py: QUICK"):
        runner.discover(tmp_path)


def test_quick_run_is_recorded_with_command_and_machine(tmp_path):
    out = tmp_path / "runs"
    done = subprocess.run(
        [sys.executable, str(BENCH / "run.py"), "run", "--quick", "bench_lbfgs", "--out", str(out)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    rec = json.loads((out / "bench_lbfgs.json").read_text())
    assert rec["returncode"] == 0 and rec["quick"] is True
    assert rec["command"] == (
        "OMP_NUM_THREADS=1 OMP_WAIT_POLICY=PASSIVE MPLBACKEND=Agg "
        "python benchmarks/bench_lbfgs.py --iterations 10 --repeat 1"
    )
    # what the benchmark printed: its four rows of cost per iteration
    assert rec["stdout"].count("ms/iteration") == 4
    m = rec["machine"]
    assert m["cores"] == os.cpu_count() and m["cpu_model"]
    import torch

    assert m["torch"] == torch.__version__
    assert rec["wall_s"] > 0 and rec["started_utc"].endswith("+00:00")
    # the CPU seconds of the process (it imports torch and runs 40 L-BFGS iterations)
    assert rec["cpu_s"] > 0
    page = runner.page(out)
    assert "## bench_lbfgs" in page and f"`{rec['command']}`" in page


def test_unknown_benchmark_is_one_line_error():
    done = subprocess.run(
        [sys.executable, str(BENCH / "run.py"), "run", "--quick", "bench_nope"],
        capture_output=True,
        text=True,
    )
    assert done.returncode != 0 and "unknown benchmark(s): bench_nope" in done.stderr


def test_results_pages_name_benchmarks_that_exist():
    scripts = _scripts()
    pages = sorted((BENCH / "results").glob("*.md"))
    assert pages
    for page in pages:
        text = page.read_text()
        named = set(re.findall(r"benchmarks/(\w+)\.py", text)) | set(
            re.findall(r"\b(bench_\w+)\.py", text)
        )
        assert named, f"{page.name} names no benchmark command"
        assert named - {"run"} <= scripts, f"{page.name}: {sorted(named - scripts - {'run'})}"


def test_a_benchmark_past_its_timeout_is_killed_and_recorded_as_failed(tmp_path):
    argv = ["run", "--quick", "bench_lbfgs", "--timeout", "0.5", "--out", str(tmp_path)]
    done = subprocess.run(
        [sys.executable, str(BENCH / "run.py"), *argv],
        capture_output=True,
        text=True,
    )
    rec = json.loads((tmp_path / "bench_lbfgs.json").read_text())
    assert done.returncode == 1 and rec["returncode"] is None and rec["cpu_s"] is None
    assert "timed out after 0.5 s" in rec["stderr_tail"] and rec["wall_s"] < 30
