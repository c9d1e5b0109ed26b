"""Collecting a sweep's results as they arrive: a design's chunks joined, its folder
written under a hidden name and swapped in, and summary.csv / summary.json rewritten."""

from __future__ import annotations

import collections
import csv
import io
import os
import shutil
import uuid
from pathlib import Path
from typing import Any

from metainterface._files import csv_header, provenance, strict_json, write_text
from metainterface.sweep.folders import write_result
from metainterface.validation.bem import LoadPath
from metainterface.validation.validate import ValidationPlan

#: Columns of summary.csv, one row per design.
SUMMARY_COLUMNS = (
    "name",
    "status",
    "max_rel_err_upper_half",
    "target_error_bem",
    "target_error_model",
    "error",
)


def _swap_in(staging: Path, final: Path) -> None:
    """Put a finished folder in place of ``final`` (two renames, no half-written folder)."""
    if final.exists():
        old = final.with_name(f".{final.name}.old-{uuid.uuid4().hex[:8]}")
        os.replace(final, old)
        os.replace(staging, final)
        shutil.rmtree(old, ignore_errors=True)
    else:
        os.replace(staging, final)


def _staging(out: Path, name: str) -> Path:
    return out / f".{name}.partial-{uuid.uuid4().hex[:8]}"


def summary_row(name: str, summary: dict[str, Any]) -> dict[str, Any]:
    """One row of summary.csv: name, status (ok / failed), the largest relative error over
    the upper half of the loads, the target errors (BEM, model; blank without a target),
    the error message of a failed design."""
    if "error" in summary:
        return {"name": name, "status": "failed", "error": summary["error"]}
    return {
        "name": name,
        "status": "ok",
        "max_rel_err_upper_half": summary.get("max_rel_err_upper_half"),
        "target_error_bem": summary.get("target_error_bem"),
        "target_error_model": summary.get("target_error_model"),
    }


def _cell(value: Any) -> Any:
    if value is None:
        return ""
    return repr(float(value)) if isinstance(value, float) else value  # repr: exact floats


def _write_summary(out: Path, rows: list[dict[str, Any]], **settings: Any) -> None:
    buf = io.StringIO()
    buf.write(csv_header(**settings))
    writer = csv.DictWriter(buf, SUMMARY_COLUMNS, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        cells = {k: _cell(v) for k, v in row.items()}
        # '#' starts a comment for pandas.read_csv(comment="#"): keep messages readable there
        cells["error"] = str(cells.get("error", "")).replace("#", "no.").replace("\n", " ")
        writer.writerow(cells)
    write_text(out / "summary.csv", buf.getvalue())


class Collector:
    """The bookkeeping of one sweep: ``on_done`` / ``on_error`` receive each task's load
    path (or failure) by its index in the flat task list; a design whose chunks are all in
    is written whole (``out/<name>/``) and the summary files rewritten.

    items: every (name, design) of the sweep, in order (the summary's order); summaries:
    {name: summary} of the designs already finished (kept from a previous run); todo: the
    plans to solve; owner: the index in ``todo`` of each task; settings: the sweep's
    settings, for the CSV header and the provenance; figures: write validation.png.
    """

    def __init__(
        self,
        out: Path,
        items: list[tuple[str, Any]],
        summaries: dict[str, dict[str, Any]],
        todo: list[ValidationPlan],
        owner: list[int],
        settings: dict[str, Any],
        figures: bool,
    ) -> None:
        self.out, self.items, self.summaries, self.todo = out, items, summaries, todo
        self.owner, self.settings, self.figures = owner, settings, figures
        self.parts: dict[int, dict[int, LoadPath]] = {d: {} for d in range(len(todo))}
        self.failed: set[int] = set()
        self.n_chunks = collections.Counter(owner)
        self.bar: Any = None

    def write_summary(self) -> None:
        """summary.csv and summary.json of the designs finished so far, in the sweep's order."""
        ordered = {n: self.summaries[n] for n, _ in self.items if n in self.summaries}
        rows = [summary_row(n, s) for n, s in ordered.items()]
        _write_summary(self.out, rows, **self.settings)
        record = {"designs": ordered, "provenance": provenance(**self.settings)}
        write_text(self.out / "summary.json", strict_json.dumps(record, indent=2) + "\n")

    def on_done(self, i: int, part: LoadPath) -> None:
        d = self.owner[i]
        if d in self.failed:
            return
        parts = self.parts[d]
        parts[i] = part
        if len(parts) < self.n_chunks[d]:
            return
        prep = self.todo[d]
        path = LoadPath.concat([parts[j] for j in sorted(parts)])
        parts.clear()
        result = prep.result(path)
        staging = _staging(self.out, prep.name)
        write_result(result, staging, figure=self.figures, command="validate_many")
        _swap_in(staging, self.out / prep.name)
        self._finished(prep.name, result.summary())

    def on_error(self, i: int, exc: BaseException) -> None:
        d = self.owner[i]
        if d in self.failed:
            return
        self.failed.add(d)
        self.parts[d].clear()
        prep = self.todo[d]
        staging = _staging(self.out, prep.name)
        write_text(staging / "error.txt", f"{exc}\n")
        _swap_in(staging, self.out / prep.name)
        self._finished(prep.name, {"name": prep.name, "error": str(exc)})

    def _finished(self, name: str, summary: dict[str, Any]) -> None:
        self.summaries[name] = summary
        self.write_summary()
        if self.bar is not None:
            self.bar.update(1)
