"""Design targets: alpha(P*) curves to reproduce, built in or read from CSV.

Built-in targets (the three out-of-distribution targets of the paper's sec. 4), all for the
default cell (N = 9, R = 1, Delta_max = R/50, gamma in [1.8, 4]):

* ``saturating``: the exact curve of a cell of nine identical, moderately blunt asperities
  (gamma = 3.2) engaging almost together (h_k = k * 0.0125 Delta_max, k = 0..8): the area
  grows steeply, then saturates.
* ``bilinear``: the exact curve of a cell with two groups: four Hertzian asperities
  (gamma = 2) at h = 0 and five blunt ones (gamma = 3.6) at h = 0.45 Delta_max: the stiffness
  jumps when the second group engages.
* ``linear``: alpha = 25 P* for P* in [0, 0.002], synthetic (a constant friction coefficient
  over the whole range); 128 points.

The two design targets are sampled exactly at ``DESIGN_TARGET_POINTS`` uniform pressures
(:func:`design_targets`), so their own designs meet them to round-off.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import torch

from metainterface._files.columns import read_columns
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings
from metainterface.physics.curves import (
    S_HAT_MAX,
    features_from_normalised,
    normalised_from_points,
    sweep,
)
from metainterface.physics.pressures import at_pressures


@dataclass(frozen=True, repr=False)
class Target:
    """A target contact law alpha(P*): what a design should reproduce.

    Build one from arrays or lists (``Target(p_star=[...], alpha=[...], name="mine")``), or
    with :meth:`builtin`, :meth:`from_csv` or :meth:`from_friction`. Checked on
    construction: bad input raises MetainterfaceError naming the row and the rule.

    Attributes
    ----------
    p_star : ndarray, shape (M,)
        Dimensionless pressures P* = P / E*, strictly increasing from 0 (or near it).
    alpha : ndarray, shape (M,)
        Contact-area fractions A_real / A_nom in [0, 1), ending > 0.
    name : str
        A label (used for output folders).
    stiffness : ndarray, shape (M,), or None
        S* = dP*/dalpha at the same points, optional (exact for built-ins); without it the
        surrogate estimates S* by finite differences.
    source : str
        Where it came from.
    meta : dict
        Anything else recorded with the designs (e.g. the friction law it was made from).
    """

    p_star: np.ndarray
    alpha: np.ndarray
    name: str = "target"
    stiffness: np.ndarray | None = None
    source: str = ""
    meta: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise MetainterfaceError(f"target name must be a non-empty string, got {self.name!r}")
        if self.name in (".", "..") or any(c in self.name for c in "/\\\0"):
            # the name becomes an output folder: it must not point elsewhere
            raise MetainterfaceError(
                f"target name {self.name!r} cannot name a folder (no '/', '\\', '.' or '..')"
            )
        where = f"target {self.name}"
        p = _column(where, "p_star", self.p_star)
        a = _column(where, "alpha", self.alpha)
        if p.shape != a.shape:
            raise MetainterfaceError(
                f"{where}: p_star and alpha must have the same length, got {p.size} and {a.size}"
            )
        check_target(self.name, p, a, self.source or where)
        object.__setattr__(self, "p_star", p)
        object.__setattr__(self, "alpha", a)
        if self.stiffness is not None:
            s = _column(where, "stiffness", self.stiffness)
            if s.shape != p.shape:
                raise MetainterfaceError(f"{where}: stiffness must have one value per point")
            object.__setattr__(self, "stiffness", s)

    @property
    def p_star_max(self) -> float:
        """The largest pressure of the target."""
        return float(self.p_star[-1])

    def __repr__(self) -> str:
        return (
            f"Target({self.name!r}, {self.p_star.size} points, P* in [0, {self.p_star_max:.4g}], "
            f"alpha in [{self.alpha.min():.4g}, {self.alpha.max():.4g}])"
        )

    @staticmethod
    def builtins() -> tuple[str, ...]:
        """The names of the built-in targets."""
        return tuple(BUILTIN_TARGETS)

    @classmethod
    def builtin(cls, name: str) -> Target:
        """A built-in target: ``saturating``, ``bilinear`` or ``linear`` (paper sec. 4)."""
        return builtin_target(name)

    @classmethod
    def from_csv(cls, path: str | os.PathLike[str], name: str | None = None) -> Target:
        """A target from a CSV with header ``p_star,alpha`` ('#' lines and blank lines are
        skipped; comma, ';' or tab separated, decimal commas with ';' or tab)."""
        return target_from_csv(path, name)

    @classmethod
    def from_friction(
        cls,
        law: str | os.PathLike[str],
        *,
        shear_strength: str | float,
        modulus: str | float,
        radius: str | float,
        area: str | float,
        settings: CellSettings | None = None,
        name: str | None = None,
        fit: str = "auto",
        work_of_adhesion: str | float | None = None,
    ) -> Target:
        """A target from a friction law: a CSV ``normal_force,friction_force`` [N] (or
        ``normal_force,friction_coefficient``), one row per load; the header may give the
        force unit (``normal_force [mN]``, ``friction_force_kN``), the file ';' or tab
        separators and decimal commas. A likely unit slip in the scale (E* below 1 kPa,
        tau above E*, R above 10 cm) warns (:class:`~metainterface.UnitSlipWarning`).

        shear_strength tau, modulus E*, radius R, area (nominal area of the whole interface):
        quantities with units ('0.25MPa', '0.5mm', '4cm2') or numbers in SI. Bowden-Tabor:
        alpha = F_f / (tau A), P* = F_n / (A E*). The conversion is kept in ``meta``.
        fit: "auto" replaces measured rows that are not a law as they stand (scatter,
        repeated or unsorted loads) or fewer than 10 rows by a monotone smooth fit,
        "always" or "never" force it; the fit and its residual are in
        ``meta["friction"]["fit"]``.
        work_of_adhesion: w ('50mJ/m2' or J/m^2), for adhesive contact (JKR asperities): an
        offset F_f(0) > 0 is then accepted and kept, and ``design`` uses the forward model
        with adhesion w / (E* R) (``meta["friction"]["adhesion"]``).
        """
        from metainterface.units.friction import friction_target_in_units

        ft = friction_target_in_units(
            law,
            shear_strength=shear_strength,
            modulus=modulus,
            radius=radius,
            area=area,
            settings=settings,
            fit=fit,
            work_of_adhesion=work_of_adhesion,
        )
        return friction_law_target(ft, law, name)


def friction_law_target(ft: Any, source: str | os.PathLike[str], name: str | None = None) -> Target:
    """The Target of a converted friction law (a ``units.friction.FrictionTarget``) read
    from the CSV ``source``: named after the file unless ``name``; the conversion in
    ``meta["friction"]``."""
    return Target(
        p_star=ft.p_star,
        alpha=ft.alpha,
        name=name or Path(source).stem,
        source=str(source),
        meta={"friction": ft.record()},
    )


def _column(where: str, name: str, values: object) -> np.ndarray:
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise MetainterfaceError(f"{where}: {name} must be a list of numbers") from None
    if arr.ndim != 1:
        raise MetainterfaceError(f"{where}: {name} must be 1-D, got shape {arr.shape}")
    return arr


#: Pressures at which design targets are sampled: 127 * 8 + 1 uniform points, so that the
#: refinement's 128-point grid (RefineSettings.grid_points) falls on every 8th and a design
#: is compared with its target's exact values there; other grids interpolate finely.
DESIGN_TARGET_POINTS = 127 * 8 + 1


def design_targets(
    names: list[str],
    gamma: torch.Tensor,
    h: torch.Tensor,
    settings: CellSettings | None = None,
    source: str = "",
    points: int = DESIGN_TARGET_POINTS,
) -> list[Target]:
    """The exact curves of (B, N) designs (h in units of R) as targets, one per name: alpha
    and S* at ``points`` uniform pressures on [0, P*_max], exact to round-off (the pressure
    is solved for, :func:`~metainterface.physics.pressures.at_pressures`)."""
    s = settings or CellSettings()
    gamma, h = gamma.to(torch.float64), h.to(torch.float64)
    if len(names) != gamma.shape[0] or gamma.shape != h.shape or gamma.dim() != 2:
        raise MetainterfaceError(
            f"design_targets: {len(names)} names for gamma {tuple(gamma.shape)}, "
            f"h {tuple(h.shape)}; need one (N,) row of each per name"
        )
    with torch.no_grad():
        p_max = sweep(gamma, h, s, n_delta=2).p_star[:, -1:]
        p = torch.linspace(0.0, 1.0, points, dtype=torch.float64)[None] * p_max
        p[:, -1] = p_max[:, 0]  # exactly P*_max: the last point is Delta_max itself
        sw, _ = at_pressures(gamma, h, s, p)
    return [
        Target(
            p_star=p[i].numpy(),
            alpha=sw.alpha[i].numpy(),
            name=name,
            stiffness=sw.stiffness[i].numpy(),
            source=source,
            meta={"gamma": gamma[i].tolist(), "h": h[i].tolist()},
        )
        for i, name in enumerate(names)
    ]


def design_target_of(name: str, gamma: list[float], h_frac: list[float], source: str) -> Target:
    s = CellSettings()
    g = torch.tensor([gamma], dtype=torch.float64)
    h = torch.tensor([h_frac], dtype=torch.float64) * s.delta_max
    return design_targets([name], g, h, s, source)[0]


def _saturating() -> Target:
    return design_target_of(
        "saturating",
        [3.2] * 9,
        [0.0125 * k for k in range(9)],
        "nine gamma = 3.2 asperities at h_k = k * 0.0125 Delta_max",
    )


def _bilinear() -> Target:
    return design_target_of(
        "bilinear",
        [2.0] * 4 + [3.6] * 5,
        [0.0] * 4 + [0.45] * 5,
        "four gamma = 2 asperities at h = 0, five gamma = 3.6 at h = 0.45 Delta_max",
    )


def _linear() -> Target:
    p = np.linspace(0.0, 0.002, 128)
    return Target(
        p_star=p,
        alpha=25.0 * p,
        name="linear",
        stiffness=np.full_like(p, 1 / 25.0),
        source="alpha = 25 P*, P* <= 0.002",
    )


BUILTIN_TARGETS: dict[str, Callable[[], Target]] = {
    "saturating": _saturating,
    "bilinear": _bilinear,
    "linear": _linear,
}


def builtin_target(name: str) -> Target:
    """One of the built-in targets by name."""
    try:
        return BUILTIN_TARGETS[name]()
    except KeyError:
        raise MetainterfaceError(
            f"unknown target {name!r}; built-in targets are {', '.join(BUILTIN_TARGETS)}"
        ) from None


def check_target(name: str, p_star: np.ndarray, alpha: np.ndarray, where: str) -> None:
    """Validate a target curve; errors name the row (1-based) and the rule broken."""
    if p_star.size < 3:
        raise MetainterfaceError(f"{where}: a target needs at least 3 points, got {p_star.size}")
    for col, arr in (("p_star", p_star), ("alpha", alpha)):
        bad = np.flatnonzero(~np.isfinite(arr))
        if bad.size:
            raise MetainterfaceError(f"{where}: row {bad[0] + 1}: {col} is not a finite number")
        bad = np.flatnonzero(arr < 0)
        if bad.size:
            raise MetainterfaceError(
                f"{where}: row {bad[0] + 1}: {col} = {arr[bad[0]]:g} is negative"
            )
    bad = np.flatnonzero(np.diff(p_star) <= 0)
    if bad.size:
        raise MetainterfaceError(
            f"{where}: row {bad[0] + 2}: p_star must be strictly increasing "
            f"({p_star[bad[0] + 1]:g} after {p_star[bad[0]]:g})"
        )
    if p_star[0] > 0.05 * p_star[-1]:
        raise MetainterfaceError(
            f"{where}: row 1: p_star = {p_star[0]:g} must start at 0 or near it "
            f"(<= 5 % of the largest pressure, {p_star[-1]:g})"
        )
    if alpha[-1] <= 0:
        raise MetainterfaceError(f"{where}: alpha must become positive")
    bad = np.flatnonzero(alpha >= 1)
    if bad.size:
        raise MetainterfaceError(
            f"{where}: row {bad[0] + 1}: alpha = {alpha[bad[0]]:g} is not < 1 (a real contact "
            "area cannot reach the nominal area)"
        )


def target_from_csv(path: str | os.PathLike[str], name: str | None = None) -> Target:
    """A target from a CSV with header ``p_star,alpha`` (>= 3 rows, p_star increasing from ~0)."""
    cols = read_columns(path, ("p_star", "alpha"))
    return Target(
        p_star=cols["p_star"], alpha=cols["alpha"], name=name or Path(path).stem, source=str(path)
    )


def target_features(
    target: Target, n_steps: int = 128, s_hat_max: float = S_HAT_MAX
) -> torch.Tensor:
    """The surrogate's input (2 n_steps + 2,) for a target: alpha_hat, S_hat, log10 scalars.

    S* comes from the target's own stiffness where it has one, else from finite differences
    of alpha(P*) (:func:`~metainterface.physics.curves.normalised_from_points`, the estimate
    the friction-law network was trained on); S_hat is clipped to [0, s_hat_max] (steep
    targets have unbounded S_hat).
    """
    p, a = target.p_star, target.alpha
    if p[0] > 0:  # the curve starts at the origin, as every contact curve does
        p, a = np.concatenate([[0.0], p]), np.concatenate([[0.0], a])
    p64 = torch.as_tensor(p, dtype=torch.float64)[None]
    a64 = torch.as_tensor(a, dtype=torch.float64)[None]
    alpha_hat, s_hat, p_max, a_max = normalised_from_points(p64, a64, n_steps, s_hat_max)
    if target.stiffness is not None:
        grid = np.linspace(0.0, target.p_star_max, n_steps)
        stiff = np.interp(grid, target.p_star, target.stiffness)
        s_hat = torch.as_tensor(np.clip(stiff * float(a_max[0]) / float(p_max[0]), 0.0, s_hat_max))[
            None
        ]
    return features_from_normalised(alpha_hat, s_hat, p_max, a_max)[0].to(torch.float32)
