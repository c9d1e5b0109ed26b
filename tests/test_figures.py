"""Every figure function rendered small and large: no text runs into other text, nothing is cut
off at the figure's edge, every panel is labelled, titles are short, limits hold the data.

Text extents come from matplotlib itself (each artist's window extent after a draw), so the
test sees what a reader would: overlapping tick labels, a title over an axis label, a
legend over a colour bar.
"""

from __future__ import annotations

import itertools
import re
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.text import Text

import metainterface as mi
from metainterface.plots import (
    plot_comparison,
    plot_curve,
    plot_dataset_examples,
    plot_reconstructions,
    plot_training,
    plot_validation,
)

SMALL, LARGE = 4.5, 16.0
LONG_NAME = "a_rather_long_target_name_from_a_measurement_campaign_2026_run_17"


def _boxes(fig):
    """(description, bbox) of every piece of text a reader sees, legends as one box each."""
    canvas = FigureCanvasAgg(fig)  # the figures carry no pyplot canvas: draw them as a PNG would
    canvas.draw()
    r = canvas.get_renderer()
    out = [  # the figure's own texts: suptitle, fig.text(...)
        (f"figure text {t.get_text()!r}", t.get_window_extent(r))
        for t in fig.get_children()
        if isinstance(t, Text) and t.get_visible() and t.get_text()
    ]
    for i, ax in enumerate(fig.axes):
        if not ax.get_visible():
            continue
        if ax.title.get_text():
            out.append((f"axes {i} title {ax.title.get_text()!r}", ax.title.get_window_extent(r)))
        for name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            if ax.axison and axis.get_visible() and axis.label.get_text():
                desc = f"axes {i} {name}label {axis.label.get_text()!r}"
                out.append((desc, axis.label.get_window_extent(r)))
        for name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            if not (axis.get_visible() and ax.axison):
                continue
            lo, hi = sorted(axis.get_view_interval())
            span = hi - lo
            for tick in axis.get_major_ticks():
                if not lo - 1e-9 * span <= tick.get_loc() <= hi + 1e-9 * span:
                    continue
                for label in (tick.label1, tick.label2):
                    if label.get_visible() and label.get_text():
                        desc = f"axes {i} {name}tick {label.get_text()!r}"
                        out.append((desc, label.get_window_extent(r)))
            off = axis.get_offset_text()
            if off.get_visible() and off.get_text():
                out.append((f"axes {i} {name} offset", off.get_window_extent(r)))
        legend = ax.get_legend()
        if legend is not None:
            out.append((f"axes {i} legend", legend.get_window_extent(r)))
        out += [
            (f"axes {i} text {t.get_text()!r}", t.get_window_extent(r))
            for t in ax.texts
            if t.get_visible()
        ]
    return out


def check_figure(fig, tol: float = 1.0) -> None:
    """No two texts overlap (by more than ``tol`` pixels each way), all lie inside the
    figure, every visible axes that draws ticks has its axis labels or is a colour bar."""
    boxes = _boxes(fig)
    assert boxes, "no text at all"
    canvas = fig.bbox
    for desc, b in boxes:
        assert b.x0 >= canvas.x0 - tol and b.x1 <= canvas.x1 + tol, f"{desc} cut off: {b}"
        assert b.y0 >= canvas.y0 - tol and b.y1 <= canvas.y1 + tol, f"{desc} cut off: {b}"
    for (d1, b1), (d2, b2) in itertools.combinations(boxes, 2):
        w = min(b1.x1, b2.x1) - max(b1.x0, b2.x0)
        h = min(b1.y1, b2.y1) - max(b1.y0, b2.y0)
        assert not (w > tol and h > tol), f"{d1} overlaps {d2}"
    for ax in fig.axes:
        if ax.get_visible() and ax.axison and ax.get_label() != "<colorbar>":
            assert ax.get_xlabel() or not ax.xaxis.get_visible(), f"unlabelled x: {ax.get_title()}"
            assert ax.get_ylabel(), f"unlabelled y: {ax.get_title()!r}"
    titles = [ax.get_title() for ax in fig.axes] + [fig.get_suptitle()]
    for title in titles:
        assert all(len(line) <= 60 for line in title.splitlines()), f"long title {title!r}"
        assert not re.search(r"[\w.-]+/[\w.-]+/", title), f"a path in title {title!r}"


