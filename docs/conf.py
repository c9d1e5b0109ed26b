"""Sphinx configuration of the metainterface documentation.

Build (from the repository root): ``sphinx-build -W --keep-going -b html docs docs/_build/html``.
Warnings are errors; the tutorials are executed on every build; the API reference is
generated from ``metainterface.__all__`` (``_ext/metainterface_docs.py``). The build
fetches nothing from the network (no intersphinx), and the pages load nothing from it
either: math is rendered to MathML at build time (``_ext/mathml_render.py``), which the
browser draws itself, so the pages read the same offline.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
# The tutorials run in a Jupyter kernel that inherits this environment: one OpenMP thread
# (PyTorch's thread per core collapses when the cores are shared).
os.environ.setdefault("OMP_NUM_THREADS", "1")
# tqdm.auto warns at import in a kernel without ipywidgets; the tutorials show no bars.
os.environ.setdefault("PYTHONWARNINGS", "ignore:IProgress not found")

import metainterface  # noqa: E402

project = "metainterface"
author = "metainterface developers"
copyright = "metainterface developers"
release = metainterface.__version__
version = release

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "mathml_render",
    "metainterface_docs",
]
html_math_renderer = "mathml"

exclude_patterns = ["_build", "figures/*.md", "**/.ipynb_checkpoints", "jupyter_execute"]
templates_path: list[str] = []

# Dead cross-references are errors (with -W). Only third-party types that cannot be resolved
# offline are ignored (no intersphinx: the build must not reach the network).
nitpicky = True
nitpick_ignore_regex = [
    (
        r"py:.*",
        r"(numpy|np|torch|matplotlib|pathlib|os|abc|collections\.abc|typing|scipy|concurrent)\..*",
    ),
    (r"py:class", r"(Tensor|Axes|Figure|Path|PathLike|Sequence|Callable|Mapping)"),
]

# --- autodoc / napoleon: one docstring style, numpydoc ---------------------------------
autodoc_typehints = "signature"
autodoc_typehints_format = "short"
autodoc_member_order = "bysource"
autodoc_class_signature = "separated"
napoleon_google_docstring = False
napoleon_numpy_docstring = True
# Types in "Parameters" and "Returns" are prose ("Design or path", "(N,) array"): shown as
# written, not turned into cross-references.
napoleon_use_param = False
napoleon_use_rtype = False
napoleon_use_ivar = True
napoleon_preprocess_types = False
napoleon_attr_annotations = False
python_use_unqualified_type_names = True
add_module_names = False

# --- MyST-NB: tutorials executed at every build -----------------------------------------
nb_execution_mode = "force"
nb_execution_raise_on_error = True
nb_execution_timeout = 300
nb_execution_show_tb = True
nb_merge_streams = True
nb_output_stderr = "show"
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
myst_dmath_double_inline = True

# --- HTML ---------------------------------------------------------------------------------
# pydata-sphinx-theme: the theme of NumPy, SciPy, pandas and Matplotlib, so the layout is
# the one this field's readers already know (sidebar navigation, API pages, search).
html_theme = "pydata_sphinx_theme"
html_title = f"metainterface {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_static_path = ["_static"]
html_css_files = ["custom.css"]
html_show_sourcelink = False


def _public_bases(app, name, obj, options, bases) -> None:
    """Result classes share their coverage/idle/carrying properties through a small internal
    mixin: the reference shows the properties on each class, not the mixin as a base."""
    bases[:] = [b for b in bases if b.__qualname__ != "ReachCounts"]


def setup(app) -> None:
    app.connect("autodoc-process-bases", _public_bases)
