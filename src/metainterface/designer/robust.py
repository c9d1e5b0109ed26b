"""A design made for a printer: the robust design's error statistics and the printable
heights' record, checked from the options of :func:`~metainterface.design`."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from metainterface import _checks
from metainterface.designer.results import DesignResult
from metainterface.errors import MetainterfaceError
from metainterface.inverse.perturb import Perturbation
from metainterface.physics.cell import CellSettings
from metainterface.units.printer import layer_step, length_in_r
from metainterface.units.quantities import (
    parse_length,
)

#: Made cells drawn to report a robust design's error distribution (independent of the
#: K copies it was refined against).
ROBUST_REPORT_SAMPLES = 1024
MAX_ROBUST_SAMPLES = 1024


def _manufacturing(
    robust: Any,
    sigma_h: Any,
    sigma_gamma: Any,
    scale_sigma: Any,
    robust_samples: Any,
    z_step: Any,
    radius: Any,
    settings: CellSettings | None,
    seed: int,
) -> tuple[Perturbation | None, float | None, float | None]:
    """The perturbation of a robust design and the layer step [units of R], checked."""
    if not isinstance(robust, bool):
        raise MetainterfaceError(f"robust must be True or False, got {robust!r}")
    radius_m = None if radius is None else parse_length(radius, option="radius")
    cell = settings or CellSettings()
    step = None if z_step is None else layer_step(z_step, radius_m, cell.delta_max)
    if not robust:
        if any(v not in (0, 0.0) for v in (sigma_h, sigma_gamma, scale_sigma)):
            raise MetainterfaceError("sigma_h, sigma_gamma and scale_sigma need robust=True")
        return None, step, radius_m
    s_h = length_in_r(sigma_h, radius_m, option="sigma_h", radius_option="radius")
    s_g = _checks.number("sigma_gamma", sigma_gamma, low=0.0)
    s_s = _checks.number("scale_sigma", scale_sigma, low=0.0, high=0.5)
    if s_h == s_g == s_s == 0.0:
        raise MetainterfaceError("robust=True needs sigma_h, sigma_gamma or scale_sigma > 0")
    k = _checks.whole("robust_samples", robust_samples, low=1, high=MAX_ROBUST_SAMPLES)
    perturb = Perturbation.draw(
        cell.n_asperities, k, seed, sigma_h=s_h, sigma_gamma=s_g, scale_sigma=s_s
    )
    return perturb, step, radius_m


def _robust_stats(
    r: DesignResult, perturb: Perturbation, seed: int, device: Any = None
) -> DesignResult:
    """The result with ``robust``: its nominal error and the distribution of the error of
    made cells (independent draws), beside the rms error it was refined against."""
    from metainterface.inverse.scatter import spread

    d = r.design
    check = Perturbation.draw(
        d.n_asperities,
        ROBUST_REPORT_SAMPLES,
        seed + 1,
        sigma_h=perturb.sigma_h,
        sigma_gamma=perturb.sigma_gamma,
        scale_sigma=perturb.scale_sigma,
    )
    s = spread(
        d.gamma,
        d.h,
        d.settings,
        r.model,
        check,
        target=(r.target.p_star, r.target.alpha),
        linear=False,
        device=device,
    )
    stats = {
        "sigma_h": perturb.sigma_h,
        "sigma_gamma": perturb.sigma_gamma,
        "scale_sigma": perturb.scale_sigma,
        "robust_samples": perturb.samples,
        "error_nominal": r.error,
        "error_rms_refined": r.robust_error_refined,
        "error_median": float(np.median(s.errors)),
        "error_p95": float(np.quantile(s.errors, 0.95)),
        "check_samples": ROBUST_REPORT_SAMPLES,
        "check_seed": seed + 1,
    }
    return replace(r, robust=stats)


def _printable_record(r: DesignResult, radius_m: float | None) -> DesignResult:
    q = dict(r.printable or {})
    if radius_m is not None:
        q["z_step_m"] = q["z_step"] * radius_m
    q["z_step_units"] = "R"
    return replace(r, printable=q)
