"""The unit cell: lattice, admissible design space, nominal area (paper sec. 2.2 and 4.1).

N = n * n asperities sit on an n x n square lattice, asperity k in lattice cell (k // n, k % n).
Each owns a square of side 4 a_max, where a_max is the largest contact radius reachable in the
admissible space (gamma in [gamma_min, gamma_max], h = 0, Delta = Delta_max); so the cell side
is L = 4 n a_max and A_nom = L^2. Lengths are in the unit of R (R = 1 in the core).
"""

from __future__ import annotations

import functools
import json
import math
import os
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import torch

from metainterface._files import strict_json
from metainterface._files.atomic import write_text
from metainterface._files.provenance import provenance
from metainterface.errors import MetainterfaceError
from metainterface.physics.sneddon import contact_radius

# Resolution of the gamma scan that finds a_max; the maximum is at an end point for all
# practical settings, the scan only guards against exotic ones (Delta_max ~ R).
_A_MAX_SCAN = 4097
#: Bounds that keep the closed forms in floating-point range (Gamma(gamma/2 + 1) overflows
#: near gamma = 340; Delta_max / R below 1e-9 underflows the areas) and sizes sane.
GAMMA_LIMIT = 100.0
DELTA_RATIO = (1e-9, 1.0)
SCALE_LIMITS = (1e-12, 1e12)
MAX_ASPERITIES = 10_000
MAX_STEPS = 1_000_000
#: Anchored heights above this many Delta_max are refused as absurd; an asperity between
#: Delta_max and this is legitimate but never touches (Design.idle).
H_LIMIT = 1000.0


def _finite(name: str, value: float, *, low: float | None = None, strict: bool = True) -> float:
    if isinstance(value, str | bool):  # float("2") would pass a string number silently
        raise MetainterfaceError(f"{name} must be a number, got {value!r}", argument=name)
    try:
        value = float(value)
    except (TypeError, ValueError, OverflowError):
        raise MetainterfaceError(f"{name} must be a number, got {value!r}", argument=name) from None
    if not math.isfinite(value):
        raise MetainterfaceError(f"{name} must be finite, got {value}", argument=name)
    if low is not None and (value <= low if strict else value < low):
        raise MetainterfaceError(
            f"{name} must be {'>' if strict else '>='} {low}, got {value}", argument=name
        )
    return value


