"""Forward models as objects: the interface and the two shipped models (the registry that
names them is ``physics.registry``).

A forward model maps (B, N) designs to their response along a Delta sweep. Two ship:

    Independent()                 the paper's superposition of Sneddon contacts (sec. 2.2)
    Interacting(curvature=False)  the same with the lattice's elastic field (``interaction``)

Both take ``adhesion=w`` (work of adhesion in units of E* R): JKR asperities, the loading
curve under a rising force, and an unloading branch and pull-off force (``physics.adhesion``).

Each implements ``sweep`` and ``asperity_sweep`` (and may give a cheaper ``load_area``, and
a cheaper ``newton_load`` for the exact law's Newton steps on Delta);
everything else (curves, alpha at given pressures, the dense curve that BEM results are
compared with) is derived once, in :class:`ForwardModel`. ``physics.registry.MODELS``
maps names to instances; ``register_model`` there adds one, and it is then accepted by
``design``, ``curve``, ``validate`` and the CLI's ``--model`` choices alike.
"""

from __future__ import annotations

import functools
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, fields, is_dataclass, replace

import numpy as np
import torch
from torch import Tensor

from metainterface.errors import MetainterfaceError
from metainterface.physics import adhesion as jkr
from metainterface.physics import curves, pressures
from metainterface.physics.cell import CellSettings, Design
from metainterface.physics.curves import Curve, ModelCurve, Sweep, anchor, delta_grid, to_grid
from metainterface.physics.interaction import (
    CURVATURE,
    ITERATIONS,
    asperity_sweep_interacting,
    interaction,
    load_area_interacting,
    sweep_interacting,
)
from metainterface.physics.jkr import check_adhesion
from metainterface.physics.metrics import interp
from metainterface.physics.sneddon import area
from metainterface.physics.tape import Pullback

#: Delta samples of the dense sweep that BEM loads are interpolated on (:meth:`model_curve`).
N_DELTA_DENSE = 8193


#: The fraction of the top load at which an adhesive model reads zero load (loads_read).
ZERO_LOAD = 1e-12