@pytest.fixture(scope="module")
def friction_result(tmp_path_factory):
    """A design result of a friction-law target (newtons), with a long name, made without
    the optimiser (the figure, not the design, is under test)."""
    folder = tmp_path_factory.mktemp("law")
    fn = np.linspace(0.05, 2.0, 12)
    law = folder / f"{LONG_NAME}.csv"
    law.write_text(
        "normal_force,friction_force\n"
        + "".join(f"{a},{b}\n" for a, b in zip(fn, 1.2 * fn**0.7, strict=True))
    )
    t = mi.Target.from_friction(
        law, shear_strength="0.25MPa", modulus="2MPa", radius="0.5mm", area="4cm2"
    )
    # no cell reaches this law at these E*, tau and area: the figure of a forced design
    return mi.design(
        t, force=True, verify=False, effort=mi.Effort(refine=False, hedge=0, fallback=0)
    )


@pytest.fixture(scope="module")
def csv_result(tmp_path_factory):
    """A CSV target much longer than the design's pressure range needs."""
    p = np.linspace(0.0, 0.002, 5000)
    t = mi.Target(p_star=p, alpha=0.04 * (1 - np.exp(-p / 0.0006)), name="measured")
    return mi.design(t, verify=False, effort=mi.Effort(refine=False, hedge=0, fallback=0))


@pytest.mark.parametrize("width", [SMALL, LARGE])
def test_design_figure_friction(friction_result, width):
    fig = friction_result.figure(width=width)
    check_figure(fig)
    labels = {ax.get_xlabel() for ax in fig.axes} | {ax.get_ylabel() for ax in fig.axes}
    assert "normal force [N]" in labels and "friction force [N]" in labels
    assert "friction coefficient μ" in labels
    assert any("Δmax" in ax.get_title() for ax in fig.axes)
    # the cell's colour legend
    assert any(ax.get_label() == "<colorbar>" for ax in fig.axes)


def _tick_overlaps(fig) -> list[str]:
    """The pairs of tick labels on one axis whose drawn boxes overlap (from the renderer)."""
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    r = canvas.get_renderer()
    found = []
    for i, ax in enumerate(fig.axes):
        for name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            lo, hi = sorted(axis.get_view_interval())
            boxes = [
                (label.get_text(), label.get_window_extent(r))
                for tick in axis.get_major_ticks()
                if lo - 1e-9 * (hi - lo) <= tick.get_loc() <= hi + 1e-9 * (hi - lo)
                for label in (tick.label1, tick.label2)
                if label.get_visible() and label.get_text()
            ]
            for (a, ba), (b, bb) in itertools.combinations(boxes, 2):
                if ba.overlaps(bb):
                    found.append(f"axes {i} {name}: {a!r} and {b!r}")
    return found


@pytest.fixture(scope="module")
def wide_result():
    """P* up to ~0.01, designed once for both widths; checked in BEM on a small grid, so the
    figure carries the BEM curve as a default design's does (the figure is under test)."""
    p = np.linspace(0.0, 0.0125, 200)
    t = mi.Target(p_star=p, alpha=0.9 * (1 - np.exp(-p / 0.004)), name="wide")
    return mi.design(
        t,
        verify=mi.Verify(grid=96, loads=4, correct=False, max_error=1.0),
        effort=mi.Effort(refine=False, hedge=0, fallback=0),
    )


@pytest.mark.parametrize("width", [6.0, None])
def test_pressure_tick_labels_do_not_run_together(wide_result, width):
    """P* up to ~0.01: plain labels ('0.000', '0.003', ...) touched at 6 inches; they are
    scaled into the axis label instead."""
    assert wide_result.bem is not None
    fig = wide_result.figure(width=width)
    assert _tick_overlaps(fig) == []
    area = next(ax for ax in fig.axes if ax.get_title() == "contact area")
    assert "×10⁻²" in area.get_xlabel()


