"""A small dataset shared by the data tests (generated once per session)."""

from __future__ import annotations

import pytest

from metainterface.data import Dataset, generate_dataset, load_dataset
from metainterface.physics import CellSettings

SAMPLES = 1200
SEED = 7


@pytest.fixture(scope="session")
def settings() -> CellSettings:
    return CellSettings()


@pytest.fixture(scope="session")
def dataset_path(tmp_path_factory, settings):
    path = tmp_path_factory.mktemp("dataset") / "small.npz"
    # Small blocks and an unrelated chunk size, so blocks and chunks straddle each other.
    generate_dataset(SAMPLES, SEED, settings, path, progress=False, chunk=250, block=97)
    return path


@pytest.fixture(scope="session")
def dataset(dataset_path, settings) -> Dataset:
    return load_dataset(dataset_path, settings)
