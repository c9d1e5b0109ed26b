"""The benchmark suite's one entry point: list, run and record every benchmark in benchmarks/.

    python benchmarks/run.py list
    python benchmarks/run.py run [NAME ...] [--quick] [--jobs 2] [--out DIR] [-- ARGS ...]
    python benchmarks/run.py page [--runs DIR] [--out FILE.md]

A benchmark is a script ``benchmarks/bench_*.py`` (or ``surrogate_diagnostics.py``) with a
``main()`` and a module-level ``QUICK`` string: the arguments of its quick mode, a run of
seconds that goes through the same code paths on small sizes (what CI runs, to catch a
benchmark that a refactor broke; its figures mean nothing). ``{tmp}`` in ``QUICK`` stands for
a temporary folder of that run's own. ``run`` starts each benchmark
in a fresh process, as its docstring tells a user to (``python benchmarks/NAME.py ARGS``,
with the source tree's ``src`` first on PYTHONPATH), and writes one JSON record per
benchmark to ``--out``: the exact command, its environment variables, exit code, wall time,
everything it printed, the machine (cores, CPU model, load average, torch, numpy and Python
versions) and the source tree's git commit. ``page`` turns the records of a folder into a
Markdown page (one section a benchmark: its command, the machine, what it printed).

Why a small runner rather than pytest-benchmark or asv: the benchmarks are end-to-end
measurements of whole processes (fresh interpreters, subprocesses, BEM worker pools, CPU-
bound neighbours, peak memory, files written) that print tables of accuracy as well as time;
pytest-benchmark times a function repeated in one process, and asv builds an environment per
commit and wants its own benchmark classes. Neither records what these scripts print, and
both would be a new dependency; the runner is ~200 lines of the standard library.
"""

from __future__ import annotations

import argparse
import ast
import datetime as dt
import json
import os
import platform
import shlex
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RUNS = HERE / "results" / "runs"
# Quick runs are smoke runs: one thread each, so two can share the CI's two cores.
QUICK_ENV = {"OMP_NUM_THREADS": "1", "OMP_WAIT_POLICY": "PASSIVE", "MPLBACKEND": "Agg"}


@dataclass(frozen=True)
class Benchmark:
    """One script of benchmarks/: its name (file stem), path, summary and quick arguments."""

    name: str
    path: Path
    summary: str
    quick: tuple[str, ...]


def _literal(tree: ast.Module, name: str) -> object:
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == name for t in node.targets
        ):
            return ast.literal_eval(node.value)
    return None


def discover(folder: Path = HERE) -> list[Benchmark]:
    """Every benchmark script of ``folder``, sorted by name, read without importing it (the
    scripts import torch: listing stays instant). Raises ValueError for a script without
    ``main()`` or without a ``QUICK`` string."""
    found = []
    for path in sorted(folder.glob("*.py")):
        if path.name == "run.py" or path.name.startswith("_"):
            continue
        tree = ast.parse(path.read_text(), filename=str(path))
        if not any(isinstance(n, ast.FunctionDef) and n.name == "main" for n in tree.body):
            continue  # a helper module, not a benchmark
        quick = _literal(tree, "QUICK")
        if not isinstance(quick, str):
            raise ValueError(f"{path.name}: QUICK must be a string (the quick mode's arguments)")
        doc = ast.get_docstring(tree) or ""
        summary = doc.strip().splitlines()[0] if doc.strip() else ""
        found.append(Benchmark(path.stem, path, summary, tuple(shlex.split(quick))))
    return found


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _version(package: str) -> str | None:
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return None


