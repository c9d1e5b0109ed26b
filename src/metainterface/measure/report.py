"""What a measured part tells its user on screen: the warnings to read before trusting its
figures, the summary report, and the height-unit slip."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from metainterface.measure.predict import DISAGREE, RESOLVED_PIXELS


def measure_warnings(result: Any) -> list[str]:
    """Everything a user should know before trusting a MeasureResult's figures, one line
    each."""
    r, p = result.registration, result.prediction
    sh = p.shapes
    um = 1e6 * result.scan.radius_m
    o = r.orientation
    out = []
    if o.ambiguous:
        out.append(
            f"orientation: {o.describe()} fits only {o.margin:.2g}x better than "
            f"{o.runner_up}: too close to tell apart (the per-asperity figures may "
            "belong to other asperities)"
        )
    if o.unit_slip:
        out.append(height_slip(o.height_scale))
    if sh.terraces is not None:
        t = sh.terraces
        out.append(
            f"terraces: layer steps of {t.step * um:.3g} um "
            f"({'as given' if t.given else 'read from the scan'}); heights restored onto "
            "them before the BEM"
        )
    flat = np.flatnonzero(sh.flat_radius > 0)
    if flat.size:
        radii = ", ".join(f"{k}: {sh.flat_radius[k] * um:.3g}" for k in flat)
        out.append(f"flat tips (radius in um) on asperities {radii}; made flat before the BEM")
    for k, what in enumerate(sh.feature):
        if what:
            out.append(f"asperity {k}: {what} (more than Delta_max/3 from its fitted shape)")
    if sh.smoothed > 0:
        out.append(
            f"scan noise {sh.noise * um:.2g} um: the cell smoothed by a Gaussian of "
            f"{sh.smoothed:.2g} grid steps"
        )
    if p.adhesion > 0:
        out.append(
            "adhesive part: the cell solved in the JKR-limit BEM by approach (its "
            "contacts' resolution by the scan is not estimated)"
        )
    elif p.resolved_from is None:
        out.append("the scan's pixels resolve the contacts at none of the loads")
    elif p.resolved_from > p.p_star[0]:
        out.append(
            f"below P* = {p.resolved_from:.3g} the contacts are narrower than "
            f"{RESOLVED_PIXELS:g} scan pixels: the prediction holds from there on"
        )
    if p.cell.filled > 0:
        out.append(
            f"{100 * p.cell.filled:.2g} % of the cell is not in the scan: filled with the "
            "fitted asperities"
        )
    if np.any(p.disagree):
        out.append(
            "BEM on the measured cell and the fitted model differ by more than "
            f"{100 * DISAGREE:g} % at P* = "
            + ", ".join(f"{v:.3g}" for v in p.p_star[p.disagree])
            + ": the made shapes are not all power laws (the BEM's figure is the one)"
        )
    return out


def measure_report(result: Any, max_error: float | None = None) -> str:
    """The summary a user reads on screen: the made error from BEM with its accuracy,
    the orientation found, the worst asperities in um, every warning, the correction."""
    r, p, d = result.registration, result.prediction, result.design
    um = 1e6 * result.scan.radius_m
    lines = [
        f"scan {result.scan.source}: {result.scan.shape[1]} x {result.scan.shape[0]} points, "
        f"{result.scan.dx * um:.3g} um pixels; {int(r.seen.sum())} asperities fitted",
        f"orientation: {r.orientation.describe()}, rotation "
        f"{math.degrees(r.lattice.theta):.3g} deg (margin {r.orientation.margin:.2g}x over "
        f"{r.orientation.runner_up})",
        f"made error (BEM on the measured cell, {p.grid}^2, {len(p.p_star)} loads): "
        f"{100 * p.error_bem:.3g} % +- {100 * p.error_accuracy:.2g} % (the BEM's own, "
        f"from {p.grid_coarse}^2); fitted model {100 * p.error_fit:.3g} %, design "
        f"{100 * p.error_design:.3g} %",
    ]
    h_design = d.h - d.h.min()
    dev = (r.h - h_design) * um
    worst = np.argsort(-p.share)[:3]
    parts = [
        f"{k} (gamma {d.gamma[k]:.3g} -> {r.gamma[k]:.3g}, h {dev[k]:+.3g} um, "
        f"{100 * p.share[k]:.0f} % of the error)"
        for k in worst
        if p.share[k] > 0
    ]
    if parts:
        lines.append("worst asperities: " + "; ".join(parts))
    lines += [f"warning: {w}" for w in measure_warnings(result)]
    c = result.compensation
    if c is not None:
        if c.printed is None:
            lines.append(
                f"correction: none written; the design printed as it is reads "
                f"{100 * c.error_before:.3g} % (BEM of the predicted made cell)"
            )
        else:
            lines.append(
                f"correction: predicted made error {100 * c.error_before:.3g} % -> "
                f"{100 * c.error_after:.3g} % (BEM of the predicted made cell; the fitted "
                f"family alone would say {100 * c.error_family:.3g} %)"
            )
        lines += [f"correction cannot reach: {t}" for t in c.limits]
    if max_error is not None and p.error_bem > max_error:
        lines.append(
            f"made error {100 * p.error_bem:.3g} % is above --max-error {100 * max_error:.3g} %"
        )
    return "\n".join(lines)


def height_slip(scale: float) -> str:
    """The warning for a scan whose heights are ``scale`` times the design's."""
    factor = 10.0 ** (3 * round(math.log10(scale) / 3))
    return (
        f"the scan's heights are about {scale:.3g} times the design's: a height unit slip? "
        f"(give the unit, e.g. --height-unit {'nm' if factor > 1 else 'mm'} where um was "
        f"read; a factor {factor:g})"
    )
