"""Helpers of the robustness suite: how a refused case is judged, strict JSON."""

from __future__ import annotations

import json
import os
import signal
from pathlib import Path

import pytest

from metainterface.cli import main

#: Examples per property in the slow variants.
SLOW_EXAMPLES = 200


def snapshot(folder: Path) -> dict[str, tuple[int, int, int]]:
    """Every entry under ``folder`` (links not followed): its type and mode, size, mtime
    (a folder's own mtime left out: its entries are compared one by one)."""
    out = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            p = Path(root) / name
            st = os.lstat(p)
            mtime = 0 if name in dirs else st.st_mtime_ns
            out[str(p.relative_to(folder))] = (st.st_mode, st.st_size if mtime else 0, mtime)
    return out


def run_cli(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, list[str]]:
    """Run the command line in this process: (exit status, stderr lines). argparse's own
    exits are caught; the signal handlers must be as they were."""
    saved = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGHUP)}
    capsys.readouterr()
    if os.environ.get("FUZZ_LOG"):  # which case ran, for a run that hangs or crashes
        with open(os.environ["FUZZ_LOG"], "a", encoding="utf-8") as log:
            log.write(repr(argv) + "\n")
    try:
        rc = main(argv)
    except SystemExit as exc:
        rc = exc.code if isinstance(exc.code, int) else 1
    finally:
        assert {s: signal.getsignal(s) for s in saved} == saved
    err = capsys.readouterr().err
    return rc, [line for line in err.splitlines() if line.strip()]


def assert_refused(
    argv: list[str], field: str, folder: Path, capsys: pytest.CaptureFixture[str]
) -> str:
    """The case exits 2 with ONE stderr line naming ``field`` and changes nothing in
    ``folder``; returns the line."""
    before = snapshot(folder)
    rc, lines = run_cli(argv, capsys)
    after = snapshot(folder)
    assert rc == 2, (argv, rc, lines)
    assert len(lines) == 1, (argv, lines)
    assert field.lower() in lines[0].lower(), (argv, field, lines[0])
    assert "Traceback" not in lines[0]
    assert after == before, (argv, set(after) ^ set(before))
    return lines[0]


def strict_json(path: Path) -> object:
    """Parse JSON refusing NaN and Infinity tokens."""

    def refuse(token: str) -> None:
        raise AssertionError(f"{path}: non-standard JSON token {token}")

    return json.loads(path.read_text(encoding="utf-8"), parse_constant=refuse)
