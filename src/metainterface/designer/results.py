"""What :func:`~metainterface.design` returns: a designed cell with its errors and checks,
that draws and saves itself (design.json, curve.csv, design.png)."""

from __future__ import annotations

import functools
import hashlib
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from metainterface._files import write_columns
from metainterface._files.provenance import HASH_DIGITS
from metainterface.inverse.targets import Target
from metainterface.physics.cell import Design
from metainterface.physics.limits import PressureCheck
from metainterface.physics.models import ForwardModel
from metainterface.physics.registry import get_model
from metainterface.verify import BemCheck, Correction

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

from metainterface.designer.curve_result import (
    CURVE_STEPS,
    Curve,
    ReachCounts,
    _axes,
    decimate,
    design_curve,
    shown,
)


@dataclass(frozen=True, repr=False)
class DesignResult(ReachCounts):
    """A designed unit cell for one target.

    Attributes
    ----------
    target : Target
        The target designed for.
    design : Design
        The cell: numpy ``gamma`` and ``h`` (N,), and its settings.
    error : float
        The curve error sqrt(fit^2 + (1 - coverage)^2): fit the relative L2 error
        ||alpha - alpha_target||_2 / ||alpha_target||_2 at the target's pressures the design
        reaches, coverage below (0.01 = 1 %; docs: concepts/errors).
    initial_error : float
        The same before refinement (the zero-shot prediction's, or the best start's).
    method : str
        ``"surrogate"``, ``"multistart"`` or ``"hertz"``.
    seconds : float
        Wall time per target [s].
    model : ForwardModel
        The forward model designed with.
    start : int
        Which start won (0 = the zero-shot prediction); see :attr:`origin`.
    zero_shot_from : str
        Which network made the zero-shot design, and from which view of the target:
        ``"surrogate"``, or for a target without stiffness also e.g. ``"friction-law
        network"`` or ``"surrogate, end x0.4"`` (its end cut to 0.4 of its largest
        pressure); ``""`` for the baselines.
    fallback : bool
        The design came from the fallback multistart.
    notes : tuple of str
        What the pipeline decided on the user's behalf.
    pressure : PressureCheck or None
        The peak-pressure check, when a limit was given.
    robust : dict or None
        Robust design only: the errors designed for and the statistics of the made cells:
        ``error_nominal``, ``error_median``, ``error_p95`` (over independent draws) and
        ``error_rms_refined`` (over the copies refined against).
    robust_error_refined : float or None
        Robust design only: the rms error over the copies refined against.
    printable : dict or None
        With a layer height: ``z_step`` [R] and the error before the snap, after it and
        after the re-refine (``error`` is the last).
    forced : bool
        The target was outside the reachable range and designed anyway (``force=True``):
        the closest design, not a match.
    coverage : float
        The fraction of the target's load range (0 to its largest P*) the design reaches.
    idle : tuple of int
        Indices of the asperities that carry no load (never touch within Delta_max, or
        only past the target's largest load).
    carrying : int
        The number of load-carrying asperities, N - len(idle).
    bem : BemCheck or None
        The design's check in BEM (``verify``): the BEM curve at the check's loads and its
        error to the target (:attr:`bem_error`); None when not verified.
    bem_before : BemCheck or None
        When the design was corrected in BEM: the check of the uncorrected design.
    corrections : tuple of Correction
        The correction's iterations (step, BEM error, kept or not), empty if none ran.
    """

    target: Target
    design: Design
    error: float
    initial_error: float
    method: str
    seconds: float
    model: ForwardModel = field(default_factory=get_model)
    start: int = 0
    zero_shot_from: str = ""
    fallback: bool = False
    notes: tuple[str, ...] = ()
    pressure: PressureCheck | None = None
    robust: dict[str, Any] | None = None
    printable: dict[str, Any] | None = None
    robust_error_refined: float | None = None
    forced: bool = False
    bem: BemCheck | None = None
    bem_before: BemCheck | None = None
    corrections: tuple[Correction, ...] = ()

    def _reach_of(self) -> tuple[ForwardModel, tuple[np.ndarray, np.ndarray]]:
        return self.model, (self.target.p_star, self.target.alpha)

    @functools.cached_property
    def f0_error(self) -> float | None:
        """An offset law's design: ``abs(F_0 / F_0,law - 1)``, its friction at zero load
        against the law's (under the model it was designed with); None for any other target."""
        from metainterface.inverse.offset import f0_error

        d = self.design
        return f0_error(self.target, d.gamma, d.h, d.settings, self.model)

    @property
    def f0_met(self) -> bool | None:
        """F_0 within ``inverse.offset.F0_MEET`` (2 %) of the law's; None without an offset."""
        from metainterface.inverse.offset import F0_MEET

        e = self.f0_error
        return None if e is None else e <= F0_MEET

    @property
    def bem_error(self) -> float | None:
        """The BEM curve's relative error to the target (None when not verified)."""
        return None if self.bem is None else self.bem.bem_error

    @property
    def bem_ok(self) -> bool | None:
        """The BEM error is within the threshold asked for (None when not verified)."""
        return None if self.bem is None else self.bem.ok

    @property
    def origin(self) -> str:
        """Which start the design came from, in words (random starts numbered from 1)."""
        if self.fallback:
            return f"fallback multistart, random start {self.start + 1}"
        if self.method != "surrogate":
            return f"random start {self.start + 1}"
        return "zero-shot" if self.start == 0 else f"hedge start {self.start}"

    def curve(self, steps: int = CURVE_STEPS) -> Curve:
        """The design's curve under the model it was designed with."""
        return design_curve(self.design, self.model, steps=steps)

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw the target and the design's alpha(P*) on ``ax`` (default: a new figure)."""
        from metainterface.plots import draw_curve

        ax = draw_curve(
            _axes(ax),
            self.curve(),
            label=f"{self.method}: {_percent(self.error)}",
            target=self.target,
        )
        ax.set_title(self.target.name)
        return ax

    def figure(self, *, width: float | None = None) -> Figure:
        """The full design figure: alpha(P*) and S*(P*) against the target, the friction law
        in newtons when the target came from one, the parameters and the cell seen from
        above. width: figure width in inches (default: the figure's own)."""
        from metainterface.plots import plot_design

        return shown(plot_design(self, self.figure_curve(), width=width))

    def figure_curve(self) -> Curve:
        """The design's curve for figures: dense, with every engagement resolved."""
        return design_curve(self.design, self.model, steps=1024, resolve_engagement=True)

    def record(self) -> dict[str, Any]:
        """What design.json stores about how the design was made: the target decimated to
        at most ``RECORD_POINTS`` points (with its size and the hash of the full curve)."""
        t = self.target
        keep = decimate(t.p_star.size)
        return {
            "target": {
                "name": t.name,
                "source": t.source,
                "points": int(t.p_star.size),
                "sha256": _array_hash(t.p_star, t.alpha),
                **({"stored_points": int(keep.size)} if keep.size < t.p_star.size else {}),
                "p_star": t.p_star[keep].tolist(),
                "alpha": t.alpha[keep].tolist(),
                **_compact_meta(t.meta),
            },
            "method": self.method,
            "model": self.model.label,
            "winning_start": self.origin,
            "relative_error": self.error,
            "error_definition": "sqrt(fit^2 + (1 - coverage)^2)",
            "coverage": self.coverage,
            **(
                {"f0_error": self.f0_error, "f0_met": self.f0_met}
                if self.f0_error is not None
                else {}
            ),
            "idle_asperities": list(self.idle),
            "carrying_asperities": self.carrying,
            **({"forced": True} if self.forced else {}),
            "zero_shot_error": self.initial_error,
            **({"zero_shot_from": self.zero_shot_from} if self.zero_shot_from else {}),
            "seconds": self.seconds,
            **({"notes": list(self.notes)} if self.notes else {}),
            **({"pressure_check": self.pressure.to_dict()} if self.pressure else {}),
            **({"robust": self.robust} if self.robust else {}),
            **({"printable": self.printable} if self.printable else {}),
            **({"bem_check": self.bem_record()} if self.bem is not None else {}),
        }

    def bem_record(self) -> dict[str, Any]:
        """design.json's "bem_check" block: the check of the design handed over and, if it
        was corrected, the uncorrected design's errors and each iteration."""
        assert self.bem is not None
        block = self.bem.to_dict()
        if self.bem_before is not None:
            block["uncorrected"] = {
                "bem_error": self.bem_before.bem_error,
                "accuracy": self.bem_before.accuracy,
                "model_error": self.bem_before.model_error,
            }
            block["corrections"] = [c.to_dict() for c in self.corrections]
        return block

    def save(
        self, folder: str | os.PathLike[str], *, full_target: bool = False, **extra: Any
    ) -> Path:
        """Write design.json, curve.csv and design.png into ``folder`` (and target.csv, the
        whole target, with ``full_target``); ``extra`` keys go into design.json. Returns the
        path of design.json."""
        from metainterface.plots import plot_design, save_figure

        folder, t = Path(folder), self.target
        folder.mkdir(parents=True, exist_ok=True)
        record = self.record()
        if full_target:
            write_columns(
                folder / "target.csv",
                {"p_star": t.p_star, "alpha": t.alpha},
                target=t.name,
                sha256=record["target"]["sha256"],
            )
        write_columns(
            folder / "curve.csv", self.curve().columns(), target=t.name, method=self.method
        )
        save_figure(
            plot_design(self, self.figure_curve()),
            folder / "design.png",
            target=t.name,
            method=self.method,
        )
        friction = t.meta.get("friction") if isinstance(t.meta, dict) else None
        if isinstance(friction, dict) and "fit" in friction:  # the measured rows were fitted
            from metainterface.plots.lawfit import plot_friction_fit

            fig = plot_friction_fit(friction, t.name)
            save_figure(fig, folder / "friction_fit.png", target=t.name)
        return self.design.save(folder / "design.json", **record, **extra)

    def __repr__(self) -> str:
        note = f", note: {self.notes[0]}" if self.notes else ""
        made = ""
        if self.robust:
            made += (
                f", robust: made cells median {_percent(self.robust['error_median'])}, "
                f"p95 {_percent(self.robust['error_p95'])}"
            )
        if self.printable:
            q = self.printable
            made += (
                f", on a {q['z_step']:.3g} R layer grid: {_percent(q['error_before_snap'])} "
                f"-> snapped {_percent(q['error_after_snap'])} -> re-refined "
                f"{_percent(q['error_after_refine'])}"
            )
        forced = "FORCED (target unreachable), " if self.forced else ""
        if self.bem is not None:
            before = self.bem_before
            fixed = "" if before is None else f", corrected from {before.error_text()}"
            flag = "" if self.bem.ok else f" (above {_percent(self.bem.max_error)})"
            where = " at loads the correction did not fit" if self.bem.held_out else ""
            made += f", BEM error {self.bem.error_text()}{flag}{where} on {self.bem.grid}^2{fixed}"
        return (
            f"DesignResult({forced}target={self.target.name!r}, method={self.method!r}, "
            f"model={self.model.label!r}, error={_percent(self.error)}, "
            + (
                ""
                if self.f0_error is None
                else f"F_0 off by {_percent(self.f0_error)}"
                + ("" if self.f0_met else " (UNMET: above 2 %)")
                + ", "
            )
            + f"coverage={_percent(self.coverage)}, carrying {self.carrying} of "
            f"{self.design.n_asperities} asperities, "
            f"zero-shot {_percent(self.initial_error)}, {self.seconds:.2f} s{made}, "
            f"design={self.design!r}{note})"
        )


def _array_hash(*arrays: np.ndarray) -> str:
    """'sha256:<hex>' of float64 arrays' bytes: names a curve without storing it."""
    digest = hashlib.sha256()
    for a in arrays:
        digest.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
    return "sha256:" + digest.hexdigest()[:HASH_DIGITS]


def _compact_meta(meta: dict[str, Any]) -> dict[str, Any]:
    """The target's meta with the friction law's force lists decimated like the target."""
    friction = meta.get("friction")
    if not isinstance(friction, dict) or "normal_force_n" not in friction:
        return meta
    fn, ff = friction["normal_force_n"], friction["friction_force_n"]
    keep = decimate(len(fn))
    law = {**friction, "normal_force_n": [fn[i] for i in keep]}
    law["friction_force_n"] = [ff[i] for i in keep]
    if keep.size < len(fn):
        law["law_points"] = len(fn)
    return {**meta, "friction": law}


def _percent(x: float) -> str:
    """A relative error in per cent with significant digits (0.0097 % not 0.00 %)."""
    return f"{100 * x:.3g} %"
