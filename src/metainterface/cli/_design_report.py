"""`metainterface design`'s report: the summary table and its BEM legend."""

from __future__ import annotations

import argparse


def table(args: argparse.Namespace, results: list) -> None:
    """The summary table: errors (the one curve error), coverage and carrying asperities."""
    width = max(len("target"), *(len(r.target.name) for r in results)) + 2
    head = (
        f"{'target':<{width}}{'method':<12}{'zero-shot':>11}{'error':>11}{'coverage':>10}"
        f"{'carrying':>10}{'seconds':>9}"
    )
    offset = any(r.f0_error is not None for r in results)
    if offset:  # an offset law: F_0 beside the curve error, part of what a design meets
        head += f"{'F_0':>11}"
    checked = [r for r in results if r.bem is not None]
    if checked:
        head += f"{'BEM':>11}{'+-':>9}{'BEM s':>8}"
    if args.robust:
        head += f"{'made p50':>11}{'made p95':>11}"
    if args.z_step is not None:
        head += f"{'unsnapped':>11}{'snapped':>11}"
    print(head)
    for r in results:
        line = (
            f"{r.target.name:<{width}}{r.method:<12}{100 * r.initial_error:>9.3g} %"
            f"{100 * r.error:>9.3g} %{100 * r.coverage:>8.3g} %"
            f"{f'{r.carrying}/{r.design.n_asperities}':>10}{r.seconds:>9.2f}"
        )
        if offset:
            f0 = "" if r.f0_error is None else f"{100 * r.f0_error:.3g} %"
            line += f"{f0:>11}"
        if r.robust:
            line += f"{100 * r.robust['error_median']:>9.3g} %{100 * r.robust['error_p95']:>9.3g} %"
        if r.printable:
            q = r.printable
            line += f"{100 * q['error_before_snap']:>9.3g} %{100 * q['error_after_snap']:>9.3g} %"
        if r.bem is not None:
            acc = "n/a" if r.bem.accuracy is None else f"{100 * r.bem.accuracy:.2g} %"
            line += f"{100 * r.bem.bem_error:>9.3g} %{acc:>9}{_bem_seconds(r):>8.1f}"
        if r.forced:
            line += "  FORCED (out of reach)"
        if r.f0_met is False:
            line += "  F_0 UNMET"
        print(line)
    if args.robust:
        print("error: the nominal design's; made p50/p95: of cells made with the errors given")
    if args.z_step is not None:
        print(
            "unsnapped/snapped: before the snap to the layer grid and right after it; error: "
            "after the shapes were re-refined"
        )
    print(
        "error: sqrt(fit^2 + (1 - coverage)^2), fit over the loads the design reaches; "
        "coverage: the share of the target's load range it reaches"
    )
    if offset:
        print(
            "F_0: the design's friction at zero load against the law's (off by, relative); "
            "met within 2 %"
        )
    others = [r for r in results if r.zero_shot_from not in ("", "surrogate")]
    if others:  # targets without stiffness: say which reading of the target won
        said = "; ".join(f"{r.target.name}: {r.zero_shot_from}" for r in others)
        print(f"zero-shot read by: {said} (the prediction closest to the target kept)")
    if checked:
        print(_bem_legend(checked))


def _bem_seconds(r) -> float:
    """Wall time of a result's BEM solves [s]: the check, the correction's, and the
    corrected design's check at the held-out loads."""
    seconds = (r.bem_before or r.bem).seconds + sum(c.seconds for c in r.corrections)
    return seconds + (r.bem.seconds if r.bem_before is not None and r.bem.held_out else 0.0)


def _bem_legend(results: list) -> str:
    """What the BEM column is, in one line (with the corrections made)."""
    b = results[0].bem
    grids = f"{b.grid}^2" + ("" if b.coarse_grid is None else f" and {b.coarse_grid}^2")
    line = (
        f"BEM: the design solved in BEM ({b.engine}, {grids}, {b.p_star.size} loads), "
        "its error to the target; +-: the check's own accuracy (the grids' error)"
    )
    fixed = [r for r in results if r.bem_before is not None and r.bem is not r.bem_before]
    for r in fixed:
        steps = ", ".join(
            f"{100 * c.bem_error:.3g} %{'' if c.accepted else ' (not kept)'}" for c in r.corrections
        )
        line += (
            f"; {r.target.name} corrected in BEM: {r.bem_before.error_text()} -> "
            f"(iterations, at the loads they fit: {steps}) {r.bem.error_text()} at "
            f"{r.bem.p_star.size} loads between those"
        )
    return line
