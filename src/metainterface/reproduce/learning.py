"""The stages of a reproduction run that learn: the dataset, the shipped surrogate's test-set
reconstructions (fig. 3) and the wall case, and the training dynamics (fig. 4)."""

from __future__ import annotations

from dataclasses import fields, replace
from typing import Any

import numpy as np
import torch

from metainterface.data import generate_dataset, load_dataset
from metainterface.data.load import Dataset
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings
from metainterface.physics.curves import curve, sweep
from metainterface.plots import plot_reconstructions, plot_training
from metainterface.reproduce.context import Context, model_label, pct
from metainterface.reproduce.figures import plot_regularisation, plot_wall_case
from metainterface.surrogate.checkpoint import load_model
from metainterface.surrogate.config import TrainConfig
from metainterface.surrogate.data import split_of
from metainterface.surrogate.evaluate import Predictions, evaluate, predict_split
from metainterface.surrogate.loss import weights_of
from metainterface.surrogate.run_state import read_metrics
from metainterface.surrogate.train import train

# -- the dataset, fig. 3 and the wall case --------------------------------------------------


def _rows(ds: Dataset, keep: np.ndarray) -> Dataset:
    n = len(ds)
    arrays = {
        f.name: getattr(ds, f.name)[keep]
        for f in fields(ds)
        if isinstance(getattr(ds, f.name), np.ndarray) and getattr(ds, f.name).shape[:1] == (n,)
    }
    return replace(ds, **arrays)


def per_category(ds: Dataset, split: str, count: int | None) -> Dataset:
    """The rows of ``split``, at most ``count`` per category (the first ones in file order)."""
    sub = ds.subset(split)
    if count is None:
        return sub
    keep = np.zeros(len(sub), dtype=bool)
    for name in np.unique(sub.category):
        keep[np.flatnonzero(sub.category == name)[:count]] = True
    return _rows(sub, keep)


