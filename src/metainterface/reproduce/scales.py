"""How big a reproduction run is (full, quick, tiny), and what the paper states.

``PAPER`` holds the values the paper states, each with where it says so; they are the
reference column of results.md, never a result.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

from metainterface.errors import MetainterfaceError
from metainterface.inverse.refine import RefineSettings


@dataclass(frozen=True)
class Scale:
    """The sizes of one reproduction run.

    regenerate_limit: regenerate the shipped model's own training dataset (samples and seed
        from its model file) when it has at most this many samples; else a fresh dataset of
        ``samples`` samples with ``seed`` (its train split is not the model's).
    test_per_category / gap_train_per_category: test rows evaluated and train rows of the
        train/test loss gap, per category (None: all of them).
    train_per_category, val_per_category, epochs, batch_size: the small training run of fig. 4.
    starts, refine: random starts of the baselines and the refinement of every method (fig. 5).
    bem_grid (None: 256 n, the paper's 768 for N = 9), bem_loads, bem_tolerance, bem_jobs
    (None: the available cores), bem_target (fig. 6), bem_categories (appendix D).
    """

    name: str
    regenerate_limit: int
    samples: int
    seed: int
    test_per_category: int | None
    gap_train_per_category: int | None
    train_per_category: int
    val_per_category: int
    epochs: int
    batch_size: int
    starts: int
    refine: RefineSettings = field(default_factory=RefineSettings)
    bem_grid: int | None = None
    bem_loads: int = 20
    bem_tolerance: float = 1e-11
    bem_jobs: int | None = None
    bem_target: str = "bilinear"
    bem_categories: tuple[str, ...] = ("coplanar", "mixed", "stratified")
    wall_category: str = "lhs"
    kappa_category: str = "bimodal"

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


SCALES: dict[str, Scale] = {
    # the paper's settings where a 2-core machine allows it (within an hour)
    "full": Scale(
        name="full",
        regenerate_limit=200_000,
        samples=100_000,
        seed=1,
        test_per_category=None,
        gap_train_per_category=None,
        train_per_category=2000,
        val_per_category=300,
        epochs=40,
        batch_size=512,
        starts=50,
    ),
    # a smaller BEM grid, fewer loads, test samples, epochs and starts (a few minutes)
    "quick": Scale(
        name="quick",
        regenerate_limit=200_000,
        samples=20_000,
        seed=1,
        test_per_category=250,
        gap_train_per_category=2000,
        train_per_category=600,
        val_per_category=100,
        epochs=20,
        batch_size=256,
        starts=10,
        bem_grid=384,
        bem_loads=8,
    ),
    # for the test suite: every stage and file in seconds, numbers meaningless
    "tiny": Scale(
        name="tiny",
        regenerate_limit=0,
        samples=240,
        seed=1,
        test_per_category=None,
        gap_train_per_category=None,
        train_per_category=12,
        val_per_category=3,
        epochs=2,
        batch_size=24,
        starts=2,
        # a short polish and no re-seeded starts: the stages' code runs, in a third of the time
        refine=RefineSettings(
            stages=1, steps_per_stage=1, iterations=3, polish_iterations=10, reseed=False
        ),
        bem_grid=24,
        bem_loads=2,
        bem_tolerance=1e-9,
        bem_jobs=1,
        bem_categories=("mixed",),
    ),
}


def get_scale(scale: str | Scale | None, quick: bool = False) -> Scale:
    """A Scale by name (or as given); None means quick or full by ``quick``."""
    if isinstance(scale, Scale):
        return scale
    name = scale or ("quick" if quick else "full")
    try:
        return SCALES[name]
    except KeyError:
        raise MetainterfaceError(
            f"unknown scale {name!r}; choose one of {', '.join(SCALES)}"
        ) from None


#: What the paper states: key -> (value, where and what).
PAPER: dict[str, tuple[Any, str]] = {
    "dataset_samples": (100_000, "sec. 3.1: 100,000 synthetic topographies"),
    "epochs": (500, "sec. 3.2: 500 epochs, early stopping with 50 epochs patience"),
    "train_test_gap": (0.04, "sec. 3.2: final training and test loss differ by < 4 %"),
    "kappa_gain": (0.03, "sec. 3.2: the kappa schedule improves the validation loss by < 3 %"),
    "starts": (50, "sec. 4: multi-start optimisation with 50 random initialisations"),
    "refine": ((5, 5, 20), "app. C: 5 stages x 5 L-BFGS steps x 20 iterations"),
    "bem_max_rel_err": (0.03, "sec. 4.1: maximum relative error of BEM vs model < 3 %"),
    "model_error": (0.05, "sec. 2.2: the superposition holds with < 5 % error against BEM"),
    "bem_grid": (768, "sec. 4.1: 768 x 768 grid, 64 points per a_max"),
    "bem_tolerance": (1e-11, "sec. 4.1: Polonsky-Keer-Rey tolerance 1e-11"),
    "local_pressure": (0.1, "sec. 4.1: sharp asperities (gamma < 2) reach p_local/E* ~ 0.1"),
}
