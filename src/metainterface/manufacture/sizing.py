"""Printer sizing: the smallest radius R at which a printer's height error keeps a design's
error within a bound (:func:`min_radius`, :class:`PrinterSizing`)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import torch

from metainterface import _checks
from metainterface._device import resolve_device
from metainterface._threads import uses_threads
from metainterface.designer.results import DesignResult
from metainterface.inverse import scatter as tol
from metainterface.inverse.perturb import Perturbation
from metainterface.inverse.targets import Target
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel
from metainterface.units.quantities import parse_quantity

if TYPE_CHECKING:
    pass

from metainterface.manufacture.tolerance import (
    _NAMES,
    _max_error,
    _pc,
    _prepare,
)


@dataclass(frozen=True, repr=False)
class PrinterSizing:
    """The smallest asperity radius R at which a printer's height error keeps the p95
    relative curve error within a budget.

    printer_sigma_m: the printer's absolute height error (one standard deviation) [m].
    max_error: the budget. sigma_h: the largest height error in units of R that meets it
    (sigma_h = printer_sigma / R). radius_m: the smallest R [m] (inf: no R meets the budget,
    even perfect heights miss it under the other errors; 0: any R does). error_p95: the p95
    error there. cell_side_m, delta_max_m: the cell's side and height range at that R.
    """

    printer_sigma_m: float
    max_error: float
    sigma_h: float
    radius_m: float
    error_p95: float
    cell_side_m: float
    delta_max_m: float
    settings: dict[str, Any]

    @property
    def feasible(self) -> bool:
        """Whether some radius meets the budget."""
        return math.isfinite(self.radius_m)

    def to_dict(self) -> dict[str, Any]:
        return {
            "printer_sigma_m": self.printer_sigma_m,
            "max_error": self.max_error,
            "min_radius_m": self.radius_m if self.feasible else None,
            "sigma_h_over_r": self.sigma_h if math.isfinite(self.sigma_h) else None,
            "error_p95": self.error_p95,
            "cell_side_m": self.cell_side_m if self.feasible else None,
            "delta_max_m": self.delta_max_m if self.feasible else None,
            "settings": self.settings,
        }

    def __repr__(self) -> str:
        if not self.feasible:
            return (
                f"PrinterSizing(no radius meets p95 <= {_pc(self.max_error)}: the other errors "
                f"alone give p95 {_pc(self.error_p95)})"
            )
        return (
            f"PrinterSizing(printer sigma {self.printer_sigma_m * 1e6:.3g} um, p95 <= "
            f"{_pc(self.max_error)}: R >= {self.radius_m * 1e3:.4g} mm (cell side "
            f"{self.cell_side_m * 1e3:.4g} mm, Delta_max {self.delta_max_m * 1e6:.4g} um), "
            f"p95 there {_pc(self.error_p95)})"
        )


@uses_threads()
def min_radius(
    design: Design | DesignResult | str | os.PathLike[str],
    *,
    printer_sigma: str | float,
    max_error: float | str,
    sigma_gamma: float = 0.0,
    scale_sigma: float = 0.0,
    samples: int = 1024,
    seed: int = 0,
    model: str | ForwardModel | None = None,
    target: Target | str | None = None,
    option_names: dict[str, str] | None = None,
    progress: bool = False,
    device: str = "auto",
) -> PrinterSizing:
    """What printer a design needs: the smallest asperity radius R at which a printer's
    absolute height error keeps the p95 relative curve error within ``max_error``.

    The design's heights scale with R and the printer's error does not, so the height
    error in units of R is printer_sigma / R: R is found by bisection on that (the p95
    error grows with it), with the same random draws at every probe.

    Parameters
    ----------
    design : Design, DesignResult or path
        A result of :func:`~metainterface.design` is measured to its own target unless
        ``target`` is given.
    printer_sigma : str or float
        The printer's height error, one standard deviation ('1um', or metres), > 0.
    max_error : float or str
        The p95 error budget: a fraction (0.05) or a percentage ('5%').
    sigma_gamma, scale_sigma, samples, seed, model, target
        As in :func:`tolerance` (fewer samples by default: about 30 probes are run).
    progress : bool
        Show a progress bar of the probes (on stderr, once the search takes over 2 s).
    device : str
        Where the probes run, as in :func:`tolerance`.

    Returns
    -------
    PrinterSizing
        ``radius_m`` (inf when even perfect heights miss the budget) and the p95 there.
    """
    names = {**_NAMES, **(option_names or {})}
    d, fm, samples, seed, ref, _ = _prepare(design, model, samples, seed, target, None, names)
    sigma_m = parse_quantity(printer_sigma, "length", option=names["printer_sigma"])
    budget = _max_error(max_error, names["max_error"])
    s_g = _checks.number(names["sigma_gamma"], sigma_gamma, low=0.0)
    s_s = _checks.number(names["scale_sigma"], scale_sigma, low=0.0, high=0.5)
    dev = resolve_device(device, small=True)
    pert = Perturbation.draw(
        d.n_asperities, samples, seed, sigma_h=0.0, sigma_gamma=s_g, scale_sigma=s_s
    )
    from tqdm.auto import tqdm

    with (
        torch.no_grad(),
        tqdm(
            total=tol.SEARCH_STEPS + 3,
            desc="radius search",
            unit="probe",
            delay=2.0,
            disable=not progress,
        ) as bar,
    ):
        s_h, err = tol.largest_sigma(
            d.gamma,
            d.h,
            d.settings,
            fm,
            pert,
            budget,
            target=None if ref is None else (ref.p_star, ref.alpha),
            iterations=tol.SEARCH_STEPS,
            progress=bar.update,
            device=dev,
        )
    radius_m = math.inf if s_h == 0.0 else sigma_m / s_h  # s_h = inf: any R (0)
    unit = radius_m / d.settings.radius
    return PrinterSizing(
        printer_sigma_m=sigma_m,
        max_error=budget,
        sigma_h=s_h,
        radius_m=radius_m,
        error_p95=err,
        cell_side_m=d.settings.cell_side * unit,
        delta_max_m=d.settings.delta_max * unit,
        settings={
            "sigma_gamma": s_g,
            "scale_sigma": s_s,
            "samples": samples,
            "seed": seed,
            "model": fm.label,
            "reference": "nominal curve" if ref is None else f"target {ref.name}",
        },
    )