def median_row(pred: Predictions, category: str) -> int | None:
    """The test row of ``category`` whose zero-shot curve error is the median (None if none)."""
    rows = np.flatnonzero(pred.category == category)
    if rows.size == 0:
        return None
    order = np.argsort(pred.curve_error[rows], kind="stable")
    return int(rows[order[(rows.size - 1) // 2]])


def _representative(pred: Predictions, category: str) -> tuple[str, int]:
    """The median row of ``category``, or of the first category that has test rows."""
    for name in (category, *sorted(set(pred.category.tolist()))):
        row = median_row(pred, name)
        if row is not None:
            return name, row
    raise MetainterfaceError("the test split is empty")


def _dataset(ctx: Context, settings: CellSettings, config: dict[str, Any]) -> dict[str, Any]:
    info = config.get("dataset") or {}
    samples, seed = info.get("samples"), info.get("seed")
    own = (
        isinstance(samples, int)
        and isinstance(seed, int)
        and 0 < samples <= ctx.scale.regenerate_limit
    )
    if not own:
        samples, seed = ctx.scale.samples, ctx.scale.seed
    path = ctx.work / f"dataset-{samples}-{seed}.npz"
    reused = False
    if path.is_file():
        try:
            ds = load_dataset(path, settings)
            reused = ds.seed == seed and len(ds) == samples
        except MetainterfaceError:
            reused = False
    if not reused:
        generate_dataset(samples, seed, settings, path, progress=ctx.progress)
        ds = load_dataset(path, settings)
    return {"dataset": ds, "samples": samples, "seed": seed, "own": own}


def clip_gamma(gamma: np.ndarray, settings: CellSettings) -> np.ndarray:
    # predictions are float32 sigmoids: keep them inside the bounds Design checks
    return np.clip(gamma, settings.gamma_min, settings.gamma_max)


def _exact(gamma: np.ndarray, h: np.ndarray, settings: CellSettings) -> dict[str, np.ndarray]:
    sw = sweep(
        torch.as_tensor(gamma, dtype=torch.float64)[None],
        torch.as_tensor(h, dtype=torch.float64)[None],
        settings,
        n_delta=512,
    )
    return {
        "p_star": sw.p_star[0].numpy(),
        "alpha": sw.alpha[0].numpy(),
        "stiffness": sw.stiffness[0].numpy(),
        "gamma": np.asarray(gamma, dtype=np.float64),
        "h": np.asarray(h, dtype=np.float64),
    }


def stage_fig3(ctx: Context) -> dict[str, Any]:
    """Zero-shot reconstructions of the shipped surrogate on a test split (fig. 3), its
    per-category errors and train/test loss gap, and the wall case."""
    model, settings, config = load_model(ctx.model_path)
    data = _dataset(ctx, settings, config)
    ds = data["dataset"]
    test_ds = per_category(ds, "test", ctx.scale.test_per_category)
    gap_ds = per_category(ds, "train", ctx.scale.gap_train_per_category)
    test = split_of(test_ds, "test")
    result = evaluate(model, split_of(gap_ds, "train"), test, settings, weights_of(config))
    pred = predict_split(model, test, settings)
    ctx.data.update(settings=settings, dataset=ds, test=test_ds, pred=pred, model_config=config)

    rows = result["categories"]
    worst = max((r["median_curve_error"], k) for k, r in rows.items() if k != "all")
    source = (
        f"the test split of the model's own training dataset, regenerated ({data['samples']} "
        f"samples, seed {data['seed']}), held out from its training"
        if data["own"]
        else f"the test split of a fresh dataset ({data['samples']} samples, seed "
        f"{data['seed']}); the model's own training data was not regenerated"
    )
    ctx.save(
        "fig3_reconstructions",
        plot_reconstructions(test_ds, pred, settings),
        "Paper fig. 3 (fig:dataset). Test curves alpha(P*) (solid black) and the exact curves "
        "of the shipped surrogate's zero-shot designs (dashed), three per topography category: "
        "(a) LHS, (b) mixed, (c) truncated, (d) bimodal, (e) coplanar, (f) stratified. Test "
        f"rows: {source}; {len(test_ds)} evaluated. Median relative curve error over all "
        f"categories {pct(rows['all']['median_curve_error'])}; worst category median "
        f"{pct(worst[0])} ({worst[1]}).",
        model=str(ctx.model_path),
    )

    cat, i = _representative(pred, ctx.scale.wall_category)
    truth = _exact(test_ds.gamma[i], test_ds.h[i], settings)
    guess = _exact(clip_gamma(pred.gamma[i], settings), pred.h[i], settings)
    err = float(pred.curve_error[i])
    ctx.save(
        "wall_case",
        plot_wall_case(
            truth, guess, settings.delta_max, f"{cat} test design #{i}: curve error {pct(err)}"
        ),
        "Paper 'wall case' figure (fig:wall_case). One test design (the median-error one of "
        f"the {cat} category, test row {i}) against the shipped surrogate's zero-shot "
        "prediction: (a) alpha(P*) and (c) S*(P*) of both (exact forward model), (b) height "
        "offsets h/Delta_max and (d) shape exponents gamma per asperity (sorted by height). "
        f"Relative curve error {pct(err)}; the parameters differ by up to "
        f"{np.max(np.abs(truth['gamma'] - guess['gamma'])):.2f} in gamma and "
        f"{np.max(np.abs(truth['h'] - guess['h'])) / settings.delta_max:.2f} Delta_max in h.",
    )
    wall = {
        "category": cat,
        "row": i,
        "curve_error": err,
        "gamma_true": truth["gamma"].tolist(),
        "gamma_pred": guess["gamma"].tolist(),
        "h_true": (truth["h"] / settings.delta_max).tolist(),
        "h_pred": (guess["h"] / settings.delta_max).tolist(),
        "p_star_max_true": float(truth["p_star"][-1]),
        "p_star_max_pred": float(guess["p_star"][-1]),
        "alpha_max_true": float(truth["alpha"][-1]),
        "alpha_max_pred": float(guess["alpha"][-1]),
    }
    return {
        "dataset": {k: data[k] for k in ("samples", "seed", "own")},
        "test_rows": len(test_ds),
        "gap_train_rows": len(gap_ds),
        "model": {
            "path": model_label(ctx.model_path),
            "train": config.get("train", {}),
            "epoch": config.get("epoch"),
            "val_loss": config.get("val_loss"),
        },
        "evaluation": result,
        "wall_case": wall,
    }


# -- fig. 4 -----------------------------------------------------------------------------------


def stage_fig4(ctx: Context) -> dict[str, Any]:
    """A short training run of a fresh surrogate (fig. 4a-d) and the contact regularisation of
    one design at kappa from 1e3 to 1e5 (fig. 4e-f)."""
    sc, settings, ds = ctx.scale, ctx.data["settings"], ctx.data["dataset"]
    tr = per_category(ds, "train", sc.train_per_category)
    va = per_category(ds, "val", sc.val_per_category)
    cfg = TrainConfig(
        epochs=sc.epochs,
        batch_size=min(sc.batch_size, len(tr)),
        seed=0,
        patience=sc.epochs,
        curriculum_epochs=max(1, sc.epochs // 5),
    )
    run_dir = ctx.work / f"train-{sc.name}"
    res = train(
        split_of(tr, "train"),
        split_of(va, "val"),
        settings,
        run_dir,
        cfg,
        resume=(run_dir / "checkpoint.pt").is_file(),
        progress=ctx.progress,
        dataset_info={"samples": len(tr), "seed": ds.seed, "note": "reproduce fig. 4"},
    )
    metrics = read_metrics(run_dir)
    small, _, small_config = load_model(run_dir / "model.pt")
    test = split_of(ctx.data["test"], "test")
    gap_ds = per_category(ds, "train", sc.gap_train_per_category)
    small_eval = evaluate(
        small, split_of(gap_ds, "train"), test, settings, weights_of(small_config)
    )
    val = metrics["val_loss"]
    jumps = val[1:] / val[:-1] - 1.0
    ctx.save(
        "fig4a-d_training",
        plot_training(metrics),
        "Paper fig. 4a-d (fig:training_metrics). A fresh surrogate trained by "
        f"metainterface.surrogate.train on {len(tr)} generated samples ({len(va)} validation) "
        f"for {len(val)} epochs (the paper: 500 epochs on 80,000): (a) training loss (at the "
        "current kappa, with dropout) and validation loss (exact contact), (b) the softplus "
        "steepness kappa, exponential over the first quarter of the epochs, (c) the curriculum "
        "weight lambda, linear to 0, (d) the cosine learning rate. Validation loss "
        f"{val[0]:.3f} -> {val[-1]:.3f} (best {res.best_val_loss:.3f} at epoch "
        f"{res.best_epoch}).",
        epochs=len(val),
        train_samples=len(tr),
    )

    cat, i = _representative(ctx.data["pred"], sc.kappa_category)
    test_ds = ctx.data["test"]
    g = torch.as_tensor(test_ds.gamma[i : i + 1], dtype=torch.float64)
    h = torch.as_tensor(test_ds.h[i : i + 1], dtype=torch.float64)
    kappas = np.logspace(3, 5, 5)
    soft = [curve(g, h, settings, smooth=float(k), n_delta=2048) for k in kappas]
    exact = curve(g, h, settings, n_delta=2048)
    a_hat = np.stack([c.alpha_hat[0].numpy() for c in soft])
    s_hat = np.stack([c.stiffness_hat[0].numpy() for c in soft])
    a_ex, s_ex = exact.alpha_hat[0].numpy(), exact.stiffness_hat[0].numpy()
    p_hat = exact.p_hat.numpy()
    dev = [
        {
            "kappa": float(k),
            "max_alpha_hat_dev": float(np.max(np.abs(a - a_ex))),
            "mean_s_hat_dev": float(np.mean(np.abs(s - s_ex))),
        }
        for k, a, s in zip(kappas, a_hat, s_hat, strict=True)
    ]
    ctx.save(
        "fig4e-f_regularisation",
        plot_regularisation(
            p_hat, kappas, a_hat, s_hat, (a_ex, s_ex), f"{cat} test design #{i} (ground truth)"
        ),
        "Paper fig. 4e-f (fig:training_metrics). Normalised contact area alpha_hat and "
        "stiffness S_hat against P_hat of one test design (the median-error one of the "
        f"{cat} category, test row {i}) with the softplus contact law at kappa = 1e3 (light) "
        "... 1e5 (dark), and with the exact bracket (dashed). Largest |alpha_hat - exact|: "
        f"{dev[0]['max_alpha_hat_dev']:.3f} at kappa = 1e3, {dev[-1]['max_alpha_hat_dev']:.4f} "
        "at kappa = 1e5.",
    )
    return {
        "train_samples": len(tr),
        "val_samples": len(va),
        "config": {k: getattr(cfg, k) for k in ("epochs", "batch_size", "lr", "seed")}
        | {"curriculum_epochs": cfg.curriculum_epochs, "kappa_fraction": cfg.kappa_fraction},
        "epochs_run": len(val),
        "best_epoch": res.best_epoch,
        "best_val_loss": res.best_val_loss,
        "first_val_loss": float(val[0]),
        "final_val_loss": float(val[-1]),
        "final_train_loss": float(metrics["train_loss"][-1]),
        "largest_val_increase": float(jumps.max()) if jumps.size else 0.0,
        "evaluation": small_eval,
        "kappa_design": {"category": cat, "row": i},
        "kappa_deviation": dev,
    }
