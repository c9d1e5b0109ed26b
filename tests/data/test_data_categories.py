"""Each category's samples obey the rules of paper sec. 2.4 (checked on the written dataset)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import special

from metainterface.data import (
    CATEGORIES,
    CATEGORY_NAMES,
    MixedParams,
    TruncatedParams,
    sample_lhs,
    sample_mixed,
)
from metainterface.errors import MetainterfaceError
from metainterface.physics import CellSettings


def _rows(dataset, name):
    sub = dataset.subset(category=name)
    assert len(sub) > 0
    return sub.gamma, sub.h / sub.settings.delta_max, sub.settings


def test_every_sample_sorted_anchored_and_in_gamma_bounds(dataset, settings):
    assert np.all(np.diff(dataset.h, axis=1) >= 0)
    assert np.all(dataset.h[:, 0] == 0.0)
    assert dataset.gamma.min() >= settings.gamma_min
    assert dataset.gamma.max() <= settings.gamma_max


def test_lhs_puts_one_point_in_every_stratum_of_every_axis(settings):
    count = 200
    gamma, h = sample_lhs(np.random.default_rng(1), count, settings)
    span = settings.gamma_max - settings.gamma_min
    unit = np.hstack([(gamma - settings.gamma_min) / span, h / settings.delta_max])
    strata = np.floor(unit * count).astype(int)
    for column in strata.T:
        assert sorted(column) == list(range(count))


def test_lhs_rows_of_dataset_stay_in_the_design_box(dataset):
    _, h, _ = _rows(dataset, "lhs")
    assert h.max() <= 1.0


def test_truncated_one_to_three_active_rest_beyond_reach(dataset):
    _, h, _ = _rows(dataset, "truncated")
    active = h < 1.0
    n_active = active.sum(axis=1)
    assert set(np.unique(n_active)) == {1, 2, 3}
    assert np.all(h[~active] > 1.1)
    # sorted: the active ones come first
    assert np.all(active == (np.arange(h.shape[1]) < n_active[:, None]))


def test_bimodal_soft_shallow_and_blunt_deep(dataset):
    gamma, h, s = _rows(dataset, "bimodal")
    band = 0.2 * (s.gamma_max - s.gamma_min)
    soft = (gamma <= s.gamma_min + band) & (h < 0.2)
    blunt = (gamma >= s.gamma_max - band) & (h > 0.5) & (h <= 1.0)
    assert np.all(soft | blunt)
    assert np.all(soft.sum(axis=1) >= 1)
    assert np.all(blunt.sum(axis=1) >= 1)


def test_stratified_few_in_loading_zone_rest_clustered(dataset):
    _, h, _ = _rows(dataset, "stratified")
    low = h < 0.8
    assert set(np.unique(low.sum(axis=1))) == {1, 2, 3}
    assert np.all((h[~low] >= 0.8) & (h[~low] <= 1.0))


def test_coplanar_dense_flat_subset(dataset):
    _, h, s = _rows(dataset, "coplanar")
    flat = h < 0.01
    n_flat = flat.sum(axis=1)
    assert n_flat.min() >= 4
    assert np.any(n_flat == s.n_asperities)
    assert np.any(n_flat < s.n_asperities)
    assert np.all((h[~flat] >= 0.01) & (h[~flat] <= 1.0))


def test_mixed_depths_inside_the_design_box(dataset):
    _, h, _ = _rows(dataset, "mixed")
    assert h.max() <= 1.0


def _truncnorm_mean(mu, sd, high):
    a, b = (0 - mu) / sd, (high - mu) / sd
    phi = lambda x: math.exp(-x * x / 2) / math.sqrt(2 * math.pi)  # noqa: E731
    return mu + sd * (phi(a) - phi(b)) / (special.ndtr(b) - special.ndtr(a))


def _truncexp_mean(scale, high):
    return scale - high * math.exp(-high / scale) / (1 - math.exp(-high / scale))


@pytest.mark.parametrize(
    ("weights", "mean"),
    [
        ((1, 0, 0), 0.5),
        ((0, 1, 0), _truncnorm_mean(0.5, 0.2, 1.0)),
        ((0, 0, 1), _truncexp_mean(0.25, 1.0)),
    ],
)
def test_mixed_laws_have_their_truncated_means(weights, mean):
    s = CellSettings(delta_max=0.02)
    _, h = sample_mixed(np.random.default_rng(3), 4000, s, MixedParams(weights=weights))
    x = h.ravel() / s.delta_max
    assert x.min() >= 0 and x.max() <= 1
    assert abs(x.mean() - mean) < 5 * x.std() / math.sqrt(x.size)


def test_mixed_per_sample_draws_one_law_per_sample():
    s = CellSettings()
    p = MixedParams(weights=(0.5, 0.0, 0.5))
    _, h = sample_mixed(np.random.default_rng(4), 3000, s, p)
    # an exponential(0.25) row rarely has a mean above 0.4, a uniform row rarely below it:
    # one law per row makes the row means bimodal, a per-asperity mixture would not
    means = h.mean(axis=1) / s.delta_max
    assert np.mean(means < 0.3) > 0.35 and np.mean(means > 0.4) > 0.35


def test_category_table_matches_the_paper():
    assert CATEGORY_NAMES == ("lhs", "truncated", "bimodal", "stratified", "coplanar", "mixed")
    assert [c.fraction for c in CATEGORIES] == [0.20, 0.16, 0.16, 0.16, 0.16, 0.16]


def test_bad_category_parameters_name_the_field():
    with pytest.raises(MetainterfaceError, match="inactive_h_min"):
        TruncatedParams(inactive_h_min=0.9)
    with pytest.raises(MetainterfaceError, match="weights"):
        MixedParams(weights=(0, 0, 0))


@pytest.mark.parametrize("n", [1, 4, 16])
def test_samplers_respect_other_cell_sizes(n):
    s = CellSettings(n_asperities=n)
    for c in CATEGORIES:
        gamma, h = c.sampler(np.random.default_rng(0), 50, s, c.params)
        assert gamma.shape == h.shape == (50, n)
        assert np.all(h >= 0) and np.all(np.isfinite(h))
        assert gamma.min() >= s.gamma_min and gamma.max() <= s.gamma_max
