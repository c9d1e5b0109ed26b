"""The stages of a reproduction run: each calls the package, saves its figures and returns
the numbers behind them (JSON-ready) for results.md.

Stages share what they compute through ``Context.data`` (the dataset and the surrogate's
test predictions of fig. 3, the designs of fig. 5).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Any

import numpy as np
import torch
from matplotlib.figure import Figure

from metainterface._files.atomic import write_text
from metainterface.data import generate_dataset, load_dataset
from metainterface.data.load import Dataset
from metainterface.designer.curves import design_curve
from metainterface.errors import MetainterfaceError
from metainterface.inverse import METHODS, builtin_target, design
from metainterface.physics.cell import CellSettings, Design
from metainterface.physics.curves import curve, sweep
from metainterface.physics.sneddon import area, force, shape_constant
from metainterface.plots import (
    plot_comparison,
    plot_reconstructions,
    plot_training,
    plot_validation,
    save_figure,
)
from metainterface.reproduce.figures import plot_asperities, plot_regularisation, plot_wall_case
from metainterface.reproduce.scales import PAPER, Scale
from metainterface.surrogate.checkpoint import default_model_path, load_model
from metainterface.surrogate.data import split_of
from metainterface.surrogate.evaluate import Predictions, evaluate, predict_split
from metainterface.surrogate.loss import weights_of
from metainterface.surrogate.train import TrainConfig, read_metrics, train
from metainterface.validation import available_cpus, validate_design

OOD_TARGETS: tuple[str, ...] = ("saturating", "bilinear", "linear")


@dataclass
class Context:
    """What the stages of one run share: output folder, scratch folder, scale, model file."""

    out: Path
    work: Path
    scale: Scale
    model_path: Path
    progress: bool
    command: str
    figures: dict[str, dict[str, str]] = field(default_factory=dict)
    data: dict[str, Any] = field(default_factory=dict)

    def save(self, name: str, fig: Figure, caption: str, **settings: Any) -> None:
        """name.png, name.pdf and the caption name.txt in the output folder."""
        from metainterface import __version__

        record = {"figure": name, "scale": self.scale.to_dict(), **settings}
        files = {}
        for suffix in ("png", "pdf"):
            path = self.out / f"{name}.{suffix}"
            save_figure(fig, path, command=self.command, **record)
            files[suffix] = path.name
        text = (
            f"{caption.strip()}\n\nScale: {self.scale.name}. Made by metainterface "
            f"{__version__}: `{self.command}`.\n"
        )
        write_text(self.out / f"{name}.txt", text)
        files["txt"] = f"{name}.txt"
        self.figures[name] = files


def model_label(path: Path) -> str:
    """How results.md names a model file (the shipped one without a machine's path)."""
    if path.resolve() == default_model_path().resolve():
        return "metainterface/weights/surrogate.pt (shipped)"
    return str(path)


def _pct(x: float) -> str:
    return f"{100 * x:.2f} %"


# -- fig. 1 and table 1 ---------------------------------------------------------------------

FIG1_GAMMAS: tuple[float, ...] = (1.0, 1.5, 2.0, 3.0, 5.0, 10.0, 100.0)

#: Table 1 of the paper: gamma -> (F(A) with E* = 1 for radius R, exponent of dF/dA in A).
TABLE1: dict[float, tuple[Callable[[np.ndarray, float], np.ndarray], float, str]] = {
    1.0: (lambda a, r: a / 4.0, 0.0, "E* A / 4"),
    2.0: (
        lambda a, r: 4.0 / (3.0 * r * math.pi**1.5) * a**1.5,
        0.5,
        "4 E* A^(3/2) / (3 R pi^(3/2))",
    ),
    3.0: (lambda a, r: 9.0 / (16.0 * math.pi * r**2) * a**2, 1.0, "9 E* A^2 / (16 pi R^2)"),
}


def _single(gamma: float, delta: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    g = torch.full((delta.size,), gamma, dtype=torch.float64)
    d = torch.as_tensor(delta, dtype=torch.float64)
    return force(g, d, radius).numpy(), area(g, d, radius).numpy()


def _area_on(force_grid: np.ndarray, gamma: float) -> np.ndarray:
    """A(F) of one asperity (R = E* = 1) on ``force_grid``, NaN beyond its range."""
    f, a = _single(gamma, np.logspace(-12, 0, 3000), 1.0)
    ok = (f > 0) & (a > 0)
    la = np.interp(np.log(force_grid), np.log(f[ok]), np.log(a[ok]), left=np.nan, right=np.nan)
    return np.exp(la)


def stage_fig1(ctx: Context) -> dict[str, Any]:
    """fig. 1a-b from the Sneddon closed forms; table 1 checked against them."""
    r = np.linspace(-1.0, 1.0, 401)
    profiles = {
        g: float(shape_constant(torch.tensor(g, dtype=torch.float64))) * np.abs(r) ** g
        for g in FIG1_GAMMAS
    }
    f_grid = np.logspace(-8, -1, 240)
    areas = {g: _area_on(f_grid, g) for g in FIG1_GAMMAS}
    dense = np.stack([_area_on(f_grid, g) for g in np.geomspace(1.0, 100.0, 60)])
    envelope = (np.nanmin(dense, axis=0), np.nanmax(dense, axis=0))
    slopes = []
    for g in FIG1_GAMMAS:
        ok = np.isfinite(areas[g])
        slope = float(np.polyfit(np.log(f_grid[ok]), np.log(areas[g][ok]), 1)[0])
        slopes.append({"gamma": g, "slope": slope, "paper": 2.0 / (g + 1.0)})
    fig = plot_asperities(r, profiles, f_grid, areas, envelope, areas[1.0], math.pi)
    worst = max(abs(s["slope"] - s["paper"]) for s in slopes)
    ctx.save(
        "fig1_asperities",
        fig,
        "Paper fig. 1a-b (fig:asp_shape_limits). (a) Power-law asperity profiles "
        "f(r) = c |r|^gamma with c = 1/(2 R^(gamma-1)), from the cone (gamma = 1, darkest) to "
        "gamma = 100 (lightest); all reach f = R/2 at r = R. (b) Contact area A against load F "
        "of single asperities (Sneddon closed forms of metainterface.physics.sneddon, R = E* = "
        "1) on log-log axes; grey: the band covered by gamma in [1, 100], between the cone "
        "(A ~ F) and the flat punch (A = pi R^2). Fitted log-log slopes match 2/(gamma+1) "
        f"within {worst:.1e}. Panel (c) of the paper (a schematic) is not reproduced.",
    )

    radius = 2.0  # table 1 carries R explicitly: check it away from R = 1
    delta = np.logspace(-4, -1.5, 60) * radius
    table = []
    for g, (closed_form, exponent, text) in TABLE1.items():
        f, a = _single(g, delta, radius)
        dev = float(np.max(np.abs(f / closed_form(a, radius) - 1.0)))
        dfda = np.gradient(f, a)
        fitted = float(np.polyfit(np.log(a[2:-2]), np.log(dfda[2:-2]), 1)[0])
        table.append(
            {
                "gamma": g,
                "force_law": text,
                "max_rel_dev": dev,
                "stiffness_exponent": fitted,
                "paper_exponent": exponent,
            }
        )
    return {"slopes": slopes, "table1": table, "table1_radius": radius}


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


def _clip(gamma: np.ndarray, settings: CellSettings) -> np.ndarray:
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
        f"categories {_pct(rows['all']['median_curve_error'])}; worst category median "
        f"{_pct(worst[0])} ({worst[1]}).",
        model=str(ctx.model_path),
    )

    cat, i = _representative(pred, ctx.scale.wall_category)
    truth = _exact(test_ds.gamma[i], test_ds.h[i], settings)
    guess = _exact(_clip(pred.gamma[i], settings), pred.h[i], settings)
    err = float(pred.curve_error[i])
    ctx.save(
        "wall_case",
        plot_wall_case(
            truth, guess, settings.delta_max, f"{cat} test design #{i}: curve error {_pct(err)}"
        ),
        "Paper 'wall case' figure (fig:wall_case). One test design (the median-error one of "
        f"the {cat} category, test row {i}) against the shipped surrogate's zero-shot "
        "prediction: (a) alpha(P*) and (c) S*(P*) of both (exact forward model), (b) height "
        "offsets h/Delta_max and (d) shape exponents gamma per asperity (sorted by height). "
        f"Relative curve error {_pct(err)}; the parameters differ by up to "
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


# -- fig. 5 ---------------------------------------------------------------------------------


def stage_fig5(ctx: Context) -> dict[str, Any]:
    """The three out-of-distribution targets by the three methods (fig. 5)."""
    sc = ctx.scale
    settings = ctx.data.get("settings") or load_model(ctx.model_path)[1]
    ctx.data["settings"] = settings
    results: dict[str, dict[str, Any]] = {}
    for name in OOD_TARGETS:
        target = builtin_target(name)
        results[name] = {}
        for method in METHODS:
            results[name][method] = design(
                [target],
                method,
                settings=settings,
                model_path=ctx.model_path,
                starts=sc.starts,
                seed=0,
                refine_settings=sc.refine,
                hedge=0,  # the paper's pipeline: the zero-shot prediction is the only start
            )[0]
    ctx.data["designs"] = results
    per_target = [[results[t][m] for m in METHODS] for t in OOD_TARGETS]
    curves = [
        [design_curve(Design(r.gamma, r.h, settings), r.model, steps=512) for r in row]
        for row in per_target
    ]
    fig = plot_comparison(per_target, curves)
    rows = {
        t: {
            m: {
                "zero_shot_error": r.initial_error,
                "error": r.error,
                "seconds": r.seconds,
                "gamma": r.gamma.tolist(),
                "h": (r.h / settings.delta_max).tolist(),
            }
            for m, r in per.items()
        }
        for t, per in results.items()
    }
    summary = "; ".join(
        f"{t}: " + ", ".join(f"{m} {_pct(rows[t][m]['error'])}" for m in METHODS)
        for t in OOD_TARGETS
    )
    rs = sc.refine
    ctx.save(
        "fig5_comparison",
        fig,
        "Paper fig. 5 (fig:multistart_hertz_comparison). Out-of-distribution targets "
        "(saturating, bilinear, linear; black) designed by the shipped surrogate followed by "
        "the multi-stage L-BFGS refinement (blue; the paper's pipeline, no hedge starts), by "
        f"{sc.starts}-start direct optimisation "
        f"(green; the paper: 50 starts) and by a {sc.starts}-start Hertz-only baseline (gamma "
        f"= 2, orange); refinement {rs.stages} stages x {rs.steps_per_stage} steps x "
        f"{rs.iterations} iterations. Legend: relative curve error and wall time per target "
        f"on this machine. Errors: {summary}.",
        starts=sc.starts,
    )
    return {"starts": sc.starts, "refine": asdict(rs), "targets": rows}


# -- fig. 6 and appendix D ------------------------------------------------------------------


def _validate(ctx: Context, name: str, design_: Design, target, title: str, text: str) -> dict:
    sc = ctx.scale
    jobs = sc.bem_jobs or max(1, min(available_cpus(), sc.bem_loads))
    res = validate_design(
        design_,
        grid=sc.bem_grid,
        loads=sc.bem_loads,
        jobs=jobs,
        tolerance=sc.bem_tolerance,
        name=name,
    )
    ctx.save(
        name,
        plot_validation(res, target=target, title=title),
        f"{text} {'Tamaas' if res.engine == 'tamaas' else 'torch'} BEM (Polonsky-Keer-Rey, "
        f"tolerance {sc.bem_tolerance:g}) on a "
        f"{res.grid} x {res.grid} grid (the paper: 768) at {len(res.p_star)} loads up to P* at "
        f"Delta_max, against the independent-asperity model. Largest relative error of alpha: "
        f"{_pct(res.max_rel_err)} over all loads, {_pct(res.max_rel_err_upper)} over the upper "
        f"half (the paper: < 3 %). Largest local pressure p/E* = {res.p_max.max():.3g}.",
        grid=res.grid,
        loads=len(res.p_star),
    )
    s = res.summary()
    s.update(
        gamma_min=float(design_.gamma.min()),
        rel_err=res.rel_err.tolist(),
        p_star=res.p_star.tolist(),
        jobs=jobs,
    )
    return s


def stage_fig6(ctx: Context) -> dict[str, Any]:
    """BEM validation of the surrogate's design of one target (fig. 6) and of zero-shot
    designs of test curves of several categories (appendix D)."""
    sc, settings = ctx.scale, ctx.data["settings"]
    out = {}
    r = ctx.data["designs"][sc.bem_target]["surrogate"]
    name = f"fig6_bem_{sc.bem_target}"
    out[name] = _validate(
        ctx,
        name,
        Design(r.gamma, r.h, settings),
        (r.target.p_star, r.target.alpha),
        f"{sc.bem_target} target: surrogate + refinement design",
        "Paper fig. 6 (fig:bem_validation). The surrogate-guided design of the "
        f"{sc.bem_target} target (fig. 5): (left) alpha(P*) of the target, the model and BEM, "
        "(centre) the cell's topography, (right) p/E* at the largest load.",
    ) | {"source": f"{sc.bem_target} target, surrogate + refinement"}
    pred, test = ctx.data["pred"], ctx.data["test"]
    for cat in sc.bem_categories:
        i = median_row(pred, cat)
        if i is None:
            continue
        p = np.linspace(0.0, 1.0, test.alpha_hat.shape[1]) * test.p_star_max[i]
        name = f"appD_bem_{cat}"
        out[name] = _validate(
            ctx,
            name,
            Design(_clip(pred.gamma[i], settings), pred.h[i], settings),
            (p, test.alpha_hat[i] * test.alpha_max[i]),
            f"{cat} test curve #{i}: zero-shot surrogate design",
            "Paper appendix D (fig:bem_additional). The shipped surrogate's zero-shot design "
            f"for a {cat} test curve (the median-error one, test row {i}; target = the test "
            "curve): (left) alpha(P*) of target, model and BEM, (centre) topography, (right) "
            "p/E* at the largest load.",
        ) | {"source": f"{cat} test row {i}, zero-shot"}
    return {"designs": out, "paper": {k: PAPER[k][0] for k in ("bem_max_rel_err", "model_error")}}


STAGES: dict[str, tuple[Callable[[Context], dict[str, Any]], str, tuple[str, ...]]] = {
    "fig1": (stage_fig1, "single asperities (fig. 1a-b) and table 1", ()),
    "fig3": (stage_fig3, "dataset, test-set reconstructions (fig. 3) and the wall case", ()),
    "fig4": (stage_fig4, "training dynamics (fig. 4a-f)", ("fig3",)),
    "fig5": (stage_fig5, "surrogate vs multistart vs Hertz (fig. 5)", ()),
    "fig6": (stage_fig6, "BEM validation (fig. 6, appendix D)", ("fig3", "fig5")),
}


def plan(only: list[str] | tuple[str, ...] | None) -> list[str]:
    """The stages to run, in order: ``only`` (None: all) and what they need."""
    if not only:
        return list(STAGES)
    unknown = [s for s in only if s not in STAGES]
    if unknown:
        raise MetainterfaceError(f"unknown stage {unknown[0]!r}; stages are {', '.join(STAGES)}")
    wanted = set(only)
    for s in only:
        wanted.update(STAGES[s][2])
    return [s for s in STAGES if s in wanted]