class ForwardModel(ABC):
    """The protocol of a forward model: subclass it, implement the two sweeps, register it.

    All tensors carry a leading batch axis: gamma, h (B, N) with h in units of R; delta (K,)
    or (B, K) [units of R]; results (B, K). ``smooth`` is the softplus steepness kappa_s
    [1/R] (None: the exact Macaulay bracket).
    """

    #: The name under which the model is registered and recorded in output files.
    name: str = ""
    #: Whether the response depends on which lattice cell each asperity sits in (then the
    #: refinement keeps asperity k in cell k; otherwise it may reorder them freely).
    placed: bool = True
    #: Work of adhesion w [E* R] (w_phys = w E* R); 0: adhesionless contact. An adhesive
    #: model's curve is the loading curve under a rising force (``physics.adhesion``).
    adhesion: float = 0.0

    @abstractmethod
    def sweep(
        self,
        gamma: Tensor,
        h: Tensor,
        settings: CellSettings,
        *,
        smooth: float | None = None,
        n_delta: int | None = None,
        delta: Tensor | None = None,
    ) -> Sweep:
        """P*, alpha and S* = dP*/dalpha (B, K) along the sweep, differentiable."""

    @abstractmethod
    def asperity_sweep(
        self,
        gamma: Tensor,
        h: Tensor,
        settings: CellSettings,
        *,
        n_delta: int | None = None,
        delta: Tensor | None = None,
    ) -> tuple[Sweep, Tensor]:
        """The exact sweep and each asperity's contact area / A_nom, (B, K, N)."""

    def load_area(
        self,
        gamma: Tensor,
        h: Tensor,
        settings: CellSettings,
        *,
        smooth: float | None = None,
        n_delta: int | None = None,
        delta: Tensor | None = None,
    ) -> Sweep:
        """The sweep where only P* and alpha are needed (S* may be NaN); a model overrides
        it where leaving S* out is cheaper."""
        return self.sweep(gamma, h, settings, smooth=smooth, n_delta=n_delta, delta=delta)

    def load_area_pullback(
        self, settings: CellSettings, smooth: float | None = None
    ) -> Callable[..., tuple[Sweep, Pullback]] | None:
        """``f(gamma, h, delta=None)`` -> the sweep and its closed-form pullback in P* and
        alpha (``physics.curves.sweep_pullback``); None where the model
        has none (autograd then)."""
        return None

    @property
    def takes_adhesion(self) -> bool:
        """Whether the model has an ``adhesion`` option (``with_adhesion`` can set it)."""
        return is_dataclass(self) and "adhesion" in {f.name for f in fields(self)}

    def with_adhesion(self, adhesion: float) -> ForwardModel:
        """This model with work of adhesion ``adhesion`` [E* R]; a one-line error for a
        model that takes none."""
        if not self.takes_adhesion:
            raise MetainterfaceError(
                f"model {self.label!r} does not take adhesion; use 'independent' or 'interacting'",
                argument="model",
            )
        return replace(self, adhesion=adhesion)  # type: ignore[type-var]

    @property
    def label(self) -> str:
        """The model and its options as recorded in files: ``interacting(curvature=True)``."""
        if not is_dataclass(self):
            return self.name
        opts = [
            f"{f.name}={getattr(self, f.name)!r}"
            for f in fields(self)
            if getattr(self, f.name) != f.default
        ]
        return f"{self.name}({', '.join(opts)})" if opts else self.name

    # --- adhesion: the unloading branch and the pull-off force ---------------------------

    def adhesion_kernel(self, settings: CellSettings, dtype: torch.dtype, device) -> Tensor | None:
        """The (N, N) interaction matrix the adhesive solve uses (None: independent)."""
        return None

    def unloading(
        self, gamma: Tensor, h: Tensor, settings: CellSettings, *, n_delta: int = 1025
    ) -> Sweep:
        """The unloading branch from Delta_max of (B, N) designs under a falling force:
        delta (B, K) descending, P* (B, K) (negative: a pull) and alpha (B, K)
        (``physics.adhesion.unloading_adhesive``; without adhesion, the loading curve
        reversed: adhesionless contact has no hysteresis)."""
        if not self.adhesion:
            delta = torch.linspace(
                settings.delta_max, 0.0, n_delta, dtype=gamma.dtype, device=gamma.device
            )
            sw = self.load_area(gamma, h, settings, delta=delta)
            return Sweep(
                delta=delta.expand_as(sw.p_star),
                p_star=sw.p_star,
                alpha=sw.alpha,
                stiffness=torch.full_like(sw.p_star, float("nan")),
            )
        kernel = self.adhesion_kernel(settings, gamma.dtype, gamma.device)
        return jkr.unloading_adhesive(
            gamma, h, settings, self.adhesion, n_delta=n_delta, kernel=kernel, **self._jkr_opts()
        )

    def pull_off(self, gamma: Tensor, h: Tensor, settings: CellSettings) -> Tensor:
        """The pull-off pressure P*_off = -min F / (A_nom E*) >= 0 (B,) after loading to
        Delta_max: how sticky the part feels (0 without adhesion). Multiply by A_nom E*
        for a force per cell, by E* for a pull per nominal area."""
        if not self.adhesion:
            return torch.zeros_like(gamma[:, 0])
        kernel = self.adhesion_kernel(settings, gamma.dtype, gamma.device)
        return jkr.pull_off(gamma, h, settings, self.adhesion, kernel=kernel, **self._jkr_opts())

    def touch_loads(self, design: Design) -> np.ndarray:
        """(N,) the largest P* of one design, loaded by approach, before each asperity touches
        (``physics.adhesion.touch_loads``; zeros without adhesion: no snap-in)."""
        gamma, h = design.tensors(torch.float64)
        if not self.adhesion:
            return np.zeros(gamma.shape[-1])
        kernel = self.adhesion_kernel(design.settings, gamma.dtype, gamma.device)
        opts = {"kernel": kernel, **self._jkr_opts()}
        with torch.no_grad():
            return jkr.touch_loads(gamma, h, design.settings, self.adhesion, **opts)[0].numpy()

    def design_pull_off(self, design: Design) -> float:
        """The pull-off pressure P*_off of one design (see :meth:`pull_off`)."""
        gamma, h = design.tensors(torch.float64)
        with torch.no_grad():
            return float(self.pull_off(gamma, h, design.settings)[0])

    def _jkr_opts(self) -> dict:
        return {}

    def _adhesive_sweep(self, gamma, h, settings, *, n_delta=None, delta=None):
        kernel = self.adhesion_kernel(settings, gamma.dtype, gamma.device)
        return jkr.sweep_adhesive(
            gamma,
            h,
            settings,
            self.adhesion,
            n_delta=n_delta,
            delta=delta,
            kernel=kernel,
            **self._jkr_opts(),
        )

    # --- derived, the same for every model -----------------------------------------------

    def curve(
        self,
        gamma: Tensor,
        h: Tensor,
        settings: CellSettings,
        *,
        smooth: float | None = None,
        n_delta: int | None = None,
    ) -> Curve:
        """alpha and S* of (B, N) designs on settings.n_steps uniform pressures."""
        sw = self.sweep(gamma, h, settings, smooth=smooth, n_delta=n_delta)
        return to_grid(sw, settings.n_steps)

    def design_sweep(
        self, design: Design, *, n_delta: int | None = None, smooth: float | None = None
    ) -> Sweep:
        """The float64 sweep of one Design: delta (K,), the rest (1, K)."""
        gamma, h = design.tensors(torch.float64)
        return self.sweep(gamma, h, design.settings, smooth=smooth, n_delta=n_delta)

    def alpha_at(
        self,
        gamma: Tensor,
        h: Tensor,
        settings: CellSettings,
        p_star: Tensor,
        *,
        smooth: float | None = None,
        n_delta: int | None = None,
        exact: bool = False,
    ) -> tuple[Tensor, Tensor]:
        """alpha (B, M) at the pressures p_star (B, M) and P*_max (B,); alpha is held at its
        last value beyond P*_max. Interpolated in an ``n_delta`` sweep, or, with ``exact``
        (exact law only), solved for P*(Delta) = p_star by Newton with exact gradients."""
        fn = self.sweep if exact else self.load_area
        opts = {"smooth": smooth, "n_delta": n_delta, "exact": exact, "load_fn": self.newton_load}
        if not self.adhesion:
            return pressures.alpha_at(gamma, h, settings, p_star, sweep_fn=fn, **opts)
        # an adhesive curve is a path (the force's running maximum along the Deltas given):
        # loads go in ascending (a tolerance study asks for two grids in one call)
        order = torch.argsort(p_star, dim=-1)
        ascending = p_star.gather(-1, order)
        # zero load: where the rising force first holds (loads_read), of the top load asked,
        # else of P*_max
        top = ascending[..., -1:]
        if bool((top <= 0).any()):
            top = torch.where(top > 0, top, self.load_area(gamma, h, settings).p_star[:, -1:])
        ascending = self.loads_read(ascending, top)
        alpha, p_max = pressures.alpha_at(gamma, h, settings, ascending, sweep_fn=fn, **opts)
        return alpha.gather(-1, torch.argsort(order, dim=-1)), p_max

    def loads_read(self, p_star: Tensor, top: Tensor | None = None) -> Tensor:
        """Ascending pressures (B, M) as :meth:`alpha_at` reads them: as given, but an
        adhesive model reads zero load at ``ZERO_LOAD`` of the top load (``top`` (B, 1), by
        default the last pressure), where the rising force first holds it (the end of the
        snap-in's plateau at P* = 0), not in a state the snap-in passes through. Losses on
        a target's grid read it so too."""
        if not self.adhesion:
            return p_star
        return torch.maximum(p_star, ZERO_LOAD * (p_star[..., -1:] if top is None else top))

    def newton_load(self, gamma: Tensor, h: Tensor, settings: CellSettings) -> Callable[..., Sweep]:
        """``load(delta=...)``: P* and ``load_slope`` of (B, N) designs at Deltas (B, M), for
        the Newton steps of ``pressures.solve_delta``; the sweep unless a model has less.
        With adhesion, a ``PathLoad``: its first brackets hold no snap-in."""
        if not self.adhesion:
            return functools.partial(self.sweep, gamma, h, settings)
        # P* and its slope alone: a fifth of an adhesive sweep's operations are its alpha's
        kernel = self.adhesion_kernel(settings, gamma.dtype, gamma.device)
        load = functools.partial(
            jkr.adhesive_load, gamma, h, settings, self.adhesion, kernel=kernel, **self._jkr_opts()
        )
        return jkr.PathLoad(load, h, settings)

    def alpha_at_loads(
        self,
        gamma: Tensor,
        h: Tensor,
        settings: CellSettings,
        p_star: Tensor,
        *,
        n_delta: int = 2049,
        max_extend: int = 6,
    ) -> Tensor:
        """alpha (B, Q) at the pressures p_star (B, Q), running the exact sweep past
        Delta_max (doubling its range at most ``max_extend`` times) until it covers them.

        For comparing models at one set of loads: they reach different P* at Delta_max.
        """
        top = p_star.max(dim=-1).values
        span = settings.delta_max
        for _ in range(max_extend + 1):
            delta = torch.linspace(0.0, span, n_delta, dtype=gamma.dtype, device=gamma.device)
            sw = self.load_area(gamma, h, settings, delta=delta)
            if bool((sw.p_star[:, -1] >= top).all()):
                return interp(p_star, sw.p_star, sw.alpha)
            span *= 2.0
        raise MetainterfaceError(
            f"P* up to {float(top.max()):.4g} is not reached by the {self.label} model "
            f"within Delta <= {span / 2:.4g}"
        )

    def model_curve(self, design: Design, n_delta: int = N_DELTA_DENSE) -> ModelCurve:
        """The dense exact curve of one design, with each asperity's area (for BEM)."""
        gamma, h = design.tensors(torch.float64)
        with torch.no_grad():
            sw, per = self.asperity_sweep(
                gamma, h, design.settings, delta=delta_grid(design.settings, n_delta)
            )
        curve = ModelCurve(
            p_star=sw.p_star[0].numpy(), alpha=sw.alpha[0].numpy(), asperity_alpha=per[0].numpy()
        )
        if not (curve.p_star.size >= 2 and curve.p_star_max > 0):
            raise MetainterfaceError(f"model {self.label!r} gives no load up to Delta_max")
        return curve