def test_tick_overlap_check_sees_labels_running_together():
    from matplotlib.figure import Figure

    fig = Figure(figsize=(3.0, 2.5), layout="constrained")
    ax = fig.add_subplot()
    ax.plot([0, 0.0125], [0, 1])
    ax.set_xticks(np.linspace(0, 0.0125, 6))
    ax.ticklabel_format(axis="x", style="plain")
    assert _tick_overlaps(fig)


@pytest.fixture(scope="module")
def stopping_result(tmp_path_factory):
    """F_f = 0.4 F_n up to 6 N at E* = 2 MPa, tau = 0.25 MPa on 4 cm^2: out of reach (a cell
    reaches mu >= ~1.8 and ~4.6 N there), designed anyway."""
    law = tmp_path_factory.mktemp("stop") / "constant.csv"
    fn = np.linspace(0.25, 6.0, 24)
    law.write_text("normal_force,friction_force\n" + "".join(f"{a},{0.4 * a}\n" for a in fn))
    t = mi.Target.from_friction(
        law, shear_strength="0.25MPa", modulus="2MPa", radius="0.5mm", area="4cm2"
    )
    return mi.design(t, force=True, verify=False, effort=mi.Effort(hedge=0, fallback=0))


def test_design_figure_shows_where_a_design_stops(stopping_result):
    """A design that stops short of its law: both friction panels mark where (in newtons),
    the coefficient panel holds the design's mu, idle asperities are marked, the title says
    it was forced and gives the coverage."""
    r = stopping_result
    assert r.forced and r.coverage < 1
    fig = r.figure()
    title = fig.get_suptitle()
    assert "FORCED" in title and "coverage" in title
    by_title = {ax.get_title(): ax for ax in fig.axes}
    for name in ("friction", "friction coefficient"):
        labels = [ln.get_label() for ln in by_title[name].get_lines()]
        assert any(lb.startswith("design stops") and lb.endswith(" N") for lb in labels)
    ax_m = by_title["friction coefficient"]
    design_line = next(ln for ln in ax_m.get_lines() if ln.get_label() == "design")
    x, mu = design_line.get_data()
    later = x >= 0.1 * x.max()
    assert mu[later].max() <= ax_m.get_ylim()[1]
    for name in ("contact area", "stiffness"):
        assert "design stops" in [ln.get_label() for ln in by_title[name].get_lines()]
    check_figure(fig)
    if r.idle:
        cell = next(ax for ax in fig.axes if ax.get_title().startswith("cell from above"))
        assert "idle" in cell.get_title()
        assert sum("idle" in t.get_text() for t in cell.texts) == len(r.idle)


@pytest.mark.parametrize("width", [SMALL, LARGE])
def test_design_figure_csv_target(csv_result, width):
    fig = csv_result.figure(width=width)
    check_figure(fig)
    by_title = {ax.get_title(): ax for ax in fig.axes}
    area, stiff = by_title["contact area"], by_title["stiffness"]
    t = csv_result.target
    # one pressure range for both panels, holding the target and the design
    assert area.get_xlim() == stiff.get_xlim()
    assert area.get_xlim()[0] == 0 and area.get_xlim()[1] >= t.p_star_max
    assert area.get_ylim()[0] == 0 and stiff.get_ylim()[0] == 0
    # the target's own S* line beside the design's
    # (and, where the zero-shot design stops short of the target, the mark of where)
    labels = [ln.get_label() for ln in stiff.get_lines() if ln.get_label() != "design stops"]
    assert labels == ["target (differences)", "design"]
    assert ("design stops" in [ln.get_label() for ln in stiff.get_lines()]) == (
        csv_result.coverage < 1
    )
    # the error with significant digits in the title, never "0.00 %"
    assert "error" in fig.get_suptitle() and "0.00 %" not in fig.get_suptitle()


