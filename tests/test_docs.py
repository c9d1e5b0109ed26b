"""The documentation builds, warnings-free, with every tutorial executed (docs/).

The full build runs the tutorials (minutes of CPU), so it is marked ``docs`` and kept out of
the default run (``python -m pytest -q``); CI runs it as a step of its own right after
(``python -m pytest -q -m docs -n 0``, in .ci/run), so a broken example or a dead
cross-reference still fails CI, not a later docs deployment. The other tests here (a
docstring for every public name, a dead reference or a broken example failing a one-page
build) stay in the default run. The build's notebooks run side by side, one per core, before
the build (``_EXECUTE``), which takes their outputs.
"""

from __future__ import annotations

import importlib.util
import inspect
import re
import subprocess
import sys
from pathlib import Path

import pytest
from sphinx.pycode import ModuleAnalyzer

import metainterface as mi

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
TUTORIALS = sorted(p.stem for p in (DOCS / "tutorials").glob("*.md") if p.stem != "index")


def _sphinx(src: Path, out: Path, *extra: str) -> subprocess.CompletedProcess:
    """sphinx-build -W --keep-going into ``out`` with the docs' configuration."""
    cmd = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html", "-q"]
    cmd += ["-c", str(DOCS), "-d", str(out / "doctrees"), *extra, str(src), str(out / "html")]
    return subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)


#: A script, style sheet or image a page would fetch from another host.
_REMOTE = re.compile(r"<(?:script|link|img)\b[^>]*\b(?:src|href)=\"(?:https?:)?//[^\"]+\"")


def _doc_comment(obj: object, name: str) -> str | None:
    """The ``#:`` comment of a module-level binding of ``obj`` to ``name`` in the package."""
    modules = [
        m for m in sorted(sys.modules) if m == "metainterface" or m.startswith("metainterface.")
    ]
    for modname in modules:
        if getattr(sys.modules[modname], name, None) is not obj:
            continue
        lines = ModuleAnalyzer.for_module(modname).find_attr_docs().get(("", name))
        if lines and "".join(lines).strip():
            return "\n".join(lines)
    return None


@pytest.mark.parametrize("name", mi.__all__)
def test_every_public_name_has_a_docstring(name):
    obj = getattr(mi, name)
    if inspect.isclass(obj):
        doc = obj.__dict__.get("__doc__") or ""
        assert not doc.startswith(f"{obj.__name__}("), f"{name}: only the dataclass signature"
    elif callable(obj):
        doc = obj.__doc__ or ""
    else:  # data: documented by a '#:' comment where it is bound
        doc = _doc_comment(obj, name) or ""
    assert len(doc.strip()) > 20, f"metainterface.{name} has no docstring"


# Run in a fresh interpreter: the kernels get the environment docs/conf.py gives them in a
# sphinx-build, then every notebook page is executed into a jupyter-cache, as many at a time
# as there are cores, the longest first (the command line's, then training one, then the
# others in order of size: a proxy, only the order depends on it).
_EXECUTE = """
import runpy, sys
from pathlib import Path
from jupyter_cache import get_cache
from jupyter_cache.executors import load_executor

docs, cache = Path(sys.argv[1]), get_cache(sys.argv[2])
runpy.run_path(str(docs / "conf.py"))
pages = [
    p for p in docs.rglob("*.md")
    if "_build" not in p.parts and "file_format: mystnb" in p.read_text("utf-8")
]
first = {"command-line": 0, "design-space": 1}
for page in sorted(pages, key=lambda p: (first.get(p.stem, 2), -p.stat().st_size)):
    cache.add_nb_to_project(str(page), read_data={"name": "myst_nb_md", "type": "plugin"})
run = load_executor("local-parallel", cache).run_and_cache(timeout=300)
for uri in run.errored + run.excepted:
    print(uri, cache.get_project_record(uri).traceback)
print("executed", len(run.succeeded), "of", len(pages))
sys.exit(1 if run.errored or run.excepted or len(run.succeeded) != len(pages) else 0)
"""