@dataclass(frozen=True, repr=True)
class Independent(ForwardModel):
    """The paper's model: independent Sneddon asperities, summed (sec. 2.2).

    adhesion: work of adhesion w [E* R], 0 by default; w > 0 makes each asperity a JKR
    contact (``physics.adhesion``) and the curve the loading curve under a rising force
    (``smooth`` is then not used: snap-in at touch is a jump whatever the smoothing).
    """

    adhesion: float = 0.0

    name = "independent"
    placed = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "adhesion", check_adhesion(self.adhesion))

    def sweep(self, gamma, h, settings, *, smooth=None, n_delta=None, delta=None) -> Sweep:
        if self.adhesion:
            return self._adhesive_sweep(gamma, h, settings, n_delta=n_delta, delta=delta)[0]
        return curves.sweep(gamma, h, settings, smooth=smooth, n_delta=n_delta, delta=delta)

    def load_area_pullback(self, settings, smooth=None):
        if self.adhesion:
            return None
        return functools.partial(curves.sweep_pullback, settings=settings, smooth=smooth)

    def newton_load(self, gamma, h, settings):
        # without adhesion: P* and its slope alone, ~12 operations a step against ~35
        if self.adhesion:
            return super().newton_load(gamma, h, settings)
        return pressures.independent_load(gamma, h, settings)

    def asperity_sweep(self, gamma, h, settings, *, n_delta=None, delta=None):
        if self.adhesion:
            return self._adhesive_sweep(gamma, h, settings, n_delta=n_delta, delta=delta)
        if delta is None:
            delta = delta_grid(settings, n_delta, dtype=gamma.dtype, device=gamma.device)
        sw = curves.sweep(gamma, h, settings, delta=delta)
        gap = delta[None, :, None] - anchor(h)[:, None, :]
        return sw, area(gamma[:, None, :], gap, settings.radius) / settings.nominal_area


