"""`metainterface reproduce` on the tiny scale: every figure file and results.md are written,
and the numbers in results.md are the computed ones."""

import json
from dataclasses import replace

import pytest

from metainterface.cli import main
from metainterface.reproduce import reproduce, stages
from metainterface.reproduce.report import pct

FIGURES = (
    "fig1_asperities",
    "fig3_reconstructions",
    "wall_case",
    "fig4a-d_training",
    "fig4e-f_regularisation",
    "fig5_comparison",
    "fig6_bem_bilinear",
    "appD_bem_mixed",
)


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    return reproduce(tmp_path_factory.mktemp("reproduce"), scale="tiny", progress=False)


@pytest.mark.long
def test_every_figure_has_a_png_a_pdf_and_a_caption(tiny):
    assert set(tiny.figures) == set(FIGURES)
    md = tiny.results_md.read_text()
    for name in FIGURES:
        assert (tiny.out_dir / f"{name}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert (tiny.out_dir / f"{name}.pdf").read_bytes()[:5] == b"%PDF-"
        caption = (tiny.out_dir / f"{name}.txt").read_text()
        assert caption.startswith("Paper ") and "Scale: tiny" in caption
        assert f"`{name}`" in md
    assert set(tiny.seconds) == {"fig1", "fig3", "fig4", "fig5", "fig6"}


@pytest.mark.long
def test_results_json_holds_the_returned_numbers_and_settings(tiny):
    record = json.loads((tiny.out_dir / "results.json").read_text())
    assert record["numbers"] == tiny.numbers
    assert record["provenance"]["settings"]["scale"]["name"] == "tiny"
    assert record["paper"]["bem_max_rel_err"]["value"] == 0.03


@pytest.mark.long
def test_results_md_tables_show_the_computed_numbers(tiny):
    md = tiny.results_md.read_text()
    for cat, r in tiny.numbers["fig3"]["evaluation"]["categories"].items():
        assert f"| {cat} | {r['samples']} | {pct(r['median_curve_error'])} |" in md
    gap = tiny.numbers["fig3"]["evaluation"]["loss_gap"]
    assert f"| {100 * gap:+.2f} % | < 4.00 % (sec. 3.2) |" in md
    for target, per in tiny.numbers["fig5"]["targets"].items():
        for method, r in per.items():
            row = f"| {target} | {method} | {pct(r['zero_shot_error'])} | {pct(r['error'])} |"
            assert f"{row} {r['seconds']:.2f} |" in md
    for name, d in tiny.numbers["fig6"]["designs"].items():
        assert (
            f"| {name} | {d['source']} | {d['grid']} | {d['loads']} | {pct(d['max_rel_err'])}" in md
        )
    w = tiny.numbers["fig3"]["wall_case"]
    assert f"| 1 | {w['gamma_true'][0]:.3f} | {w['gamma_pred'][0]:.3f} |" in md


@pytest.mark.long
def test_a_changed_computation_shows_in_results_md(tmp_path, monkeypatch):
    real_force, real_design = stages.force, stages.design
    monkeypatch.setattr(stages, "force", lambda *a, **k: 1.01 * real_force(*a, **k))

    def worse_surrogate(targets, method, **kw):
        out = real_design(targets, method, **kw)
        return [replace(r, error=0.4321) if method == "surrogate" else r for r in out]

    monkeypatch.setattr(stages, "design", worse_surrogate)
    res = reproduce(tmp_path, scale="tiny", progress=False, only=["fig1", "fig5"])
    md = res.results_md.read_text()
    assert res.numbers["fig1"]["table1"][0]["max_rel_dev"] == pytest.approx(0.01)
    row = next(line for line in md.splitlines() if line.startswith("| 1 | E* A / 4 |"))
    assert row.startswith("| 1 | E* A / 4 | 1.00e-02 |") and row.endswith("| **differs** |")
    for target in ("saturating", "bilinear", "linear"):
        assert res.numbers["fig5"]["targets"][target]["surrogate"]["error"] == 0.4321
        assert f"| {target} | surrogate |" in md
    assert md.count("| 43.21 % |") == 3
    assert set(res.figures) == {"fig1_asperities", "fig5_comparison"}


def test_cli_runs_a_stage_and_rejects_an_unknown_one(tmp_path, capsys):
    out = tmp_path / "figs"
    assert main(["reproduce", "--out", str(out), "--scale", "tiny", "--only", "fig1"]) == 0
    printed = capsys.readouterr().out
    assert "reproduce [1/1] fig1" in printed and "done in" in printed
    assert (out / "fig1_asperities.png").is_file() and (out / "results.md").is_file()
    assert main(["reproduce", "--out", str(tmp_path / "x"), "--only", "fig2"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "metainterface reproduce: error: unknown stage 'fig2'; stages are "
        "fig1, fig3, fig4, fig5, fig6"
    ]
    assert not (tmp_path / "x").exists()
