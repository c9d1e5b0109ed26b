"""How a design degrades when it is made: tolerance analysis and printer sizing.

``tolerance`` samples manufacturing errors (every asperity's height and shape, and a common
scale of the relief) and reports the band of alpha(P*) and the distribution of the relative
curve error, beside the first-order (Jacobian) estimate of both. ``min_radius`` finds the
smallest asperity radius R at which a printer's absolute height error keeps the p95 error
within a budget (the design's heights scale with R, the printer's error does not).
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from metainterface import _checks
from metainterface._device import resolve_device
from metainterface._files import provenance, strict_json, write_columns, write_text
from metainterface._threads import uses_threads
from metainterface.designer.curve_result import ReachCounts, shown
from metainterface.designer.given import design_model
from metainterface.designer.results import DesignResult
from metainterface.errors import MetainterfaceError
from metainterface.inverse import scatter as tol
from metainterface.inverse.perturb import GAMMA_FLOOR, Perturbation
from metainterface.inverse.targets import Target
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel
from metainterface.units.plausible import warn_unit_slips
from metainterface.units.printer import length_in_r
from metainterface.units.quantities import parse_pressure, parse_quantity
from metainterface.units.recorded import recorded

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: Samples of a tolerance analysis: at least enough for a p95, at most what fits in memory.
MIN_SAMPLES, MAX_SAMPLES = 16, 262_144
#: Columns of band.csv, in order.
BAND_COLUMNS = ("p_star", "alpha_nominal", "alpha_p05", "alpha_p50", "alpha_p95")


def _radius(radius: Any, design: Design, option: str) -> float | None:
    """R [m] from the argument, else from the design file's physical or friction record."""
    if radius is not None:
        return parse_quantity(radius, "length", option=option)
    return recorded(design, "radius_m")


def _stress(value: Any, design: Design, keys: tuple[str, ...], option: str) -> float | None:
    if value is not None:
        return parse_pressure(value, option=option)
    return recorded(design, *keys)


def _reference(design: Design, target: Target | str | None) -> Target | None:
    """The target the errors are measured to: the given one, the one the design file
    carries (when ``target`` is None), or none (``"nominal"``: the design's own curve)."""
    if target == "nominal":
        return None
    if isinstance(target, Target):
        return target
    if isinstance(target, str):
        return Target.builtin(target)
    if target is not None:
        raise MetainterfaceError(
            f"target must be a Target, a built-in name or 'nominal', got {type(target).__name__}"
        )
    rec = design.extras.get("target")
    if isinstance(rec, dict) and "p_star" in rec and "alpha" in rec:
        return Target(
            p_star=rec["p_star"], alpha=rec["alpha"], name=str(rec.get("name") or "target")
        )
    return None


def _max_error(value: Any, option: str = "max_error") -> float:
    """A relative error budget: a fraction (0.05) or a percentage ('5%'), in (0, 10]."""
    if isinstance(value, str):
        text = value.strip()
        try:
            value = float(text[:-1]) / 100.0 if text.endswith("%") else float(text)
        except ValueError:
            raise MetainterfaceError(
                f"{option} expects a fraction (0.05) or a percentage (5%), got {text!r}"
            ) from None
    return _checks.number(option, value, low=0.0, high=10.0, low_open=True)


@dataclass(frozen=True)
class Settings:
    """What a tolerance analysis was asked (recorded in tolerance.json)."""

    sigma_h: float
    sigma_gamma: float
    scale_sigma: float
    samples: int
    seed: int
    model: str
    radius_m: float | None
    reference: str
    gamma_floor: float = GAMMA_FLOOR

    def to_dict(self) -> dict[str, Any]:
        out = dict(self.__dict__)
        out["sigma_h_units"] = "R"
        if self.radius_m is not None:
            out["sigma_h_m"] = self.sigma_h * self.radius_m
        out["gamma_clipping"] = f"sampled gamma below {self.gamma_floor} set to it"
        return out