@dataclass(frozen=True, repr=True)
class Interacting(ForwardModel):
    """The asperities with their elastic interaction through the periodic lattice.

    curvature: also the neighbours' curvature term (see ``physics.interaction``); off by
    default (the tip shift only). iterations: Newton sweeps of the self-consistent solve.
    """

    curvature: bool = CURVATURE
    iterations: int = ITERATIONS
    adhesion: float = 0.0

    name = "interacting"
    placed = True

    def __post_init__(self) -> None:
        if not isinstance(self.curvature, bool):
            raise MetainterfaceError(f"curvature must be True or False, got {self.curvature!r}")
        if isinstance(self.iterations, bool) or not (
            isinstance(self.iterations, int) and 1 <= self.iterations <= 100
        ):
            raise MetainterfaceError(
                f"iterations must be a whole number in [1, 100], got {self.iterations!r}"
            )
        object.__setattr__(self, "adhesion", check_adhesion(self.adhesion))
        if self.adhesion and self.curvature:
            raise MetainterfaceError(
                "curvature must be False with adhesion (the adhesive interaction is the tip "
                "shift only)",
                argument="curvature",
            )

    def adhesion_kernel(self, settings, dtype, device):
        return interaction(settings, dtype=dtype, device=device, curvature=False).shift

    def _jkr_opts(self) -> dict:
        # the adhesive solve is a Jacobi iteration (no Newton coupling): at least its own
        # default number of sweeps
        return {"iterations": max(self.iterations, jkr.ITERATIONS)}

    def _opts(self) -> dict:
        return {"curvature": self.curvature, "iterations": self.iterations}

    def sweep(self, gamma, h, settings, *, smooth=None, n_delta=None, delta=None) -> Sweep:
        if self.adhesion:
            return self._adhesive_sweep(gamma, h, settings, n_delta=n_delta, delta=delta)[0]
        return sweep_interacting(
            gamma, h, settings, smooth=smooth, n_delta=n_delta, delta=delta, **self._opts()
        )

    def load_area(self, gamma, h, settings, *, smooth=None, n_delta=None, delta=None) -> Sweep:
        if self.adhesion:
            return self._adhesive_sweep(gamma, h, settings, n_delta=n_delta, delta=delta)[0]
        d, p, a = load_area_interacting(
            gamma, h, settings, smooth=smooth, n_delta=n_delta, delta=delta, **self._opts()
        )
        return Sweep(delta=d, p_star=p, alpha=a, stiffness=torch.full_like(p, float("nan")))

    def asperity_sweep(self, gamma, h, settings, *, n_delta=None, delta=None):
        if self.adhesion:
            return self._adhesive_sweep(gamma, h, settings, n_delta=n_delta, delta=delta)
        return asperity_sweep_interacting(
            gamma, h, settings, n_delta=n_delta, delta=delta, **self._opts()
        )
