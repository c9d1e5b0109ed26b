"""The six engineered topography categories of the synthetic dataset (paper sec. 2.4).

Every sampler is a pure function ``sample_<name>(rng, count, settings, params)`` that returns
``(gamma, h)``, two (count, N) float64 arrays: shape exponents in [gamma_min, gamma_max]
(dimensionless) and height offsets [units of R, like Delta_max]. Everything random comes from
``rng`` (a ``numpy.random.Generator``), so a sampler is reproducible from its seed.

Heights are engagement depths. The dataset anchors every sample so that its lowest asperity
sits at h = 0 (first contact at Delta = 0, as the forward model assumes), so the rules below
are stated for anchored heights. Where a rule gives an absolute band (h > 1.1 Delta_max,
h in [0.8, 1.0] Delta_max, ...), the sampler anchors its lowest group itself (subtracts that
group's minimum), so the band still holds after the dataset's anchoring. Columns come in no
particular order: the dataset sorts each sample by height.

Conventions of the parameter classes: heights are fractions of Delta_max; gamma fractions are
fractions of the range gamma_max - gamma_min; every number the paper leaves open is a field
with its default named in the class docstring.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from metainterface.data._draws import (
    anchor_group,
    check_params,
    first,
    full_gamma,
    group_sizes,
    require,
    truncated_exponential_ppf,
    truncated_normal_ppf,
    uniform,
    uniform_above,
)
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings

Sampler = Callable[[np.random.Generator, int, CellSettings, Any], tuple[np.ndarray, np.ndarray]]


# -- (a) Latin hypercube --------------------------------------------------------------------


@dataclass(frozen=True)
class LHSParams:
    """Latin hypercube over the full 2N-dimensional box gamma x h.

    scramble: True (default) places each point uniformly inside its stratum, False at the
        stratum centre (scipy.stats.qmc.LatinHypercube's ``scramble``).
    h_max: heights span [0, h_max] Delta_max; default 1.0 (the paper's design box).
    """

    scramble: bool = True
    h_max: float = 1.0

    def __post_init__(self) -> None:
        check_params(self)
        require(self.h_max > 0, self, f"h_max must be > 0, got {self.h_max}")


def sample_lhs(
    rng: np.random.Generator, count: int, settings: CellSettings, params: LHSParams = LHSParams()
) -> tuple[np.ndarray, np.ndarray]:
    """One Latin hypercube of ``count`` points in 2N dimensions (scipy.stats.qmc).

    Columns 0..N-1 scale to gamma in [gamma_min, gamma_max], columns N..2N-1 to h in
    [0, h_max Delta_max]: along every one of the 2N axes each of the ``count`` equal strata
    holds exactly one point. Returns (gamma, h), both (count, N).
    """
    # imported here: scipy.stats costs ~1 s to import, and ``train`` reads this module
    # without drawing
    from scipy.stats import qmc

    n = settings.n_asperities
    try:
        lhs = qmc.LatinHypercube(d=2 * n, scramble=params.scramble, rng=rng)
    except TypeError:  # scipy < 1.15 calls it seed (same stream)
        lhs = qmc.LatinHypercube(d=2 * n, scramble=params.scramble, seed=rng)
    x = lhs.random(count)
    span = settings.gamma_max - settings.gamma_min
    gamma = settings.gamma_min + span * x[:, :n]
    h = (params.h_max * settings.delta_max) * x[:, n:]
    return gamma, h


# -- (b) truncated height distributions -----------------------------------------------------


@dataclass(frozen=True)
class TruncatedParams:
    """A sparse active subset; the rest can never touch within Delta_max.

    active_min, active_max: number of active asperities, uniform on [1, 3] (paper), clipped
        to N.
    active_h_max: active heights uniform on [0, 1.0) Delta_max, then anchored among themselves
        (default 1.0: they engage anywhere inside the loading range).
    inactive_h_min, inactive_h_max: inactive heights uniform on (1.1, 1.5] Delta_max; 1.1 is
        the paper's bound, the upper end 1.5 is our choice.
    Gammas of all asperities (active or not) are uniform on [gamma_min, gamma_max).
    """

    active_min: int = 1
    active_max: int = 3
    active_h_max: float = 1.0
    inactive_h_min: float = 1.1
    inactive_h_max: float = 1.5

    def __post_init__(self) -> None:
        check_params(self)
        require(
            1 <= self.active_min <= self.active_max,
            self,
            f"need 1 <= active_min <= active_max, got {self.active_min}, {self.active_max}",
        )
        require(
            self.active_h_max <= 1.0 < self.inactive_h_min < self.inactive_h_max,
            self,
            "need active_h_max <= 1 < inactive_h_min < inactive_h_max, got "
            f"{self.active_h_max}, {self.inactive_h_min}, {self.inactive_h_max}",
        )


def sample_truncated(
    rng: np.random.Generator,
    count: int,
    settings: CellSettings,
    params: TruncatedParams = TruncatedParams(),
) -> tuple[np.ndarray, np.ndarray]:
    """1 to 3 active asperities (h < Delta_max); the rest at h > 1.1 Delta_max, never in contact.

    Returns (gamma, h), both (count, N). After anchoring, the lowest active asperity is at 0.
    """
    n, dmax = settings.n_asperities, settings.delta_max
    gamma = full_gamma(rng, count, settings)
    k = group_sizes(rng, count, params.active_min, params.active_max, n)
    active = first(k, n)
    h_active = uniform(rng, 0.0, params.active_h_max * dmax, (count, n))
    h_inactive = uniform_above(
        rng, params.inactive_h_min * dmax, params.inactive_h_max * dmax, (count, n)
    )
    h = anchor_group(np.where(active, h_active, h_inactive), active)
    return gamma, h


# -- (c) bimodal shapes ---------------------------------------------------------------------


@dataclass(frozen=True)
class BimodalParams:
    """Shallow soft shapes paired with deep blunt punches (stiffness cliffs).

    gamma_fraction: soft gammas in the bottom 20 % of the gamma range, blunt ones in the top
        20 % (paper).
    soft_h_max: soft heights uniform on [0, 0.2) Delta_max, anchored among themselves (paper).
    blunt_h_min, blunt_h_max: blunt heights uniform on (0.5, 1.0] Delta_max; 0.5 is the
        paper's bound, the upper end 1.0 (the design box) is our choice.
    soft_min, blunt_min: at least 1 soft and 1 blunt asperity; the number of soft ones is
        uniform on [soft_min, N - blunt_min] (our choice). With N = 1 the one asperity is soft.
    """

    gamma_fraction: float = 0.2
    soft_h_max: float = 0.2
    blunt_h_min: float = 0.5
    blunt_h_max: float = 1.0
    soft_min: int = 1
    blunt_min: int = 1

    def __post_init__(self) -> None:
        check_params(self)
        require(
            0 < self.gamma_fraction <= 0.5,
            self,
            f"gamma_fraction must be in (0, 0.5], got {self.gamma_fraction}",
        )
        require(
            0 < self.soft_h_max <= self.blunt_h_min < self.blunt_h_max,
            self,
            "need 0 < soft_h_max <= blunt_h_min < blunt_h_max, got "
            f"{self.soft_h_max}, {self.blunt_h_min}, {self.blunt_h_max}",
        )
        require(self.soft_min >= 1, self, f"soft_min must be >= 1, got {self.soft_min}")


def sample_bimodal(
    rng: np.random.Generator,
    count: int,
    settings: CellSettings,
    params: BimodalParams = BimodalParams(),
) -> tuple[np.ndarray, np.ndarray]:
    """Soft asperities (low gamma, h < 0.2 Delta_max) and blunt ones (high gamma, h > 0.5).

    Returns (gamma, h), both (count, N); every asperity is either soft or blunt.
    """
    n, dmax = settings.n_asperities, settings.delta_max
    band = params.gamma_fraction * (settings.gamma_max - settings.gamma_min)
    k = group_sizes(rng, count, params.soft_min, n - params.blunt_min, n)
    soft = first(k, n)
    gamma = np.where(
        soft,
        uniform(rng, settings.gamma_min, settings.gamma_min + band, (count, n)),
        uniform_above(rng, settings.gamma_max - band, settings.gamma_max, (count, n)),
    )
    h = np.where(
        soft,
        uniform(rng, 0.0, params.soft_h_max * dmax, (count, n)),
        uniform_above(rng, params.blunt_h_min * dmax, params.blunt_h_max * dmax, (count, n)),
    )
    return gamma, anchor_group(h, soft)


# -- (d) stratified heights -----------------------------------------------------------------


@dataclass(frozen=True)
class StratifiedParams:
    """A few asperities in the loading zone, the rest clustered near Delta_max (delayed contact).

    low_min, low_fraction: the number in the loading zone is uniform on
        [low_min, max(low_min, floor(low_fraction N))]; defaults 1 and 1/3 give 1 to 3 of 9
        ("a small fraction": our choice).
    split_h: loading-zone heights uniform on [0, 0.8) Delta_max, anchored among themselves;
        the rest uniform on [0.8, cluster_h_max) Delta_max, cluster_h_max = 1.0 (paper).
    """

    low_min: int = 1
    low_fraction: float = 1.0 / 3.0
    split_h: float = 0.8
    cluster_h_max: float = 1.0

    def __post_init__(self) -> None:
        check_params(self)
        require(self.low_min >= 1, self, f"low_min must be >= 1, got {self.low_min}")
        require(
            self.low_fraction <= 1,
            self,
            f"low_fraction must be in [0, 1], got {self.low_fraction}",
        )
        require(
            0 < self.split_h < self.cluster_h_max,
            self,
            f"need 0 < split_h < cluster_h_max, got {self.split_h}, {self.cluster_h_max}",
        )


def sample_stratified(
    rng: np.random.Generator,
    count: int,
    settings: CellSettings,
    params: StratifiedParams = StratifiedParams(),
) -> tuple[np.ndarray, np.ndarray]:
    """1 to 3 asperities at h < 0.8 Delta_max, the others clustered in [0.8, 1.0] Delta_max.

    Gammas uniform on [gamma_min, gamma_max). Returns (gamma, h), both (count, N).
    """
    n, dmax = settings.n_asperities, settings.delta_max
    gamma = full_gamma(rng, count, settings)
    high = max(params.low_min, math.floor(params.low_fraction * n + 1e-9))
    k = group_sizes(rng, count, params.low_min, high, n)
    low = first(k, n)
    h = np.where(
        low,
        uniform(rng, 0.0, params.split_h * dmax, (count, n)),
        uniform(rng, params.split_h * dmax, params.cluster_h_max * dmax, (count, n)),
    )
    return gamma, anchor_group(h, low)


# -- (e) coplanar arrays --------------------------------------------------------------------


@dataclass(frozen=True)
class CoplanarParams:
    """A dense subset engages (almost) at once: the flat-punch-like limit.

    all_probability: with probability 1/3 all N asperities are coplanar (our choice) ...
    min_count: ... otherwise the coplanar subset size is uniform on [4, N] (paper; clipped to
        N when N < 4).
    coplanar_h_max: coplanar heights uniform on [0, 0.01) Delta_max, anchored (paper).
    rest_h_max: the other asperities uniform on [0.01, 1.0) Delta_max (our choice: anywhere
        above the coplanar layer inside the loading range).
    Gammas uniform on [gamma_min, gamma_max).
    """

    all_probability: float = 1.0 / 3.0
    min_count: int = 4
    coplanar_h_max: float = 0.01
    rest_h_max: float = 1.0

    def __post_init__(self) -> None:
        check_params(self)
        require(
            self.all_probability <= 1,
            self,
            f"all_probability must be in [0, 1], got {self.all_probability}",
        )
        require(self.min_count >= 1, self, f"min_count must be >= 1, got {self.min_count}")
        require(
            0 < self.coplanar_h_max < self.rest_h_max,
            self,
            f"need 0 < coplanar_h_max < rest_h_max, got {self.coplanar_h_max}, {self.rest_h_max}",
        )


def sample_coplanar(
    rng: np.random.Generator,
    count: int,
    settings: CellSettings,
    params: CoplanarParams = CoplanarParams(),
) -> tuple[np.ndarray, np.ndarray]:
    """4 to N (or all N) asperities at h < 0.01 Delta_max, the rest above that layer.

    Returns (gamma, h), both (count, N).
    """
    n, dmax = settings.n_asperities, settings.delta_max
    gamma = full_gamma(rng, count, settings)
    k = np.where(
        rng.random(count) < params.all_probability,
        n,
        group_sizes(rng, count, params.min_count, n, n),
    )
    flat = first(k, n)
    h = np.where(
        flat,
        uniform(rng, 0.0, params.coplanar_h_max * dmax, (count, n)),
        uniform(rng, params.coplanar_h_max * dmax, params.rest_h_max * dmax, (count, n)),
    )
    return gamma, anchor_group(h, flat)


# -- (f) mixed stochastic depths ------------------------------------------------------------

MIXED_LAWS = ("uniform", "gaussian", "exponential")


@dataclass(frozen=True)
class MixedParams:
    """Depths from an evenly weighted mixture of uniform, Gaussian and exponential laws.

    weights: mixture weights of (uniform, Gaussian, exponential); (1/3, 1/3, 1/3) (paper).
    per_sample: True (default, our choice) draws one law per sample and all N depths from it,
        so the category holds whole uniform, clustered and front-loaded topographies; False
        draws the law per asperity.
    h_max: every law is truncated to [0, 1.0] Delta_max (the design box).
    gauss_mean, gauss_sd: Gaussian N(0.5, 0.2^2) Delta_max before truncation (our choice).
    exp_scale: exponential of scale 0.25 Delta_max before truncation (our choice).
    Truncation is exact (inverse CDF of the truncated law), not clipping. Gammas uniform on
    [gamma_min, gamma_max).
    """

    weights: tuple[float, float, float] = (1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0)
    per_sample: bool = True
    h_max: float = 1.0
    gauss_mean: float = 0.5
    gauss_sd: float = 0.2
    exp_scale: float = 0.25

    def __post_init__(self) -> None:
        check_params(self)
        w = tuple(float(x) for x in self.weights)
        require(
            len(w) == 3 and all(math.isfinite(x) and x >= 0 for x in w) and sum(w) > 0,
            self,
            f"weights must be 3 numbers >= 0 with a positive sum, got {self.weights}",
        )
        object.__setattr__(self, "weights", w)
        for name in ("h_max", "gauss_sd", "exp_scale"):
            require(getattr(self, name) > 0, self, f"{name} must be > 0")


def sample_mixed(
    rng: np.random.Generator,
    count: int,
    settings: CellSettings,
    params: MixedParams = MixedParams(),
) -> tuple[np.ndarray, np.ndarray]:
    """All N depths drawn from uniform, truncated Gaussian or truncated exponential laws.

    Returns (gamma, h), both (count, N), h in [0, h_max Delta_max] (anchoring is left to the
    dataset, like for the LHS).
    """
    n, dmax = settings.n_asperities, settings.delta_max
    gamma = full_gamma(rng, count, settings)
    w = np.asarray(params.weights) / sum(params.weights)
    law = rng.choice(3, size=(count, 1) if params.per_sample else (count, n), p=w)
    u = rng.random((count, n))
    high = params.h_max * dmax
    h = np.choose(
        law,
        [
            u * high,
            truncated_normal_ppf(u, params.gauss_mean * dmax, params.gauss_sd * dmax, high),
            truncated_exponential_ppf(u, params.exp_scale * dmax, high),
        ],
    )
    return gamma, np.clip(h, 0.0, high)


# -- the registry ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Category:
    """One generative category: stored name, sampler, default parameters, dataset share."""

    name: str
    label: str
    sampler: Sampler
    params: Any
    fraction: float


# Order matters: a category's index here is its seed stream (never reorder; append new ones).
CATEGORIES: tuple[Category, ...] = (
    Category("lhs", "LHS", sample_lhs, LHSParams(), 0.20),
    Category("truncated", "Truncated heights", sample_truncated, TruncatedParams(), 0.16),
    Category("bimodal", "Bimodal shapes", sample_bimodal, BimodalParams(), 0.16),
    Category("stratified", "Stratified heights", sample_stratified, StratifiedParams(), 0.16),
    Category("coplanar", "Coplanar arrays", sample_coplanar, CoplanarParams(), 0.16),
    Category("mixed", "Mixed stochastic", sample_mixed, MixedParams(), 0.16),
)

CATEGORY_NAMES: tuple[str, ...] = tuple(c.name for c in CATEGORIES)

# Panel order of the paper's fig. 3: (a) LHS, (b) mixed, (c) truncated, (d) bimodal,
# (e) coplanar, (f) stratified.
FIGURE_ORDER: tuple[str, ...] = ("lhs", "mixed", "truncated", "bimodal", "coplanar", "stratified")


def category(name: str) -> Category:
    """The category called ``name``; a one-line error listing the known names otherwise."""
    for c in CATEGORIES:
        if c.name == name:
            return c
    raise MetainterfaceError(
        f"unknown category {name!r}, expected one of {', '.join(CATEGORY_NAMES)}"
    )
