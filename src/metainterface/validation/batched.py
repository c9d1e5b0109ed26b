"""Validate many designs as one batch on the torch engine (``torch_bem.solve_paths``): how a
GPU is kept busy by many small designs; a batch that fails is solved again design by design."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from metainterface.errors import MetainterfaceError
from metainterface.validation.bem import LoadPath, PathRecorder, solve_path
from metainterface.validation.validate import ValidationPlan


def solve_batched(
    plans: Sequence[ValidationPlan],
    batch: int,
    *,
    fields: bool = False,
    on_done: Callable[[int, LoadPath], Any],
    on_error: Callable[[int, BaseException], Any],
) -> None:
    """Solve the plans' load paths with the torch engine, up to ``batch`` designs of one grid
    size and load count at a time (``torch_bem.solve_paths``): how a GPU is kept busy by many
    small designs. on_done(i, path) / on_error(i, exc) per plan i, as each batch finishes.
    Every plan must use the torch engine on one device with one tolerance and iteration cap.
    A batch whose solve fails (NaN: a contact of one grid point) is solved again design by
    design, so only the design at fault fails. ``LoadPath.seconds`` is the batch's time per
    load shared equally among its designs.
    """
    groups: dict[tuple[int, int], list[int]] = {}
    for i, plan in enumerate(plans):
        groups.setdefault((plan.grid, len(plan.loads)), []).append(i)
    for members in groups.values():
        for start in range(0, len(members), batch):
            idx = members[start : start + batch]
            _solve_group([plans[i] for i in idx], idx, fields, on_done, on_error)


def _solve_group(
    group: list[ValidationPlan],
    idx: list[int],
    fields: bool,
    on_done: Callable[[int, LoadPath], Any],
    on_error: Callable[[int, BaseException], Any],
) -> None:
    from metainterface._device import resolve_device
    from metainterface.validation import torch_bem

    first = group[0]
    maps = [plan.height_map() for plan in group]
    k = len(first.loads)
    recs = [
        PathRecorder(k, first.grid, hm.owner, plan.design.n_asperities, fields)
        for plan, hm in zip(group, maps, strict=True)
    ]
    failed: dict[int, BaseException] = {}

    def on_load(j: int, pressures, gaps, errors, seconds: float) -> None:
        for b, plan in enumerate(group):
            if b in failed:
                continue
            try:
                torch_bem.check_converged(
                    float(errors[b]), plan.tolerance, plan.max_iter, j, k, plan.loads[j]
                )
            except MetainterfaceError as exc:
                failed[b] = exc
                continue
            recs[b].record(j, pressures[b], gaps[b], float(errors[b]), seconds / len(group))

    try:
        torch_bem.solve_paths(
            np.stack([hm.heights for hm in maps]),
            np.array([hm.cell_side for hm in maps]),
            np.stack([plan.loads for plan in group]),
            device=resolve_device(first.device),
            tolerance=first.tolerance,
            max_iter=first.max_iter,
            on_load=on_load,
        )
    except ArithmeticError:
        for b, plan in enumerate(group):  # one at a time: only the design at fault fails
            try:
                path = solve_path(**plan.task(maps[b]), fields=fields)
            except MetainterfaceError as exc:
                on_error(idx[b], exc)
                continue
            on_done(idx[b], path)
        return
    for b in range(len(group)):
        if b in failed:
            on_error(idx[b], failed[b])
        else:
            on_done(idx[b], recs[b].path())