@dataclass(frozen=True, repr=False)
class ToleranceResult(ReachCounts):
    """The spread of a design's curve under manufacturing errors (numpy, float64).

    p_star (M,): uniform pressures on [0, P*_max] of the nominal design. alpha_nominal,
    alpha_p05, alpha_p50, alpha_p95 (M,): the nominal curve and the 5/50/95 % band of the
    made cells. errors (S,): each made cell's relative curve error (the measure ``design``
    reports) to the reference; error_median, error_p95 its quantiles; error_nominal the
    design's own. alpha_sd_linear (M,), alpha_p05_linear, alpha_p95_linear: the first-order
    estimate of the band (nominal +- 1.645 sd); error_median_linear, error_p95_linear: of
    the errors (the linearised curve under the same normals), error_rms_linear (closed
    form). gamma, h (S, N): the sampled cells [h in units of R, not anchored]; alpha
    (S, M) their curves. clipped: fraction of sampled gammas clipped to GAMMA_FLOOR.
    settings: the request; reference: the target (None: the nominal curve).
    shear_strength, modulus [Pa]: for the friction-law band, when known.
    """

    p_star: np.ndarray
    alpha_nominal: np.ndarray
    alpha_p05: np.ndarray
    alpha_p50: np.ndarray
    alpha_p95: np.ndarray
    errors: np.ndarray
    error_median: float
    error_p95: float
    error_nominal: float
    alpha_sd_linear: np.ndarray
    alpha_p05_linear: np.ndarray
    alpha_p95_linear: np.ndarray
    error_median_linear: float
    error_p95_linear: float
    error_rms_linear: float
    gamma: np.ndarray
    h: np.ndarray
    alpha: np.ndarray
    clipped: float
    settings: Settings
    design: Design
    reference: Target | None = None
    shear_strength: float | None = None
    modulus: float | None = None
    seconds: float = 0.0
    printer: dict[str, Any] | None = field(default=None)
    forward_model: ForwardModel | None = None

    def _reach_of(self) -> tuple[ForwardModel | None, tuple[np.ndarray, np.ndarray] | None]:
        ref = self.reference
        return self.forward_model, None if ref is None else (ref.p_star, ref.alpha)

    def band(self) -> dict[str, np.ndarray]:
        """The columns of band.csv."""
        return {name: getattr(self, name) for name in BAND_COLUMNS}

    def summary(self) -> dict[str, Any]:
        """The JSON-ready record of tolerance.json."""
        out: dict[str, Any] = {
            "error_median": self.error_median,
            "error_p95": self.error_p95,
            "error_nominal": self.error_nominal,
            "error_mean": float(np.mean(self.errors)),
            "error_definition": "sqrt(fit^2 + (1 - coverage)^2)",
            "coverage": self.coverage,
            "idle_asperities": list(self.idle),
            "carrying_asperities": self.carrying,
            "first_order": {
                "error_median": self.error_median_linear,
                "error_p95": self.error_p95_linear,
                "error_rms": self.error_rms_linear,
                "band_halfwidth_max": float(np.max(tol.Z95 * self.alpha_sd_linear)),
            },
            "band_halfwidth_max": float(np.max(self.alpha_p95 - self.alpha_p05) / 2),
            "reference": self.settings.reference,
            "clipped_gamma_fraction": self.clipped,
            "settings": self.settings.to_dict(),
            "seconds": self.seconds,
        }
        if self.printer is not None:
            out["printer"] = self.printer
        return out

    def plot(self) -> Figure:
        """The band against the reference, the error distribution and, with a shear
        strength and a modulus, the friction-law band."""
        from metainterface.plots.tolerance import plot_tolerance

        return shown(plot_tolerance(self))

    def save(self, folder: str | os.PathLike[str], **extra: Any) -> Path:
        """Write band.csv, tolerance.json and tolerance.png into ``folder``; returns it.

        band.csv's comment line leaves out the creation time (the same seed gives the same
        bytes); tolerance.json records it. ``extra`` keys go into tolerance.json."""
        from metainterface.plots import save_figure

        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        record = self.settings.to_dict()
        write_columns(folder / "band.csv", self.band(), stamp=False, command="tolerance", **record)
        data = {**self.summary(), **extra, "provenance": provenance(command="tolerance", **record)}
        write_text(folder / "tolerance.json", strict_json.dumps(data, indent=2, default=str) + "\n")
        save_figure(self.plot(), folder / "tolerance.png", command="tolerance", **record)
        return folder

    def __repr__(self) -> str:
        s = self.settings
        sig = f"sigma_h={s.sigma_h:.3g} R" + (
            f" ({s.sigma_h * s.radius_m * 1e6:.3g} um)" if s.radius_m else ""
        )
        return (
            f"ToleranceResult({s.samples} samples, {sig}, sigma_gamma={s.sigma_gamma:g}, "
            f"scale_sigma={s.scale_sigma:g}, {s.model}; error to {s.reference}: "
            f"nominal {_pc(self.error_nominal)} (coverage {_pc(self.coverage)}, carrying "
            f"{self.carrying} of {self.design.n_asperities}), median {_pc(self.error_median)}, "
            f"p95 {_pc(self.error_p95)} (first order: median {_pc(self.error_median_linear)}, "
            f"p95 {_pc(self.error_p95_linear)}))"
        )


