"""Reproduce the paper's figures and tables from the package alone (issue 8).

``reproduce(out_dir)`` runs the stages of ``stages.STAGES`` (fig. 1 and table 1, fig. 3 and
the wall case, fig. 4, fig. 5, fig. 6 and appendix D) with the shipped surrogate and data it
generates itself with fixed seeds, and writes into ``out_dir``: per figure NAME.png, NAME.pdf
and a caption NAME.txt; results.md (every number in tables beside the paper's value) and
results.json (the same numbers, machine-readable, with the settings and provenance).
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from metainterface._files import strict_json
from metainterface._files.atomic import check_output_folder, write_text
from metainterface._files.provenance import provenance
from metainterface.errors import MetainterfaceError
from metainterface.reproduce.scales import PAPER, SCALES, Scale, get_scale

__all__ = ["PAPER", "SCALES", "ReproduceResult", "Scale", "get_scale", "reproduce"]

REFRESH = "metainterface reproduce --out docs/figures --quick"


@dataclass(frozen=True)
class ReproduceResult:
    """What a run wrote: numbers per stage (as in results.json), figure files, stage seconds."""

    out_dir: Path
    scale: Scale
    numbers: dict[str, Any]
    figures: dict[str, dict[str, str]]
    seconds: dict[str, float]

    @property
    def results_md(self) -> Path:
        return self.out_dir / "results.md"


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    return obj


def _command(out_dir: Path, scale: Scale, only: Sequence[str] | None) -> str:
    cmd = f"metainterface reproduce --out {out_dir}"
    if scale.name == "quick":
        cmd += " --quick"
    elif scale.name != "full":
        cmd += f" --scale {scale.name}"
    if only:
        cmd += " --only " + " ".join(only)
    return cmd


def reproduce(
    out_dir: str | os.PathLike[str],
    quick: bool = False,
    progress: bool = True,
    scale: str | Scale | None = None,
    *,
    only: Sequence[str] | None = None,
    model_path: str | os.PathLike[str] | None = None,
    work_dir: str | os.PathLike[str] | None = None,
) -> ReproduceResult:
    """Regenerate the paper's figures and tables into ``out_dir``.

    quick: the reduced scale (``SCALES['quick']``); scale: a scale name or Scale, overriding
    ``quick`` ('tiny' is for tests). only: stage names (fig1, fig3, fig4, fig5, fig6; what they
    need runs too). model_path: surrogate file (default: the shipped one). work_dir: keep the
    intermediate data (datasets, the fig. 4 training run) there and reuse it on a rerun
    (default: a temporary folder, removed at the end). progress: a line per stage on stdout
    and the progress bars of long steps on stderr.
    """
    from metainterface import __version__
    from metainterface.reproduce import context, report, stages
    from metainterface.surrogate.checkpoint import default_model_path

    sc = get_scale(scale, quick)
    names = stages.plan(list(only) if only else None)
    out = check_output_folder(out_dir)
    if work_dir is not None:
        check_output_folder(work_dir)
    model = Path(model_path) if model_path else default_model_path()
    if not model.is_file():
        raise MetainterfaceError(f"model {model}: file not found")
    command = _command(out, sc, only)
    numbers: dict[str, Any] = {}
    seconds: dict[str, float] = {}
    with contextlib.ExitStack() as stack:
        if work_dir is None:
            work = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="reproduce-")))
        else:
            work = Path(work_dir)
            work.mkdir(parents=True, exist_ok=True)
        ctx = context.Context(out, work, sc, model, progress, command)
        started = time.perf_counter()
        for k, name in enumerate(names, 1):
            func, what, _ = stages.STAGES[name]
            if progress:
                print(f"reproduce [{k}/{len(names)}] {name}: {what} ...", flush=True)
            t0 = time.perf_counter()
            numbers[name] = _jsonable(func(ctx))
            seconds[name] = time.perf_counter() - t0
            if progress:
                print(
                    f"reproduce [{k}/{len(names)}] {name}: done in {seconds[name]:.1f} s "
                    f"(total {time.perf_counter() - started:.1f} s)",
                    flush=True,
                )
    record = provenance(
        command=command, scale=sc.to_dict(), model=context.model_label(model), stages=names
    )
    header = {
        "command": command,
        "version": __version__,
        "created": record["created"],
        "refresh": REFRESH,
    }
    descriptions = {s: stages.STAGES[s][1] for s in names}
    text = report.render(numbers, seconds, descriptions, sc, ctx.figures, header)
    write_text(out / "results.md", text)
    payload = {
        "provenance": record,
        "seconds": seconds,
        "numbers": numbers,
        "figures": ctx.figures,
        "paper": {k: {"value": v, "source": s} for k, (v, s) in PAPER.items()},
    }
    write_text(out / "results.json", strict_json.dumps(_jsonable(payload), indent=1) + "\n")
    if progress:
        print(f"reproduce: {len(ctx.figures)} figures and results.md in {out}", file=sys.stdout)
    return ReproduceResult(out, sc, numbers, dict(ctx.figures), seconds)