@pytest.mark.docs
def test_the_docs_build_warnings_free_with_every_tutorial_run(tmp_path):
    # The notebooks run first, in parallel, into a cache under the build folder; the build
    # takes their outputs from it (nb_execution_mode "cache": a page whose code is not in the
    # cache, as it ran, is executed by the build itself).
    cache = tmp_path / "jupyter_cache"
    ran = subprocess.run(
        [sys.executable, "-c", _EXECUTE, str(DOCS), str(cache)],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert ran.returncode == 0, ran.stdout[-6000:] + ran.stderr[-3000:]
    mode = ["-D", "nb_execution_mode=cache", "-D", f"nb_execution_cache_path={cache}"]
    done = _sphinx(DOCS, tmp_path, *mode)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-6000:]
    html = tmp_path / "html"
    # every public name has its reference page, generated from __all__
    for name in mi.__all__:
        assert (html / "reference" / "generated" / f"metainterface.{name}.html").is_file(), name
    # every tutorial ran: its code cells have outputs, and its figures are images on disk
    for stem in TUTORIALS:
        page = (html / "tutorials" / f"{stem}.html").read_text(encoding="utf-8")
        assert "cell_output" in page, f"{stem}: no cell outputs"
        for src in re.findall(r'<img[^>]+src="([^"]+\.png)"', page):
            assert (html / "tutorials" / src).resolve().is_file(), f"{stem}: {src} missing"
    # no page loads anything from the network: offline, every page reads the same
    for page in html.rglob("*.html"):
        text = page.read_text(encoding="utf-8")
        assert not _REMOTE.findall(text), f"{page.relative_to(html)}: {_REMOTE.findall(text)}"
    first = (html / "tutorials" / "first-design.html").read_text(encoding="utf-8")
    assert first.count("<img") >= 4  # the target, the full figure, the curves, the comparison
    # the reproduced figures page shows every PNG of docs/figures with its caption
    page = (html / "concepts" / "reproduced.html").read_text(encoding="utf-8")
    for png in (DOCS / "figures").glob("*.png"):
        assert png.name in page, png.name


def _project(tmp_path: Path, index: str) -> Path:
    """A one-page source folder built with the docs' conf.py (its checks, its extensions)."""
    src = tmp_path / "src"
    src.mkdir()
    (src / "index.md").write_text(index, encoding="utf-8")
    return src


def test_math_is_mathml_in_the_page_and_no_script_comes_from_the_network(tmp_path):
    src = _project(
        tmp_path,
        "# Page\n\nInline $\\alpha = F_f / (\\tau A)$ and\n\n"
        "$$\nP^* = \\frac{\\sum_i F_i}{A_\\mathrm{nom} E^*}\n$$\n",
    )
    done = _sphinx(src, tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    page = (tmp_path / "html" / "index.html").read_text(encoding="utf-8")
    assert page.count("<math") == 2 and "<mfrac>" in page  # drawn by the browser itself
    assert "$" not in page.split("<body")[1].split("<footer")[0].replace("$$", "")
    assert not _REMOTE.findall(page), _REMOTE.findall(page)
    assert "mathjax" not in page.lower().replace("mathjax_ignore", "")


def test_a_dead_cross_reference_fails_the_build(tmp_path):
    src = _project(tmp_path, "# Page\n\nSee {func}`metainterface.no_such_function`.\n")
    done = _sphinx(src, tmp_path)
    assert done.returncode != 0
    assert "metainterface.no_such_function" in done.stderr


def test_a_broken_example_fails_the_build(tmp_path):
    page = (
        "---\nfile_format: mystnb\nkernelspec:\n  name: python3\n  display_name: Python 3\n"
        "---\n\n# Page\n\n```{code-cell} ipython3\nimport metainterface as mi\n"
        "mi.design('no such target')\n```\n"
    )
    done = _sphinx(_project(tmp_path, page), tmp_path)
    assert done.returncode != 0
    assert "ExecutionError" in done.stderr and "index.md" in done.stderr


def _extension():
    """The docs' Sphinx extension (docs/_ext/metainterface_docs.py), imported from its file."""
    spec = importlib.util.spec_from_file_location(
        "metainterface_docs", DOCS / "_ext" / "metainterface_docs.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_name_added_to_all_gets_its_reference_page_and_a_missing_docstring_is_reported(
    tmp_path, monkeypatch
):
    def documented(x: mi.Design) -> mi.Curve:
        """A new public function, documented."""

    def bare(x: float) -> float:
        return x

    monkeypatch.setattr(mi, "documented", documented, raising=False)
    monkeypatch.setattr(mi, "bare", bare, raising=False)
    monkeypatch.setattr(mi, "__all__", [*mi.__all__, "documented", "bare"])
    missing = _extension().write_reference(tmp_path)
    pages = tmp_path / "reference" / "generated"
    assert "autofunction:: metainterface.documented" in (
        pages / "metainterface.documented.rst"
    ).read_text(encoding="utf-8")
    assert "metainterface.documented" in (pages / "_body.inc").read_text(encoding="utf-8")
    assert missing == ["bare"]
