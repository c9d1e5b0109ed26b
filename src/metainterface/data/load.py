"""The dataset file's format (its arrays and splits; see ``metainterface.data.dataset``) and
reading it back: ``load_dataset`` checks a file whole and returns a ``Dataset``."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any

import numpy as np

from metainterface.data.categories import CATEGORY_NAMES
from metainterface.data.categories import category as find_category
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings

FORMAT = "metainterface/dataset-v1"
SPLITS: tuple[str, ...] = ("train", "val", "test")
SPLIT_FRACTIONS: tuple[float, ...] = (0.8, 0.1, 0.1)  # implemented by split_counts
ARRAYS: tuple[str, ...] = (
    "gamma",
    "h",
    "category",
    "split",
    "p_star_max",
    "alpha_max",
    "alpha_hat",
    "stiffness_hat",
    "meta",
)
CURVE_ARRAYS = ("p_star_max", "alpha_max", "alpha_hat", "stiffness_hat")


@dataclass(frozen=True)
class Dataset:
    """A loaded dataset: the arrays of the file (see ``data.dataset``), its settings, meta.

    S samples; gamma, h (S, N); category, split (S,) str; p_star_max, alpha_max (S,);
    alpha_hat, stiffness_hat (S, n_steps). ``subset`` selects rows by split and/or category.
    """

    gamma: np.ndarray
    h: np.ndarray
    category: np.ndarray
    split: np.ndarray
    p_star_max: np.ndarray
    alpha_max: np.ndarray
    alpha_hat: np.ndarray
    stiffness_hat: np.ndarray
    settings: CellSettings
    meta: dict[str, Any] = field(repr=False)
    path: Path | None = None

    def __len__(self) -> int:
        return int(self.gamma.shape[0])

    @property
    def seed(self) -> int:
        return int(self.meta["settings"]["seed"])

    def subset(self, split: str | None = None, *, category: str | None = None) -> Dataset:
        """The rows of one split ('train', 'val' or 'test') and/or one category, in file order."""
        keep = np.ones(len(self), dtype=bool)
        if split is not None:
            if split not in SPLITS:
                raise MetainterfaceError(
                    f"unknown split {split!r}, expected one of {', '.join(SPLITS)}"
                )
            keep &= self.split == split
        if category is not None:
            keep &= self.category == find_category(category).name
        return replace(self, **{name: getattr(self, name)[keep] for name in _ROW_ARRAYS})


_ROW_ARRAYS = tuple(name for name in ARRAYS if name != "meta")


def load_dataset(path: str | os.PathLike[str], settings: CellSettings | None = None) -> Dataset:
    """Read and check a dataset file; with ``settings``, the file's cell must equal them.

    Raises a one-line MetainterfaceError naming the file and what is missing, malformed or
    different (each differing setting with both values).
    """
    path = Path(path)
    if not path.is_file():
        raise MetainterfaceError(f"{path}: file not found")
    try:
        with path.open("rb") as fh:
            magic = fh.read(4)
    except OSError as exc:
        raise MetainterfaceError(f"{path}: cannot read ({exc.strerror})") from None
    if magic != b"PK\x03\x04":  # np.load would try .npy and pickle content next
        raise MetainterfaceError(
            f"{path}: not a .npz dataset (not a zip archive); make one with "
            "`metainterface generate`"
        )
    try:
        with np.load(path, allow_pickle=False) as npz:
            missing = [name for name in ARRAYS if name not in npz.files]
            if missing:
                raise MetainterfaceError(
                    f"{path}: missing array(s) {', '.join(missing)} "
                    f"(a dataset holds {', '.join(ARRAYS)})"
                )
            arrays = {name: npz[name] for name in ARRAYS}
    except MetainterfaceError:
        raise
    except Exception as exc:  # zipfile.BadZipFile, ValueError, OSError, ...
        first = " ".join(str(exc).split())[:120] or type(exc).__name__
        raise MetainterfaceError(f"{path}: not a readable .npz dataset ({first})") from None

    try:
        meta = json.loads(str(arrays.pop("meta")[()]))
        recorded = meta["settings"]
        cell = recorded["cell"]
    except (json.JSONDecodeError, KeyError, TypeError, IndexError):
        raise MetainterfaceError(
            f"{path}: meta is not a dataset record (no cell settings)"
        ) from None
    if recorded.get("format") != FORMAT:
        raise MetainterfaceError(
            f"{path}: meta format is {recorded.get('format')!r}, expected {FORMAT!r}"
        )
    try:
        file_settings = CellSettings(**cell)
    except (MetainterfaceError, TypeError) as exc:
        raise MetainterfaceError(f"{path}: meta has invalid cell settings: {exc}") from None

    s = arrays["gamma"].shape[0] if arrays["gamma"].ndim else -1
    n, steps = file_settings.n_asperities, file_settings.n_steps
    expected = {
        "gamma": (s, n),
        "h": (s, n),
        "category": (s,),
        "split": (s,),
        "p_star_max": (s,),
        "alpha_max": (s,),
        "alpha_hat": (s, steps),
        "stiffness_hat": (s, steps),
    }
    for name, shape in expected.items():
        if arrays[name].shape != shape:
            raise MetainterfaceError(
                f"{path}: array {name} has shape {arrays[name].shape}, expected {shape} "
                f"(N = {n}, n_steps = {steps})"
            )
    for name, allowed in (("category", CATEGORY_NAMES), ("split", SPLITS)):
        bad = np.setdiff1d(np.unique(arrays[name]), allowed)
        if bad.size:
            raise MetainterfaceError(
                f"{path}: array {name} holds unknown value {str(bad[0])!r}, "
                f"expected {', '.join(allowed)}"
            )

    for name in ("gamma", "h", *CURVE_ARRAYS):
        if arrays[name].dtype.kind not in "fiu":
            raise MetainterfaceError(f"{path}: array {name} is not numeric")
        bad = ~np.isfinite(arrays[name])
        if name in ("p_star_max", "alpha_max"):
            bad |= ~(arrays[name] > 0)
        if bad.any():
            row = int(np.flatnonzero(bad.reshape(s, -1).any(axis=1))[0])
            raise MetainterfaceError(
                f"{path}: row {row} of {name} is not a finite"
                f"{' positive' if name in ('p_star_max', 'alpha_max') else ''} number; "
                "the dataset cannot be used"
            )

    if settings is not None:
        diffs = [
            f"{f.name} is {getattr(file_settings, f.name)!r} in the file, expected "
            f"{getattr(settings, f.name)!r}"
            for f in fields(CellSettings)
            if getattr(file_settings, f.name) != getattr(settings, f.name)
        ]
        if diffs:
            raise MetainterfaceError(f"{path}: settings differ: {'; '.join(diffs)}")

    return Dataset(**arrays, settings=file_settings, meta=meta, path=path)