def test_design_figure_stiffness_is_resolved(csv_result):
    """S* dips to 0 exactly where an asperity with gamma > 2 engages: the figure's curve
    resolves each dip (its minimum near 0) instead of sampling it at a random depth."""
    import dataclasses

    d = mi.Design(gamma=[2.0] * 4 + [3.6] * 4 + [2.6], h=[0.0] * 4 + [0.009] * 4 + [0.003])
    c = dataclasses.replace(csv_result, design=d).figure_curve()
    s = c.stiffness
    h = np.sort(d.h - d.h.min())
    d_max = d.settings.delta_max
    blunt = (d.gamma[np.argsort(d.h - d.h.min())] > 2.05) & (h > 0.01 * d_max) & (h < d_max)
    assert blunt.any()
    for hk in h[blunt]:
        after = (c.delta > hk) & (c.delta < hk + 1e-3 * d.settings.delta_max)
        assert after.sum() >= 5
        before = s[(c.delta < hk) & (c.delta > hk - 0.05 * d.settings.delta_max)]
        assert s[after].min() < 0.2 * before.max()


def test_error_label_has_significant_digits(csv_result):
    import dataclasses

    tiny = dataclasses.replace(csv_result, error=9.7e-8)
    assert "9.7e-06 %" in tiny.figure(width=8).get_suptitle()
    assert "9.7e-06 %" in repr(tiny)


@pytest.mark.parametrize("width", [SMALL, LARGE])
def test_curve_figure(width):
    c = mi.curve(gamma=[1.9, 2.4, 3.0, 3.6] * 2 + [2.0], h=np.linspace(0, 0.01, 9))
    fig = plot_curve(c, title=f"/some/deep/folder/{LONG_NAME}/design.json", width=width)
    check_figure(fig)
    assert fig.get_suptitle() == "design.json"
    assert all(ax.get_xlim()[1] >= c.p_star_max for ax in fig.axes)


@pytest.mark.parametrize("epochs", [1, 120])
@pytest.mark.parametrize("width", [SMALL, LARGE])
def test_training_figure(epochs, width):
    ep = np.arange(1, epochs + 1)
    metrics = {
        "epoch": ep,
        "train_loss": 0.3 / ep,
        "val_loss": 0.4 / ep,
        "kappa": 50 * 1.1**ep,
        "lambda": np.minimum(1, ep / 10),
        "lr": 1e-3 * (1 + np.cos(np.pi * ep / (epochs + 1))) / 2,
    }
    fig = plot_training(metrics, width=width)
    check_figure(fig)
    lines = [ln for ax in fig.axes for ln in ax.get_lines()]
    assert len(lines) == 5
    if epochs == 1:  # one epoch: a visible point, not a line of length zero
        assert all(ln.get_marker() == "o" for ln in lines)


@pytest.mark.parametrize("width", [SMALL, LARGE])
def test_comparison_figure(csv_result, width):
    import dataclasses

    per = [csv_result, dataclasses.replace(csv_result, method="multistart", error=0.031)]
    fig = plot_comparison([per, per], [[r.curve() for r in per]] * 2, width=width)
    check_figure(fig)


@pytest.mark.parametrize("width", [SMALL, LARGE])
def test_dataset_figure(width):
    rng = np.random.default_rng(0)
    grid = np.linspace(0, 1, 64)
    examples = {
        name: {
            "p_star_max": rng.uniform(1e-3, 3e-3, 3),
            "alpha_max": rng.uniform(0.02, 0.08, 3),
            "alpha_hat": np.stack([grid ** rng.uniform(0.4, 0.9) for _ in range(3)]),
        }
        for name in ("lhs", "mixed", "truncated", "bimodal")
    }
    check_figure(plot_dataset_examples(examples, title=LONG_NAME, width=width))


@pytest.mark.parametrize("width", [SMALL, LARGE])
def test_reconstruction_figure(width):
    s = mi.CellSettings()
    names = ("lhs", "mixed", "truncated", "bimodal", "coplanar", "stratified")
    rng = np.random.default_rng(1)
    k = 12
    gamma = rng.uniform(1.9, 3.8, (k, 9))
    h = rng.uniform(0, 0.5, (k, 9)) * s.delta_max
    curves = [mi.curve(gamma=g, h=hh, steps=s.n_steps) for g, hh in zip(gamma, h, strict=True)]
    test = SimpleNamespace(
        category=np.array([names[i % 6] for i in range(k)]),
        p_star_max=np.array([c.p_star_max for c in curves]),
        alpha_max=np.array([c.alpha_max for c in curves]),
        alpha_hat=np.stack(
            [np.interp(np.linspace(0, c.p_star_max, s.n_steps), c.p_star, c.alpha) for c in curves]
        )
        / np.array([c.alpha_max for c in curves])[:, None],
    )
    pred = SimpleNamespace(gamma=gamma, h=h, curve_error=rng.uniform(1e-6, 0.05, k))
    check_figure(plot_reconstructions(test, pred, s, per_category=2, width=width))