def _git(*args: str) -> str | None:
    try:
        out = subprocess.run(
            ["git", *args], cwd=ROOT, capture_output=True, text=True, timeout=10, check=True
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip()


def machine() -> dict:
    """The facts a timing needs beside it: cores (all, and those this process may use), CPU
    model, load average, and the versions of Python, torch and numpy."""
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None
    return {
        "cores": os.cpu_count(),
        "cores_usable": usable,
        "cpu_model": _cpu_model(),
        "load_average": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
        "platform": platform.platform(),
        "python": platform.python_version(),
        "torch": _version("torch"),
        "numpy": _version("numpy"),
    }


def command(bench: Benchmark, args: list[str], env: dict[str, str]) -> str:
    """The command line as a user types it from the repository's root."""
    prefix = " ".join(f"{k}={shlex.quote(v)}" for k, v in env.items())
    words = ["python", str(bench.path.relative_to(ROOT)), *args]
    return (prefix + " " if prefix else "") + shlex.join(words)


def _spawn(
    argv: list[str], env: dict[str, str], timeout: float
) -> tuple[int | None, str, str, float | None]:
    """Run ``argv`` from the repository's root: (exit code or None when killed at
    ``timeout``, stdout, stderr, CPU seconds of it and its waited-for children)."""
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        proc = subprocess.Popen(argv, cwd=ROOT, env=env, stdout=out, stderr=err, text=True)
        deadline = time.monotonic() + timeout
        code = cpu = None
        while True:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                code = os.waitstatus_to_exitcode(status)
                cpu = usage.ru_utime + usage.ru_stime
                proc.returncode = code  # reaped here: Popen must not wait for it again
                break
            if time.monotonic() > deadline:
                proc.kill()
                proc.wait()
                break
            time.sleep(0.05)
        out.seek(0)
        err.seek(0)
        stdout, stderr = out.read(), err.read()
    if code is None:
        stderr += f"\ntimed out after {timeout:g} s"
    return code, stdout, stderr, cpu


def run_one(bench: Benchmark, args: list[str], quick: bool, out: Path, timeout: float) -> dict:
    """Run one benchmark in a fresh process and write its record to ``out/NAME.json``."""
    env = dict(QUICK_ENV) if quick else {}
    full_env = {**os.environ, **env}
    src = str(ROOT / "src")
    full_env["PYTHONPATH"] = src + os.pathsep + full_env.get("PYTHONPATH", "")
    # the environment's console scripts (`metainterface`) first, as in an activated venv
    bindir = os.path.dirname(sys.executable)
    full_env["PATH"] = bindir + os.pathsep + full_env.get("PATH", "")
    started = dt.datetime.now(dt.UTC).isoformat(timespec="seconds")
    # the source tree as the run starts (a checkout during a long run must not relabel it)
    commit = _git("rev-parse", "HEAD")
    dirty = bool(_git("status", "--porcelain", "--", "src", "benchmarks"))
    t0 = time.perf_counter()
    code, stdout, stderr, cpu = _spawn([sys.executable, str(bench.path), *args], full_env, timeout)
    record = {
        "benchmark": bench.name,
        "summary": bench.summary,
        "command": command(bench, args, env),
        "quick": quick,
        "returncode": code,
        "wall_s": round(time.perf_counter() - t0, 2),
        # user + system seconds of the benchmark and the processes it waited for: what a
        # busy machine changes least (wall time there grows with the load average)
        "cpu_s": None if cpu is None else round(cpu, 2),
        "started_utc": started,
        "machine": machine(),
        "git_commit": commit,
        "git_dirty": dirty,
        "stdout": stdout,
        "stderr_tail": stderr[-4000:],
    }
    out.mkdir(parents=True, exist_ok=True)
    tmp = out / f".{bench.name}.json.tmp"
    tmp.write_text(json.dumps(record, indent=1) + "\n")
    tmp.replace(out / f"{bench.name}.json")  # no half-written record
    return record


def select(names: list[str], benches: list[Benchmark]) -> list[Benchmark]:
    """The benchmarks named (file stems, with or without ``.py``), or all of them."""
    if not names:
        return benches
    by_name = {b.name: b for b in benches}
    unknown = [n for n in names if n.removesuffix(".py") not in by_name]
    if unknown:
        raise SystemExit(f"unknown benchmark(s): {', '.join(unknown)} (see: run.py list)")
    return [by_name[n.removesuffix(".py")] for n in names]


def page(runs: Path) -> str:
    """A Markdown page of every record in ``runs``: per benchmark its command, machine, wall
    time, exit code and everything it printed."""
    records = [json.loads(p.read_text()) for p in sorted(runs.glob("*.json"))]
    lines = ["# Benchmark runs", "", f"Generated by `python benchmarks/run.py page --runs {runs}`"]
    lines.append("from the records `python benchmarks/run.py run` wrote there.")
    for rec in records:
        m = rec["machine"]
        status = "ok" if rec["returncode"] == 0 else f"FAILED (exit {rec['returncode']})"
        lines += [
            "",
            f"## {rec['benchmark']}",
            "",
            rec["summary"],
            "",
            f"Command: `{rec['command']}`  ",
            f"Run {rec['started_utc']}, {rec['wall_s']} s ({rec.get('cpu_s')} s CPU), {status}, "
            "commit "
            f"{(rec['git_commit'] or '?')[:10]}{' (modified)' if rec['git_dirty'] else ''}  ",
            f"Machine: {m['cores']} cores ({m['cores_usable']} usable), {m['cpu_model']}, "
            f"load {', '.join(f'{x:.1f}' for x in m['load_average'] or [])}; "
            f"Python {m['python']}, torch {m['torch']}, numpy {m['numpy']}",
            "",
            "```text",
            rec["stdout"].rstrip(),
            "```",
        ]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="action", required=True)
    sub.add_parser("list", help="every benchmark, its summary and quick arguments")
    run = sub.add_parser("run", help="run benchmarks and record them (JSON)")
    run.add_argument("names", nargs="*", help="benchmarks to run (default: all)")
    run.add_argument("--quick", action="store_true", help="each benchmark's quick mode")
    run.add_argument("--jobs", type=int, default=1, help="benchmarks at once (default 1)")
    run.add_argument("--timeout", type=float, default=None, help="seconds a benchmark may run")
    run.add_argument("--out", type=Path, help="record folder (default results/runs, or a temp)")
    pg = sub.add_parser("page", help="a Markdown page of the records in a folder")
    pg.add_argument("--runs", type=Path, default=RUNS)
    pg.add_argument("--out", type=Path, help="write it here (default: print it)")
    argv = sys.argv[1:] if argv is None else argv
    extra: list[str] = []
    if "--" in argv:  # the arguments after "--" go to the benchmark(s)
        extra, argv = argv[argv.index("--") + 1 :], argv[: argv.index("--")]
    opts = ap.parse_args(argv)
    benches = discover()
    if opts.action == "list":
        for b in benches:
            print(f"{b.name:32s} {b.summary}")
            print(f"{'':32s} quick: {shlex.join(b.quick) or '(no arguments)'}")
        return 0
    if opts.action == "page":
        text = page(opts.runs)
        if opts.out:
            opts.out.write_text(text)
        else:
            print(text, end="")
        return 0
    chosen = select(opts.names, benches)
    out = opts.out or (
        Path(tempfile.gettempdir()) / "metainterface-bench-quick" if opts.quick else RUNS
    )
    timeout = opts.timeout or (300.0 if opts.quick else 24 * 3600.0)

    def one(bench: Benchmark) -> dict:
        args = [*bench.quick, *extra] if opts.quick else list(extra)
        with tempfile.TemporaryDirectory(prefix=f"{bench.name}-") as tmp:
            # {tmp} in QUICK: a folder of the run's own (outputs a quick run must not leave)
            args = [a.replace("{tmp}", tmp) for a in args]
            rec = run_one(bench, args, opts.quick, out, timeout)
        ok = "ok" if rec["returncode"] == 0 else f"FAILED (exit {rec['returncode']})"
        cpu = "" if rec["cpu_s"] is None else f" ({rec['cpu_s']:.1f} s CPU)"
        print(f"{bench.name:32s} {rec['wall_s']:7.1f} s{cpu}  {ok}", flush=True)
        return rec

    t0 = time.perf_counter()
    with ThreadPoolExecutor(max(1, opts.jobs)) as pool:
        records = list(pool.map(one, chosen))
    failed = [r for r in records if r["returncode"] != 0]
    cpu = sum(r["cpu_s"] or 0.0 for r in records)
    print(
        f"{len(records)} benchmarks in {time.perf_counter() - t0:.0f} s ({cpu:.0f} s CPU), "
        f"records in {out}"
    )
    for rec in failed:
        print(f"\n--- {rec['benchmark']} failed: {rec['command']}\n{rec['stderr_tail']}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
