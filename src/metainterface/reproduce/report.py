"""results.md: the numbers of a reproduction run in tables, each beside what the paper states.

Only formatting: every number comes from the run's ``numbers`` (see ``stages``); the paper's
values come from ``scales.PAPER``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from metainterface.data import FIGURE_ORDER
from metainterface.inverse import METHODS
from metainterface.reproduce.scales import PAPER, Scale

#: Largest excess of the surrogate's error over multistart's still called a match (fig. 5).
MATCH = 0.005


def pct(x: float) -> str:
    """A fraction as a percentage with two decimals (the format of every error in results.md)."""
    return f"{100 * x:.2f} %"


def _table(header: list[str], rows: list[list[Any]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return [*lines, ""]


def _below(value: float, limit: float) -> str:
    if value < limit:
        return "agrees"
    return f"**differs**: {pct(value)} is not below {pct(limit)}"


def _fig1(n: Mapping[str, Any]) -> list[str]:
    out = ["## Fig. 1 and table 1: single power-law asperities", ""]
    out += [
        f"Table 1 checked against the package's Sneddon closed forms (`physics.sneddon.force`, "
        f"`area`) at R = {n['table1_radius']:g}, E* = 1, over indentations from 1e-4 R to "
        "10^-1.5 R; the stiffness exponent is the log-log slope of the numerical dF/dA.",
        "",
    ]
    rows = []
    for r in n["table1"]:
        ok = r["max_rel_dev"] < 1e-9 and abs(r["stiffness_exponent"] - r["paper_exponent"]) < 1e-3
        rows.append(
            [
                f"{r['gamma']:g}",
                r["force_law"],
                f"{r['max_rel_dev']:.2e}",
                f"{r['stiffness_exponent']:.4f}",
                f"A^{r['paper_exponent']:g}",
                "agrees" if ok else "**differs**",
            ]
        )
    out += _table(
        [
            "gamma",
            "F(A), table 1",
            "max rel. deviation of the package's F(A)",
            "dF/dA exponent (fit)",
            "paper dF/dA",
            "agreement",
        ],
        rows,
    )
    out += ["Fig. 1b: log-log slope of A(F) against the paper's A ~ F^(2/(gamma+1)).", ""]
    out += _table(
        ["gamma", "fitted slope", "paper 2/(gamma+1)", "difference"],
        [
            [
                f"{s['gamma']:g}",
                f"{s['slope']:.5f}",
                f"{s['paper']:.5f}",
                f"{s['slope'] - s['paper']:+.1e}",
            ]
            for s in n["slopes"]
        ],
    )
    return out


def _fig3(n: Mapping[str, Any]) -> list[str]:
    ev, ds, model = n["evaluation"], n["dataset"], n["model"]
    out = ["## Fig. 3: zero-shot reconstructions of the test set", ""]
    if ds["own"]:
        out.append(
            f"Test rows: the test split of the shipped model's own training dataset, regenerated "
            f"here ({ds['samples']} samples, seed {ds['seed']}, default generator settings); "
            f"{n['test_rows']} test rows evaluated, {n['gap_train_rows']} training rows for the "
            "loss gap."
        )
    else:
        out.append(
            f"Test rows: a fresh dataset ({ds['samples']} samples, seed {ds['seed']}); the "
            "model's own training dataset was not regenerated at this scale, so the 'train' "
            "loss below is on unseen data too and the gap is not a generalisation gap."
        )
    tr = model.get("train") or {}
    out += [
        "",
        f"Shipped model: `{model['path']}`, trained for {tr.get('epochs', '?')} epochs (best "
        f"epoch {model.get('epoch', '?')}; the paper: {PAPER['epochs'][0]} epochs). Relative "
        "curve error ||alpha_pred - alpha_true|| / ||alpha_true|| on the 128-point grid.",
        "",
    ]
    rows = []
    for name in [*FIGURE_ORDER, "all"]:
        r = ev["categories"].get(name)
        if r is None:
            continue
        rows.append(
            [
                name,
                r["samples"],
                pct(r["median_curve_error"]),
                pct(r["p90_curve_error"]),
                f"{r['mean_abs_log10_p_star_max_error']:.4f}",
                f"{r['mean_abs_log10_alpha_max_error']:.4f}",
            ]
        )
    out += _table(
        [
            "category",
            "test samples",
            "median curve error",
            "p90 curve error",
            "mean abs log10 P*max err",
            "mean abs log10 alpha_max err",
        ],
        rows,
    )
    out += [
        "The paper gives no per-category numbers for fig. 3 (it shows the curves as "
        "accurately captured in all six categories).",
        "",
    ]
    gap = ev["loss_gap"]
    out += _table(
        ["quantity", "this run", "paper", "agreement"],
        [
            ["train loss (exact physics, eval mode)", f"{ev['train_loss']:.4f}", "", ""],
            ["test loss", f"{ev['test_loss']:.4f}", "", ""],
            [
                "train/test loss gap (test - train) / train",
                f"{100 * gap:+.2f} %",
                f"< {pct(PAPER['train_test_gap'][0])} ({PAPER['train_test_gap'][1].split(':')[0]})",
                _below(abs(gap), PAPER["train_test_gap"][0]),
            ],
        ],
    )
    w = n["wall_case"]
    out += [
        "### Wall case: zero-shot prediction against the ground-truth parameters",
        "",
        f"Test row {w['row']} ({w['category']}, the median-error one of its category): curve "
        f"error {pct(w['curve_error'])}; P*max {w['p_star_max_true']:.4g} (true) vs "
        f"{w['p_star_max_pred']:.4g} (predicted), alpha_max {w['alpha_max_true']:.4g} vs "
        f"{w['alpha_max_pred']:.4g}.",
        "",
    ]
    out += _table(
        ["asperity", "gamma true", "gamma predicted", "h/Delta_max true", "h/Delta_max predicted"],
        [
            [k + 1, f"{gt:.3f}", f"{gp:.3f}", f"{ht:.3f}", f"{hp:.3f}"]
            for k, (gt, gp, ht, hp) in enumerate(
                zip(w["gamma_true"], w["gamma_pred"], w["h_true"], w["h_pred"], strict=True)
            )
        ],
    )
    dg = max(abs(a - b) for a, b in zip(w["gamma_true"], w["gamma_pred"], strict=True))
    out += [
        f"The paper (qualitative): the network finds an alternative topography with the same "
        f"response. Here the parameters differ by up to {dg:.2f} in gamma at a curve error of "
        f"{pct(w['curve_error'])}.",
        "",
    ]
    return out


def _fig4(n: Mapping[str, Any], shipped: Mapping[str, Any] | None) -> list[str]:
    ev = n["evaluation"]
    cfg = n["config"]
    out = ["## Fig. 4: training dynamics", ""]
    out += [
        f"A fresh surrogate trained here for {n['epochs_run']} epochs on {n['train_samples']} "
        f"samples ({n['val_samples']} validation), batch {cfg['batch_size']}, peak learning rate "
        f"{cfg['lr']:g}, lambda to 0 over {cfg['curriculum_epochs']} epochs, kappa 1e3 -> 1e5 "
        f"over the first {cfg['kappa_fraction']:.0%} of the epochs, seed {cfg['seed']}. "
        "Panels a-d are its metrics; it is a demonstration of the dynamics, not the shipped "
        "model.",
        "",
    ]
    gap = ev["loss_gap"]
    rows = [
        ["epochs", n["epochs_run"], PAPER["epochs"][0], "scaled down on purpose"],
        [
            "first -> final validation loss",
            f"{n['first_val_loss']:.4f} -> {n['final_val_loss']:.4f}",
            "decays smoothly",
            "",
        ],
        ["best validation loss (epoch)", f"{n['best_val_loss']:.4f} ({n['best_epoch']})", "", ""],
        ["final training loss (current kappa, dropout)", f"{n['final_train_loss']:.4f}", "", ""],
        [
            "largest epoch-to-epoch rise of the validation loss",
            f"{100 * n['largest_val_increase']:+.1f} %",
            "no significant spikes",
            "" if n["largest_val_increase"] < 0.1 else "**a spike above 10 %**",
        ],
        [
            "train/test loss gap of this model",
            f"{100 * gap:+.2f} %",
            f"< {pct(PAPER['train_test_gap'][0])}",
            _below(abs(gap), PAPER["train_test_gap"][0]),
        ],
        [
            "median test curve error of this model",
            pct(ev["categories"]["all"]["median_curve_error"]),
            "",
            "shipped model: " + pct(shipped["categories"]["all"]["median_curve_error"])
            if shipped
            else "",
        ],
        [
            "gain of the kappa schedule over a fixed kappa = 1e5",
            "not reproduced (needs a second training run)",
            f"< {pct(PAPER['kappa_gain'][0])}",
            "",
        ],
    ]
    out += _table(["quantity", "this run", "paper", "note"], rows)
    kd = n["kappa_design"]
    out += [
        f"Fig. 4e-f: test row {kd['row']} ({kd['category']}) with the softplus contact law "
        "against the exact bracket, on the 128-point grid of P_hat.",
        "",
    ]
    out += _table(
        ["kappa", "max abs(alpha_hat - exact)", "mean abs(S_hat - exact)"],
        [
            [f"{d['kappa']:.3g}", f"{d['max_alpha_hat_dev']:.4f}", f"{d['mean_s_hat_dev']:.4f}"]
            for d in n["kappa_deviation"]
        ],
    )
    return out


def _fig5(n: Mapping[str, Any]) -> list[str]:
    rs = n["refine"]
    out = ["## Fig. 5: surrogate-guided design vs multistart vs Hertz", ""]
    out += [
        f"Refinement {rs['stages']} stages x {rs['steps_per_stage']} L-BFGS steps x "
        f"{rs['iterations']} iterations for every method; baselines with {n['starts']} random "
        f"starts (the paper: {PAPER['starts'][0]}). The surrogate method is the paper's "
        "pipeline: its zero-shot prediction is the only start (`design --hedge 0`). Zero-shot "
        "error: the surrogate's prediction, or the best random start, before refinement. Wall "
        "times on this machine (the authors' timings are not in the paper).",
        "",
    ]
    rows = []
    for t, per in n["targets"].items():
        for m in METHODS:
            r = per[m]
            rows.append([t, m, pct(r["zero_shot_error"]), pct(r["error"]), f"{r['seconds']:.2f}"])
    out += _table(["target", "method", "zero-shot error", "final error", "wall time [s]"], rows)
    out += ["Against the paper's claims:", ""]
    for t, per in n["targets"].items():
        s, ms, hz = per["surrogate"], per["multistart"], per["hertz"]
        if s["error"] <= ms["error"]:
            cmp = (
                f"the surrogate is as good or better ({pct(s['error'])} vs "
                f"{pct(ms['error'])}): agrees"
            )
        elif s["error"] - ms["error"] <= MATCH:
            cmp = (
                f"the surrogate is slightly worse ({pct(s['error'])} vs {pct(ms['error'])}) but "
                f"within {100 * MATCH:.1f} percentage points: agrees"
            )
        else:
            cmp = (
                f"the surrogate is **worse** ({pct(s['error'])} vs {pct(ms['error'])}): differs "
                "from the paper"
            )
        speed = ms["seconds"] / max(s["seconds"], 1e-12)
        best = min(s["error"], ms["error"])
        hertz = (
            f"Hertz {pct(hz['error'])}, {hz['error'] / max(best, 1e-12):.0f}x the best error: "
            + (
                "fails, agrees"
                if hz["error"] > 2 * best and hz["error"] > 0.02
                else "**does not fail**, differs"
            )
        )
        out.append(
            f"- **{t}**: paper 'surrogate matches or outperforms multistart': {cmp}. "
            f"Paper 'multistart is computationally more expensive': {speed:.1f}x the "
            f"surrogate's wall time ({ms['seconds']:.1f} s vs {s['seconds']:.1f} s): "
            + ("agrees" if speed > 1 else "**differs**")
            + f". Paper 'the Hertzian baseline fails': {hertz}."
        )
    return [*out, ""]


def _fig6(n: Mapping[str, Any]) -> list[str]:
    limit, model_limit = PAPER["bem_max_rel_err"][0], PAPER["model_error"][0]
    out = ["## Fig. 6 and appendix D: validation against the boundary element method", ""]
    out += [
        "Relative error alpha_BEM / alpha_model - 1 at each load; the paper states a maximum "
        f"relative error below {pct(limit)} over the whole loading range (sec. 4.1) and below "
        f"{pct(model_limit)} (sec. 2.2). The upper half of the loads is shown too: at the "
        "lowest loads only a few grid points are in contact and the grid limits the accuracy, "
        "and at a load where an asperity engages alpha(P*) rises almost vertically, so a small "
        "shift in P* gives a large relative error in alpha (see 'at load' and the figures).",
        "",
    ]
    rows = []
    for name, d in n["designs"].items():
        errs = [abs(e) for e in d["rel_err"]]
        k = errs.index(max(errs))
        rows.append(
            [
                name,
                d["source"],
                f"{d['grid']}",
                d["loads"],
                pct(d["max_rel_err"]),
                f"{k + 1} of {d['loads']} (P* = {d['p_star'][k]:.3g})",
                pct(d["max_rel_err_upper_half"]),
                f"{d['max_local_pressure']:.3g}",
                f"{d['gamma_min']:.2f}",
                _below(d["max_rel_err"], limit),
                _below(d["max_rel_err"], model_limit),
            ]
        )
    out += _table(
        [
            "figure",
            "design",
            "grid",
            "loads",
            "max rel. err (all loads)",
            "at load",
            "max rel. err (upper half)",
            "max p/E*",
            "min gamma",
            f"paper < {pct(limit)}",
            f"paper < {pct(model_limit)}",
        ],
        rows,
    )
    out += [
        f"The paper's pressure remark ({PAPER['local_pressure'][1]}) is shown by the "
        "'max p/E*' column.",
        "",
    ]
    return out


def _settings(scale: Scale, numbers: Mapping[str, Any]) -> list[str]:
    rs = scale.refine
    rows = []
    if "fig3" in numbers:
        rows.append(
            ["dataset samples", numbers["fig3"]["dataset"]["samples"], PAPER["dataset_samples"][0]]
        )
    if "fig4" in numbers:
        rows.append(
            ["training epochs (fig. 4 run)", numbers["fig4"]["epochs_run"], PAPER["epochs"][0]]
        )
    rows += [
        ["random starts of the baselines", scale.starts, PAPER["starts"][0]],
        [
            "refinement stages x steps x iterations",
            f"{rs.stages} x {rs.steps_per_stage} x {rs.iterations}",
            "5 x 5 x 20",
        ],
        ["polish iterations after the stages (ours)", rs.polish_iterations, "none"],
    ]
    if "fig6" in numbers and numbers["fig6"]["designs"]:
        d = next(iter(numbers["fig6"]["designs"].values()))
        rows += [
            ["BEM grid", d["grid"], PAPER["bem_grid"][0]],
            ["BEM loads per design", d["loads"], "not stated"],
            ["BEM tolerance", f"{scale.bem_tolerance:g}", f"{PAPER['bem_tolerance'][0]:g}"],
        ]
    return [
        "## Settings of this run against the paper's",
        "",
        *_table(["setting", "this run", "paper"], rows),
    ]


def render(
    numbers: Mapping[str, Any],
    seconds: Mapping[str, float],
    descriptions: Mapping[str, str],
    scale: Scale,
    figures: Mapping[str, Mapping[str, str]],
    header: Mapping[str, str],
) -> str:
    """The whole results.md."""
    out = [
        "# Reproduction of the paper's results",
        "",
        f"Made by `{header['command']}` (scale **{scale.name}**), metainterface "
        f"{header['version']}, {header['created']}. Every number below was computed by this "
        "run; the 'paper' columns quote the paper. To refresh: "
        f"`{header['refresh']}`.",
        "",
    ]
    out += _table(
        ["stage", "what", "seconds"],
        [[s, descriptions[s], f"{seconds[s]:.1f}"] for s in seconds]
        + [["total", "", f"{sum(seconds.values()):.1f}"]],
    )
    if "fig1" in numbers:
        out += _fig1(numbers["fig1"])
    if "fig3" in numbers:
        out += _fig3(numbers["fig3"])
    if "fig4" in numbers:
        shipped = numbers.get("fig3", {}).get("evaluation")
        out += _fig4(numbers["fig4"], shipped)
    if "fig5" in numbers:
        out += _fig5(numbers["fig5"])
    if "fig6" in numbers:
        out += _fig6(numbers["fig6"])
    out += _settings(scale, numbers)
    out += ["## Files", ""]
    out += [f"- `{name}`: " + ", ".join(files.values()) for name, files in figures.items()]
    return "\n".join(out) + "\n"