@dataclass(frozen=True)
class CellSettings:
    """Everything that fixes the cell and its curves. Validated on construction.

    Attributes
    ----------
    n_asperities : int
        N, a perfect square (1, 4, 9, 16, ...).
    radius : float
        R, the base radius shared by all shapes [length; 1 in the dimensionless core].
    e_star : float
        E*, the equivalent modulus [pressure; 1 in the dimensionless core].
    delta_max : float
        Largest global indentation Delta_max [length]; the paper uses R / 50.
    gamma_min, gamma_max : float
        Admissible shape exponents, 1 < gamma_min < gamma_max.
    n_steps : int
        Points of the uniform pressure grid (and of the Delta sweep) of a curve.
    """

    n_asperities: int = 9
    radius: float = 1.0
    e_star: float = 1.0
    delta_max: float = 0.02
    gamma_min: float = 1.8
    gamma_max: float = 4.0
    n_steps: int = 128

    def __post_init__(self) -> None:
        n = self.n_asperities
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
            raise MetainterfaceError(f"n_asperities must be a positive perfect square, got {n!r}")
        if math.isqrt(int(n)) ** 2 != n:
            raise MetainterfaceError(
                f"n_asperities must be a perfect square (1, 4, 9, 16, ...), got {n}",
                argument="n_asperities",
            )
        if n > MAX_ASPERITIES:
            raise MetainterfaceError(
                f"n_asperities must be at most {MAX_ASPERITIES}, got {n}", argument="n_asperities"
            )
        object.__setattr__(self, "n_asperities", int(n))
        for name in ("radius", "e_star", "delta_max"):
            object.__setattr__(self, name, _finite(name, getattr(self, name), low=0.0))
        for name in ("radius", "e_star"):
            value = getattr(self, name)
            if not SCALE_LIMITS[0] <= value <= SCALE_LIMITS[1]:
                raise MetainterfaceError(
                    f"{name} must be in [{SCALE_LIMITS[0]:g}, {SCALE_LIMITS[1]:g}], got {value:g}",
                    argument=name,
                )
        ratio = self.delta_max / self.radius
        if not DELTA_RATIO[0] <= ratio <= DELTA_RATIO[1]:
            raise MetainterfaceError(
                f"delta_max must be in [{DELTA_RATIO[0]:g}, {DELTA_RATIO[1]:g}] R (small-slope "
                f"contact, floating-point range), got {ratio:g} R",
                argument="delta_max",
            )
        gmin = _finite("gamma_min", self.gamma_min, low=1.0)
        gmax = _finite("gamma_max", self.gamma_max, low=1.0)
        if gmax <= gmin:
            raise MetainterfaceError(
                f"gamma bounds must satisfy 1 < gamma_min < gamma_max, got [{gmin}, {gmax}]"
            )
        if gmax > GAMMA_LIMIT:
            raise MetainterfaceError(
                f"gamma_max must be at most {GAMMA_LIMIT:g}, got {gmax:g}", argument="gamma_max"
            )
        object.__setattr__(self, "gamma_min", gmin)
        object.__setattr__(self, "gamma_max", gmax)
        steps = self.n_steps
        if (
            isinstance(steps, bool)
            or not isinstance(steps, int | np.integer)
            or not 2 <= steps <= MAX_STEPS
        ):
            raise MetainterfaceError(
                f"n_steps must be an integer in [2, {MAX_STEPS}], got {steps!r}",
                argument="n_steps",
            )
        object.__setattr__(self, "n_steps", int(steps))

    @property
    def n_side(self) -> int:
        """n, the lattice side: N = n * n."""
        return math.isqrt(self.n_asperities)

    @functools.cached_property
    def a_max(self) -> float:
        """Largest contact radius reachable in the admissible space [length]."""
        gammas = torch.linspace(self.gamma_min, self.gamma_max, _A_MAX_SCAN, dtype=torch.float64)
        delta = torch.full_like(gammas, self.delta_max)
        return float(contact_radius(gammas, delta, self.radius).max())

    @functools.cached_property
    def cell_side(self) -> float:
        """L = 4 n a_max [length]."""
        return 4.0 * self.n_side * self.a_max

    @functools.cached_property
    def nominal_area(self) -> float:
        """A_nom = L^2 [length^2]."""
        return self.cell_side**2

    def lattice_centres(self) -> np.ndarray:
        """(N, 2) centres (x, y) of the asperities' squares, asperity k in cell (k // n, k % n).

        Row index k // n runs along y, column index k % n along x [length].
        """
        n = self.n_side
        pitch = self.cell_side / n
        k = np.arange(self.n_asperities)
        return np.stack([(k % n + 0.5) * pitch, (k // n + 0.5) * pitch], axis=1)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    def __reduce__(self):  # pickle (process pools) without the cached geometry
        return (CellSettings, tuple(self.to_dict().values()))

    def with_(self, **changes: Any) -> CellSettings:
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)


@dataclass(frozen=True)
class Design:
    """One unit-cell design: shape exponents and height offsets of its N asperities.

    Attributes
    ----------
    gamma : ndarray, shape (N,)
        Shape exponents in [gamma_min, gamma_max] (dimensionless).
    h : ndarray, shape (N,)
        Height offsets >= 0 [length, units of R], asperity k in lattice cell (k // n, k % n).
    settings : CellSettings
        The cell they live in.
    extras : dict
        Any other keys of a design file, kept as they are.
    """

    gamma: np.ndarray
    h: np.ndarray
    settings: CellSettings = field(default_factory=CellSettings)
    extras: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        gamma = _as_vector("gamma", self.gamma)
        h = _as_vector("h", self.h)
        if gamma.shape != h.shape:
            raise MetainterfaceError(
                f"gamma and h must have the same length, got {gamma.size} and {h.size}"
            )
        if self.settings.n_asperities != gamma.size:
            object.__setattr__(self, "settings", self.settings.with_(n_asperities=int(gamma.size)))
        s = self.settings
        tol = 1e-9 * (s.gamma_max - s.gamma_min)
        bad = np.flatnonzero((gamma < s.gamma_min - tol) | (gamma > s.gamma_max + tol))
        if bad.size:
            i = int(bad[0])
            raise MetainterfaceError(
                f"gamma[{i}] = {gamma[i]:g} is outside the bounds "
                f"[{s.gamma_min:g}, {s.gamma_max:g}] (and gamma must be > 1)"
            )
        bad = np.flatnonzero(h < 0)
        if bad.size:
            i = int(bad[0])
            raise MetainterfaceError(f"h[{i}] = {h[i]:g} is negative; heights must be >= 0")
        bad = np.flatnonzero(h - h.min() > H_LIMIT * s.delta_max)
        if bad.size:
            i = int(bad[0])
            raise MetainterfaceError(
                f"h[{i}] = {h[i]:g} lies {(h[i] - h.min()) / s.delta_max:.3g} Delta_max above the "
                f"lowest tip; heights must be within {H_LIMIT:g} Delta_max of it"
            )
        object.__setattr__(self, "gamma", np.clip(gamma, s.gamma_min, s.gamma_max))
        object.__setattr__(self, "h", h)

    @property
    def n_asperities(self) -> int:
        return int(self.gamma.size)

    @property
    def delta_max(self) -> float:
        """Delta_max, the largest global indentation [length, units of R] (the settings')."""
        return self.settings.delta_max

    @property
    def idle(self) -> np.ndarray:
        """Indices of the asperities that never touch: more than Delta_max above the lowest."""
        return np.flatnonzero(self.h - self.h.min() > self.settings.delta_max * (1 + 1e-12))

    def tensors(self, dtype: torch.dtype = torch.float64) -> tuple[torch.Tensor, torch.Tensor]:
        """(gamma, h) as (1, N) tensors: a batch of one for the physics functions."""
        return (
            torch.as_tensor(self.gamma, dtype=dtype)[None],
            torch.as_tensor(self.h, dtype=dtype)[None],
        )

    def __repr__(self) -> str:
        s = self.settings
        opts = dict(precision=3, separator=", ", max_line_width=10**6, suppress_small=True)
        g = np.array2string(self.gamma, **opts)
        h = np.array2string(self.h / s.delta_max, **opts)
        return (
            f"Design(N={self.n_asperities}, gamma={g}, h/Delta_max={h}, "
            f"gamma in [{s.gamma_min:g}, {s.gamma_max:g}], Delta_max={s.delta_max:g} R)"
        )

    # --- the design file format, metainterface/design-v1 ---------------------------------

    def to_dict(self, **extra: Any) -> dict[str, Any]:
        """The design-v1 mapping; ``extra`` keys are added (they override ``extras``)."""
        s = self.settings
        out: dict[str, Any] = {
            "format": FORMAT,
            "gamma": [float(g) for g in self.gamma],
            "h": [float(v) for v in self.h],
            "radius": s.radius,
            "delta_max": s.delta_max,
            "gamma_bounds": [s.gamma_min, s.gamma_max],
            "e_star": s.e_star,
        }
        out.update(self.extras)
        out.update(extra)
        return out

    @classmethod
    def from_dict(cls, data: Any, *, source: str = "design") -> Design:
        """Build and validate a Design from a parsed design-v1 mapping; errors name
        ``source`` and the field."""
        if not isinstance(data, dict):
            raise MetainterfaceError(f"{source}: expected a JSON object with keys gamma and h")
        fmt = data.get("format", FORMAT)
        if fmt != FORMAT:
            raise MetainterfaceError(f"{source}: unknown format {fmt!r}, expected {FORMAT!r}")
        for key in ("gamma", "h"):
            if key not in data:
                raise MetainterfaceError(f"{source}: missing required field {key!r}")
            if not isinstance(data[key], list):
                raise MetainterfaceError(f"{source}: field {key!r} must be a list of numbers")
        bounds = data.get("gamma_bounds", [1.8, 4.0])
        if not (isinstance(bounds, list) and len(bounds) == 2):
            raise MetainterfaceError(
                f"{source}: gamma_bounds must be a list [gamma_min, gamma_max]"
            )
        try:
            settings = CellSettings(
                n_asperities=len(data["gamma"]),
                radius=data.get("radius", 1.0),
                e_star=data.get("e_star", 1.0),
                delta_max=data.get("delta_max", 0.02),
                gamma_min=bounds[0],
                gamma_max=bounds[1],
            )
            extras = {k: v for k, v in data.items() if k not in _CORE_KEYS}
            return cls(gamma=data["gamma"], h=data["h"], settings=settings, extras=extras)
        except MetainterfaceError as exc:
            raise MetainterfaceError(f"{source}: {exc}") from None

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Design:
        """Read and validate a design file; errors name the file and the field."""
        path = Path(path)
        try:
            if path.exists() and not path.is_file():  # a FIFO would block, a folder fail later
                raise MetainterfaceError(f"{path}: not a regular file")
            if path.stat().st_size > MAX_FILE_BYTES:
                raise MetainterfaceError(
                    f"{path}: {path.stat().st_size / 2**20:.0f} MiB, too large for a design file"
                )
            text = path.read_text(encoding="utf-8-sig")  # a BOM from a Windows editor is fine
        except FileNotFoundError:
            raise MetainterfaceError(f"{path}: file not found") from None
        except (OSError, UnicodeDecodeError) as exc:
            raise MetainterfaceError(f"{path}: cannot read ({exc})") from None
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise MetainterfaceError(
                f"{path}: malformed JSON at line {exc.lineno} column {exc.colno}: {exc.msg}"
            ) from None
        except RecursionError:  # thousands of nested brackets
            raise MetainterfaceError(f"{path}: JSON nested too deeply for a design file") from None
        return cls.from_dict(data, source=str(path))

    def save(self, path: str | os.PathLike[str], **extra: Any) -> Path:
        """Write the design file atomically (with a provenance record unless it carries
        one); ``extra`` keys are stored beside the design. Returns the path."""
        data = self.to_dict(**extra)
        data.setdefault("provenance", provenance())
        return write_text(path, strict_json.dumps(data, indent=2) + "\n")


#: Largest design file read (a design of the largest cell is well under 1 MiB).
MAX_FILE_BYTES = 64 * 2**20
#: The design file format every command reads and writes.
FORMAT = "metainterface/design-v1"
_CORE_KEYS = {"format", "gamma", "h", "radius", "delta_max", "gamma_bounds", "e_star"}


def _as_vector(name: str, values: Any) -> np.ndarray:
    from metainterface._checks import vector

    return vector(name, values)