@pytest.mark.parametrize("width", [SMALL, LARGE])
def test_validation_figure(width):
    pytest.importorskip("tamaas", reason="the BEM check needs the [bem] extra (Tamaas)")
    d = mi.Design(gamma=[2.0] * 4 + [3.6] * 5, h=[0.0] * 4 + [0.009] * 5)
    v = mi.validate(d, grid=48, loads=3)
    c = mi.curve(d)
    fig = plot_validation(v, target=(c.p_star, c.alpha), title=f"/x/y/{LONG_NAME}", width=width)
    check_figure(fig)


def test_the_check_sees_what_a_reader_would():
    """The check fails on the faults it exists for: tick labels of small numbers in full
    running together, a title over a label, text past the edge."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(3.0, 2.5), layout="constrained")
    ax = fig.add_subplot()
    ax.plot([0, 0.0012], [0, 1])
    ax.set(xlabel="P*", ylabel="alpha")
    ax.set_xticks(np.linspace(0, 0.0012, 9))
    ax.ticklabel_format(axis="x", style="plain")
    with pytest.raises(AssertionError, match="xtick"):
        check_figure(fig)

    fig = Figure(figsize=(3.0, 2.5), layout="constrained")
    ax = fig.add_subplot()
    ax.set(xlabel="x", ylabel="y")
    ax.text(0.5, 0.5, "one", transform=ax.transAxes)
    ax.text(0.5, 0.5, "two", transform=ax.transAxes)
    with pytest.raises(AssertionError, match="overlaps"):
        check_figure(fig)

    fig = Figure(figsize=(3.0, 2.5), layout="constrained")
    ax = fig.add_subplot()
    ax.set(xlabel="x", ylabel="y", title="a title far too long for a figure this narrow")
    with pytest.raises(AssertionError, match="cut off"):
        check_figure(fig)


@pytest.mark.parametrize(("n", "width"), [(4, SMALL), (25, SMALL), (25, LARGE)])
def test_design_figure_other_cells(csv_result, n, width):
    """Cells of 2 x 2 and 5 x 5 asperities: labels sized to the lattice, none overlapping."""
    import dataclasses

    s = mi.CellSettings(n_asperities=n)
    rng = np.random.default_rng(n)
    d = mi.Design(
        gamma=rng.uniform(1.9, 3.9, n), h=rng.uniform(0, 0.6, n) * s.delta_max, settings=s
    )
    fig = dataclasses.replace(csv_result, design=d).figure(width=width)
    check_figure(fig)


def test_plot_methods_draw_on_given_axes(csv_result):
    """result.plot() and curve.plot(): the target and the design on one pressure range."""
    from matplotlib.figure import Figure

    for width in (SMALL, LARGE):
        ax = Figure(figsize=(width, 0.75 * width), layout="constrained").add_subplot()
        assert csv_result.plot(ax) is ax
        assert ax.get_xlim()[1] >= csv_result.target.p_star_max
        check_figure(ax.figure)
        ax = Figure(figsize=(width, 0.75 * width), layout="constrained").add_subplot()
        csv_result.curve().plot(ax)
        check_figure(ax.figure)


def test_figures_returned_to_a_notebook_draw_as_png(csv_result):
    """A notebook cell that returns result.figure() or tolerance(...).plot() shows the
    picture: IPython asks the object for _repr_png_ (our figures are made without pyplot,
    which IPython would otherwise show as a text repr)."""
    png = b"\x89PNG\r\n\x1a\n"
    assert csv_result.figure(width=SMALL)._repr_png_().startswith(png)
    tol = mi.tolerance(csv_result, sigma_h=0.001, samples=32)
    assert tol.plot()._repr_png_().startswith(png)
