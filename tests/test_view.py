"""The interactive HTML view, opened in a real browser: Debian's chromium, driven by Playwright.

The page must work from disk with no network: every request it makes is to its own file (or a
data: URI), plotly draws the curves and the 3D cell without a JavaScript error, hovering a
curve shows its values, the files are offered for download, and a screenshot is not blank.
No browser is downloaded: the test skips, saying why, where chromium is not installed.
"""

from __future__ import annotations

import base64
import io
import json
import shutil
import sys

import numpy as np
import pytest

import metainterface as mi
from metainterface.cli import main

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]


@pytest.fixture(scope="module")
def design_folder(tmp_path_factory):
    """A design of a friction law in newtons, written by the CLI with --html."""
    pytest.importorskip("plotly", reason="the HTML view needs the [view] extra (plotly)")
    folder = tmp_path_factory.mktemp("view")
    fn = np.linspace(0.1, 2.4, 12)  # mu from 10 to 4: within a cell's reach here
    law = folder / "law.csv"
    law.write_text(
        "normal_force,friction_force\n"
        + "".join(f"{a},{b}\n" for a, b in zip(fn, 5.2 * fn**0.7, strict=True))
    )
    out = folder / "out"
    args = ["design", "--friction-csv", str(law), "--shear-strength", "0.25MPa"]
    args += ["--modulus", "2MPa", "--radius", "0.5mm", "--area", "4cm2", "--out", str(out)]
    args += ["--no-verify"]
    assert main([*args, "--refine", "none", "--hedge", "0", "--fallback", "0", "--html"]) == 0
    return out


def test_page_is_one_self_contained_file(design_folder):
    page = (design_folder / "view.html").read_text(encoding="utf-8")
    assert page.startswith("<!DOCTYPE html>")
    # plotly.js inline, no script or stylesheet fetched from anywhere
    assert "<script src=" not in page and "<link " not in page
    assert len(page) > 1_000_000  # plotly.js itself
    # the design's files embedded as data: URIs, design.json readable back from the page
    href = page.split('href="data:application/json;base64,')[1].split('"')[0]
    data = json.loads(base64.b64decode(href))
    assert data["format"] == "metainterface/design-v1" and len(data["gamma"]) == 9


def test_view_of_objects_and_folders(tmp_path, design_folder):
    d = mi.Design.load(design_folder / "design.json")
    assert mi.view(d, tmp_path / "d.html").stat().st_size > 1_000_000
    r = mi.design("linear", verify=False, effort=mi.Effort(refine=False, hedge=0, fallback=0))
    path = mi.view(r, tmp_path / "r.html")
    assert "linear" in path.read_text(encoding="utf-8")[:5000]
    assert main(["view", str(design_folder), "--out", str(tmp_path / "c.html")]) == 0
    with pytest.raises(mi.MetainterfaceError, match="give path"):
        mi.view(d)
    with pytest.raises(mi.MetainterfaceError, match=r"\.html"):
        mi.view(d, tmp_path / "d.png")
    assert main(["view", str(tmp_path / "missing")]) == 2


def test_without_plotly_one_line_names_the_install(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "plotly", None)
    monkeypatch.setitem(sys.modules, "plotly.graph_objects", None)
    d = mi.Design(gamma=[2.0] * 9, h=[0.0] * 9)
    with pytest.raises(mi.MetainterfaceError, match=r"pip install 'metainterface\[view\]'"):
        mi.view(d, tmp_path / "v.html")
    assert not (tmp_path / "v.html").exists()


def _variance(png: bytes) -> float:
    from PIL import Image

    return float(np.asarray(Image.open(io.BytesIO(png)).convert("L"), dtype=np.float64).var())


@pytest.mark.skipif(CHROMIUM is None, reason="no chromium: apt-get install chromium")
@pytest.mark.long
def test_page_in_a_headless_browser(design_folder, tmp_path):
    sync_api = pytest.importorskip("playwright.sync_api", reason="the test extra's playwright")
    page_file = design_folder / "view.html"
    errors, requests = [], []
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        try:
            page = browser.new_page(viewport={"width": 1200, "height": 900})
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("request", lambda r: requests.append(r.url))
            page.goto(page_file.as_uri())
            page.wait_for_selector("#curves .main-svg", timeout=30_000)
            page.wait_for_selector("#cell .gl-container canvas", timeout=30_000)
            page.wait_for_timeout(500)
            # four panels of curves (target, design, friction law), one 3D surface
            assert page.evaluate("document.getElementById('curves').data.length") >= 7
            assert page.evaluate("document.getElementById('cell').data[0].type") == "surface"
            titles = page.locator("#curves .annotation-text").all_text_contents()
            assert "friction force vs normal force" in " ".join(titles)
            # hover over the middle of the alpha(P*) panel shows a value
            box = page.locator("#curves .nsewdrag").first.bounding_box()
            page.mouse.move(box["x"] + box["width"] * 0.3, box["y"] + box["height"] * 0.5)
            page.mouse.move(box["x"] + box["width"] * 0.3 + 1, box["y"] + box["height"] * 0.5)
            page.wait_for_selector("#curves .hoverlayer .hovertext", timeout=5_000)
            assert "P* =" in page.locator("#curves .hoverlayer").text_content()
            links = page.locator("a[download]")
            names = links.all_inner_texts()
            assert {"design.json", "curve.csv", "design.png"} <= set(names)
            assert all(
                links.nth(i).get_attribute("href").startswith("data:") for i in range(len(names))
            )
            shot = page.screenshot(full_page=True)
            (tmp_path / "view.png").write_bytes(shot)
            cell = page.locator("#cell").screenshot()
        finally:
            browser.close()
    assert errors == []
    assert all(u.startswith(("file:", "data:")) for u in requests), requests
    assert _variance(shot) > 100 and _variance(cell) > 100  # drawn, not blank