def _pc(x: float) -> str:
    return f"{100 * x:.3g} %"


def _prepare(design, model, samples, seed, target, radius, option_names):
    from metainterface.designer.given import as_design

    if isinstance(design, DesignResult):  # a result knows its target: measure to it
        if target is None:
            target = design.target
        design = design.design
    d = as_design(design, None, None, None)
    samples = _checks.whole(option_names["samples"], samples, low=MIN_SAMPLES, high=MAX_SAMPLES)
    seed = _checks.whole(option_names["seed"], seed, low=0, high=2**63 - 1)
    fm = design_model(d, model)  # a design file's own model (its adhesion) by default
    ref = _reference(d, target)
    r_m = _radius(radius, d, option_names["radius"])
    return d, fm, samples, seed, ref, r_m


_NAMES = {
    "sigma_h": "sigma_h",
    "sigma_gamma": "sigma_gamma",
    "scale_sigma": "scale_sigma",
    "samples": "samples",
    "seed": "seed",
    "radius": "radius",
    "shear_strength": "shear_strength",
    "modulus": "modulus",
    "printer_sigma": "printer_sigma",
    "max_error": "max_error",
}


@uses_threads()
def tolerance(
    design: Design | DesignResult | str | os.PathLike[str],
    *,
    sigma_h: float | str = 0.0,
    sigma_gamma: float = 0.0,
    samples: int = 4096,
    seed: int = 0,
    model: str | ForwardModel | None = None,
    radius: str | float | None = None,
    scale_sigma: float = 0.0,
    target: Target | str | None = None,
    shear_strength: str | float | None = None,
    modulus: str | float | None = None,
    out: str | os.PathLike[str] | None = None,
    option_names: dict[str, str] | None = None,
    device: str = "auto",
) -> ToleranceResult:
    """The spread of a design's alpha(P*) and of its error under manufacturing errors.

    Every asperity's height offset and shape exponent get independent Gaussian errors,
    and the height offsets a common relative scale error; all ``samples`` made cells go
    through the batched forward model in one call. Sampled gammas below 1.01 are clipped
    to 1.01 (a shape exponent must stay > 1; ``result.clipped`` says how often).

    Parameters
    ----------
    design : Design, DesignResult or path
        A result of :func:`~metainterface.design` is measured to its own target unless
        ``target`` is given.
    sigma_h : float or str
        Standard deviation of each height offset. A plain number is in units of R (the
        paper's Delta_max is 0.02 R); a length with a unit ('1um') needs ``radius``.
    sigma_gamma : float
        Standard deviation of each shape exponent (absolute, dimensionless), >= 0.
    samples : int
        Made cells sampled, in [16, 262144].
    seed : int
        Seed of the draws; the same seed gives the same samples and files.
    model : str or ForwardModel
        The forward model (default: the one a design file recorded, adhesion included,
        else ``"independent"``).
    radius : str or float
        Asperity radius R ('0.5mm', or metres); default the design file's physical block.
    scale_sigma : float
        Relative standard deviation of a common scale of all height offsets (a z-axis
        calibration error, shrinkage of the relief), in [0, 0.5].
    target : Target, str or None
        What the error is measured to: None, the target of a DesignResult or the one the
        design file carries (else the design's own nominal curve); ``"nominal"``, the
        nominal curve; or a Target / built-in name.
    shear_strength, modulus : str or float
        Interface shear strength tau and modulus E* ('0.25MPa', '2MPa'), for the
        friction-law band of the figure; default the design file's friction record.
    out : path
        Write band.csv, tolerance.json and tolerance.png into this folder.
    option_names : dict
        The names bad-input errors give the options (the CLI passes its ``--options``).
    device : str
        Where the made cells are evaluated: ``"auto"`` (CUDA when torch sees it), ``"cpu"``,
        ``"cuda"`` or ``"cuda:N"``. The draws are made on the CPU: a seed gives the same
        made cells on every device.

    Returns
    -------
    ToleranceResult
        Numpy band and errors, the first-order estimates, ``.plot()`` and ``.save(dir)``.
    """
    names = {**_NAMES, **(option_names or {})}
    d, fm, samples, seed, ref, r_m = _prepare(design, model, samples, seed, target, radius, names)
    s_h = length_in_r(sigma_h, r_m, option=names["sigma_h"], radius_option=names["radius"])
    s_g = _checks.number(names["sigma_gamma"], sigma_gamma, low=0.0)
    s_s = _checks.number(names["scale_sigma"], scale_sigma, low=0.0, high=0.5)
    tau = _stress(shear_strength, d, ("shear_strength_pa",), names["shear_strength"])
    e_star = _stress(modulus, d, ("e_star_pa",), names["modulus"])
    if (radius, modulus, shear_strength) != (None, None, None):  # the user's scale: slips?
        warn_unit_slips(modulus=e_star, shear_strength=tau, radius=r_m)
    dev = resolve_device(device)
    t0 = time.perf_counter()
    pert = Perturbation.draw(
        d.n_asperities, samples, seed, sigma_h=s_h, sigma_gamma=s_g, scale_sigma=s_s
    )
    sp = tol.spread(
        d.gamma,
        d.h,
        d.settings,
        fm,
        pert,
        target=None if ref is None else (ref.p_star, ref.alpha),
        device=dev,
    )
    lo, mid, hi = np.quantile(sp.alpha, [0.05, 0.5, 0.95], axis=0)
    half = tol.Z95 * sp.linear_sd
    result = ToleranceResult(
        p_star=sp.p_star,
        alpha_nominal=sp.alpha_nominal,
        alpha_p05=lo,
        alpha_p50=mid,
        alpha_p95=hi,
        errors=sp.errors,
        error_median=float(np.median(sp.errors)),
        error_p95=float(np.quantile(sp.errors, 0.95)),
        error_nominal=sp.error_nominal,
        alpha_sd_linear=sp.linear_sd,
        alpha_p05_linear=sp.alpha_nominal - half,
        alpha_p95_linear=sp.alpha_nominal + half,
        error_median_linear=float(np.median(sp.linear_errors)),
        error_p95_linear=float(np.quantile(sp.linear_errors, 0.95)),
        error_rms_linear=sp.linear_rms,
        gamma=sp.gamma,
        h=sp.h,
        alpha=sp.alpha,
        clipped=sp.clipped,
        settings=Settings(
            sigma_h=s_h,
            sigma_gamma=s_g,
            scale_sigma=s_s,
            samples=samples,
            seed=seed,
            model=fm.label,
            radius_m=r_m,
            reference="nominal curve" if ref is None else f"target {ref.name}",
        ),
        design=d,
        reference=ref,
        shear_strength=tau,
        modulus=e_star,
        seconds=time.perf_counter() - t0,
        forward_model=fm,
    )
    if out is not None:
        result.save(out)
    return result
