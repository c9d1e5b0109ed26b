"""The dataset file: counts, split, determinism, arrays and meta, curves, loader errors."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest
import torch

import metainterface
from metainterface.data import _stream as stream_module
from metainterface.data import allocate, generate_dataset, load_dataset, split_counts
from metainterface.errors import MetainterfaceError
from metainterface.physics import CellSettings
from metainterface.physics.sneddon import area, force

SAMPLES, SEED = 1200, 7  # as in conftest.py

ROW_ARRAYS = (
    "gamma",
    "h",
    "category",
    "split",
    "p_star_max",
    "alpha_max",
    "alpha_hat",
    "stiffness_hat",
)


def test_category_counts_are_20_and_16_percent(dataset):
    names, counts = np.unique(dataset.category, return_counts=True)
    got = dict(zip(names, counts, strict=True))
    assert got == {
        "lhs": 240,
        "truncated": 192,
        "bimodal": 192,
        "stratified": 192,
        "coplanar": 192,
        "mixed": 192,
    }


def test_allocate_sums_to_total_and_rounds_to_nearest():
    for total in (1, 7, 99, 1000, 123457):
        counts = allocate(total, [0.2, 0.16, 0.16, 0.16, 0.16, 0.16])
        assert counts.sum() == total
        assert np.all(np.abs(counts - total * np.array([0.2] + [0.16] * 5)) < 1)


def test_split_is_80_10_10_overall_and_per_category(dataset):
    assert [(dataset.split == s).sum() for s in ("train", "val", "test")] == [960, 120, 120]
    for name in np.unique(dataset.category):
        sub = dataset.split[dataset.category == name]
        for s, share in (("train", 0.8), ("val", 0.1), ("test", 0.1)):
            assert abs((sub == s).sum() - share * sub.size) <= 1


def test_split_counts_for_any_size():
    for total in (1, 10, 11, 99, 1001):
        per = split_counts(allocate(total, [0.2] + [0.16] * 5))
        assert per.min() >= 0 and per.sum() == total
        assert per.sum(axis=0)[1] == (total + 5) // 10 and per.sum(axis=0)[2] == total // 10


def test_split_is_shuffled_within_categories(dataset):
    lhs = dataset.split[dataset.category == "lhs"]
    assert not np.all(lhs[: lhs.size * 8 // 10] == "train")


# the fixture used chunk 250, block 97 and the default workers
@pytest.mark.parametrize(("chunk", "workers"), [(60, 1), (10_000, 3)])
def test_same_seed_same_arrays_whatever_the_chunk(tmp_path, settings, dataset, chunk, workers):
    path = tmp_path / "again.npz"
    generate_dataset(
        SAMPLES, SEED, settings, path, progress=False, chunk=chunk, block=97, workers=workers
    )
    again = load_dataset(path)
    for name in ROW_ARRAYS:
        np.testing.assert_array_equal(getattr(again, name), getattr(dataset, name), err_msg=name)


def test_other_seed_other_arrays(tmp_path, settings, dataset):
    path = tmp_path / "other.npz"
    generate_dataset(SAMPLES, SEED + 1, settings, path, progress=False, chunk=250, block=97)
    assert not np.array_equal(load_dataset(path).gamma, dataset.gamma)


def test_file_holds_the_named_arrays_and_meta(dataset_path, settings):
    with np.load(dataset_path, allow_pickle=False) as npz:
        assert set(npz.files) == {*ROW_ARRAYS, "meta"}
        s, n, k = SAMPLES, settings.n_asperities, settings.n_steps
        assert npz["gamma"].shape == npz["h"].shape == (s, n)
        assert npz["category"].shape == npz["split"].shape == (s,)
        assert npz["p_star_max"].shape == npz["alpha_max"].shape == (s,)
        assert npz["alpha_hat"].shape == npz["stiffness_hat"].shape == (s, k)
        assert npz["category"].dtype.kind == npz["split"].dtype.kind == "U"
        meta = json.loads(str(npz["meta"]))
    assert meta["package"] == "metainterface"
    assert meta["version"] == metainterface.__version__
    recorded = meta["settings"]
    assert recorded["seed"] == SEED and recorded["samples"] == SAMPLES
    assert recorded["block"] == 97
    assert recorded["cell"] == settings.to_dict()
    assert recorded["categories"]["truncated"]["params"]["inactive_h_min"] == 1.1
    assert recorded["splits"]["counts"] == {"train": 960, "val": 120, "test": 120}
    with zipfile.ZipFile(dataset_path) as zf:
        assert zf.testzip() is None  # every entry's CRC-32 checks out


def test_curves_are_normalised(dataset):
    a = dataset.alpha_hat
    assert np.all(a[:, 0] == 0)
    np.testing.assert_allclose(a[:, -1], 1.0, rtol=1e-5)
    assert np.all(np.diff(a, axis=1) >= -1e-6)
    assert np.all(dataset.p_star_max > 0) and np.all(dataset.alpha_max > 0)
    assert np.all(dataset.stiffness_hat >= 0)


def test_maxima_are_sneddon_sums_at_delta_max(dataset, settings):
    rows = np.arange(0, len(dataset), 37)
    gamma = torch.as_tensor(dataset.gamma[rows], dtype=torch.float64)
    delta = settings.delta_max - torch.as_tensor(dataset.h[rows], dtype=torch.float64)
    f = force(gamma, delta, settings.radius).sum(-1).numpy()
    a = area(gamma, delta, settings.radius).sum(-1).numpy()
    np.testing.assert_allclose(dataset.p_star_max[rows], f / settings.nominal_area, rtol=1e-4)
    np.testing.assert_allclose(dataset.alpha_max[rows], a / settings.nominal_area, rtol=1e-4)


def test_subset_by_split_and_category(dataset):
    train = dataset.subset("train")
    assert len(train) == 960 and np.all(train.split == "train")
    test_lhs = dataset.subset("test", category="lhs")
    assert len(test_lhs) == 24 and np.all(test_lhs.category == "lhs")
    assert test_lhs.alpha_hat.shape == (24, dataset.settings.n_steps)
    with pytest.raises(MetainterfaceError, match="'dev'"):
        dataset.subset("dev")
    with pytest.raises(MetainterfaceError, match="'flat'"):
        dataset.subset(category="flat")


def test_generation_failure_leaves_no_file(tmp_path, settings, monkeypatch):
    calls = []

    def broken(*args, **kwargs):
        calls.append(1)
        if len(calls) > 1:
            raise RuntimeError("boom")
        return curves_numpy(*args, **kwargs)

    curves_numpy = stream_module.curves_numpy
    monkeypatch.setattr(stream_module, "curves_numpy", broken)
    with pytest.raises(RuntimeError, match="boom"):
        generate_dataset(300, 1, settings, tmp_path / "x.npz", progress=False, chunk=100)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("kwargs", "word"),
    [
        ({"samples": 0}, "samples"),
        ({"samples": 2.5}, "samples"),
        ({"seed": -1}, "seed"),
        ({"chunk": 0}, "chunk"),
        ({"params": {"flat": None}}, "flat"),
        ({"params": {"truncated": None}}, "TruncatedParams"),
    ],
)
def test_generate_rejects_bad_arguments(tmp_path, settings, kwargs, word):
    args = {"samples": 10, "seed": 0, "settings": settings, "out": tmp_path / "x.npz"}
    args.update(kwargs)
    with pytest.raises(MetainterfaceError, match=word):
        generate_dataset(**args, progress=False)
    assert list(tmp_path.iterdir()) == []


# -- loader errors ------------------------------------------------------------------------


def _copy_without(src, dst, drop=(), replace=None):
    with np.load(src, allow_pickle=False) as npz:
        arrays = {k: npz[k] for k in npz.files if k not in drop}
    arrays.update(replace or {})
    np.savez(dst, **arrays)
    return dst


def test_load_missing_file(tmp_path):
    with pytest.raises(MetainterfaceError, match="file not found"):
        load_dataset(tmp_path / "nope.npz")


def test_load_not_a_npz(tmp_path):
    path = tmp_path / "text.npz"
    path.write_text("hello")
    with pytest.raises(MetainterfaceError, match=r"not a \.npz dataset"):
        load_dataset(path)


def test_load_names_the_missing_arrays(tmp_path, dataset_path):
    path = _copy_without(dataset_path, tmp_path / "d.npz", drop=("alpha_hat", "split"))
    with pytest.raises(MetainterfaceError, match="missing array\\(s\\) split, alpha_hat"):
        load_dataset(path)


def test_load_names_the_different_settings(dataset_path):
    other = CellSettings(delta_max=0.03, gamma_max=3.5)
    with pytest.raises(MetainterfaceError) as err:
        load_dataset(dataset_path, other)
    text = str(err.value)
    assert "\n" not in text
    assert "delta_max is 0.02 in the file, expected 0.03" in text
    assert "gamma_max is 4.0 in the file, expected 3.5" in text


def test_load_rejects_a_wrong_shape(tmp_path, dataset_path):
    with np.load(dataset_path) as npz:
        short = npz["alpha_hat"][:, :64]
    path = _copy_without(dataset_path, tmp_path / "d.npz", replace={"alpha_hat": short})
    with pytest.raises(MetainterfaceError, match="alpha_hat has shape"):
        load_dataset(path)


def test_load_rejects_unknown_split_labels(tmp_path, dataset_path):
    with np.load(dataset_path) as npz:
        split = npz["split"].copy()
    split[0] = "dev"
    path = _copy_without(dataset_path, tmp_path / "d.npz", replace={"split": split})
    with pytest.raises(MetainterfaceError, match="'dev'"):
        load_dataset(path)


def test_load_rejects_meta_without_settings(tmp_path, dataset_path):
    meta = np.array(json.dumps({"version": "0"}))
    path = _copy_without(dataset_path, tmp_path / "d.npz", replace={"meta": meta})
    with pytest.raises(MetainterfaceError, match="meta"):
        load_dataset(path)
