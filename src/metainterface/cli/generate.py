"""`metainterface generate`: the synthetic dataset of the six topography categories (.npz)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from metainterface.cli.common import add_device
from metainterface.errors import MetainterfaceError

_FIGURE_SUFFIXES = (".png", ".pdf", ".svg")  # what plots.save_figure writes


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "generate",
        help="synthetic dataset: six topography categories and their exact curves (.npz)",
        description="Sample S designs of the paper's six categories (LHS 20 %, truncated, "
        "bimodal, stratified, coplanar, mixed 16 % each), sort and anchor them, compute "
        "their exact normalised alpha(P*) curves and write one .npz with an 80/10/10 "
        "train/val/test split. The same seed gives the same arrays.",
    )
    # Numbers are read as text and checked in run(), so bad values give one-line errors.
    p.add_argument("--samples", required=True, metavar="N", help="number of samples S (> 0)")
    p.add_argument("--seed", required=True, metavar="S", help="random seed (integer >= 0)")
    p.add_argument("--out", required=True, metavar="FILE.npz", help="output dataset file")
    p.add_argument(
        "--n-asperities", default="9", metavar="N", help="asperities per cell (default 9)"
    )
    p.add_argument("--gamma-min", default="1.8", metavar="G", help="default 1.8 (> 1)")
    p.add_argument("--gamma-max", default="4.0", metavar="G", help="default 4.0")
    p.add_argument(
        "--delta-max", default="0.02", metavar="D", help="Delta_max in units of R (default 0.02)"
    )
    p.add_argument("--plot", metavar="FIG.png", help="also draw example curves per category")
    p.add_argument(
        "--chunk",
        metavar="K",
        help="samples processed at once (default 4096; memory only, results do not depend on it)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_device(p)
    p.set_defaults(func=run)


def _int(option: str, text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise MetainterfaceError(f"{option} must be a whole number, got {text!r}") from None


def _float(option: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise MetainterfaceError(f"{option} must be a number, got {text!r}") from None
    if not math.isfinite(value):
        raise MetainterfaceError(f"{option} must be finite, got {text!r}")
    return value


def run(args: argparse.Namespace) -> int:
    import metainterface as mi
    from metainterface.data import CATEGORIES, FIGURE_ORDER
    from metainterface.data.dataset import DEFAULT_CHUNK

    samples = _int("--samples", args.samples)
    if samples <= 0:
        raise MetainterfaceError(f"--samples must be > 0, got {samples}")
    seed = _int("--seed", args.seed)
    if seed < 0:
        raise MetainterfaceError(f"--seed must be >= 0, got {seed}")
    chunk = DEFAULT_CHUNK if args.chunk is None else _int("--chunk", args.chunk)
    if chunk <= 0:
        raise MetainterfaceError(f"--chunk must be > 0, got {chunk}")
    settings = mi.CellSettings(
        n_asperities=_int("--n-asperities", args.n_asperities),
        delta_max=_float("--delta-max", args.delta_max),
        gamma_min=_float("--gamma-min", args.gamma_min),
        gamma_max=_float("--gamma-max", args.gamma_max),
    )
    if args.plot is not None and Path(args.plot).suffix.lower() not in _FIGURE_SUFFIXES:
        raise MetainterfaceError(
            f"--plot {args.plot}: unknown suffix {Path(args.plot).suffix!r}, "
            f"use one of {', '.join(_FIGURE_SUFFIXES)}"
        )

    report = mi.generate_dataset(
        samples,
        args.out,
        seed=seed,
        settings=settings,
        progress=not args.quiet,
        chunk=chunk,
        device=args.device,
    )
    if args.plot is not None:
        from metainterface.plots import plot_dataset_examples, save_figure

        labels = {c.name: c.label for c in CATEGORIES}
        panels = {
            f"({chr(ord('a') + i)}) {labels[name]}": report.examples[name]
            for i, name in enumerate(name for name in FIGURE_ORDER if name in report.examples)
        }
        fig = plot_dataset_examples(
            panels, title=f"{samples} samples, seed {seed}: test-split examples"
        )
        save_figure(
            fig,
            args.plot,
            command="generate",
            dataset=str(args.out),
            samples=samples,
            seed=seed,
            cell=settings.to_dict(),
        )
    counts = ", ".join(f"{name} {n}" for name, n in report.counts.items())
    splits = "/".join(str(n) for n in report.split_counts.values())
    print(
        f"{args.out}: {samples} samples ({counts}), train/val/test {splits}, {report.seconds:.1f} s"
    )
    return 0
