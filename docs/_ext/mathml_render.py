"""Math rendered to MathML when the pages are built: no script, nothing fetched.

Sphinx's default renderer loads MathJax from a CDN when a page is viewed, so opened offline
(a lab network, a plane) every formula shows as raw TeX. Browsers draw MathML themselves
(MathML Core: Chromium 109+, Firefox, Safari), so the TeX is converted once, at build time,
with latex2mathml; a formula it cannot convert fails the build (warnings are errors).
"""

from __future__ import annotations

from typing import Any

from docutils import nodes
from latex2mathml.converter import convert
from sphinx.application import Sphinx
from sphinx.errors import ExtensionError


def _mathml(latex: str, display: str, where: Any) -> str:
    try:
        return convert(latex.strip(), display=display)
    except Exception as exc:  # latex2mathml raises its own exception types
        raise ExtensionError(f"{where}: cannot render {latex.strip()!r} as MathML: {exc}") from exc


def visit_math(self: Any, node: nodes.math) -> None:
    self.body.append(self.starttag(node, "span", "", CLASS="math notranslate"))
    self.body.append(_mathml(node.astext(), "inline", node.source or node.line))
    self.body.append("</span>")
    raise nodes.SkipNode


def visit_math_block(self: Any, node: nodes.math_block) -> None:
    self.body.append(self.starttag(node, "div", CLASS="math notranslate"))
    if node.get("number"):
        number = f"({node['number']})"
        self.body.append(f'<span class="eqno">{number}</span>')
    self.body.append(_mathml(node.astext(), "block", node.source or node.line))
    self.body.append("</div>\n")
    raise nodes.SkipNode


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_html_math_renderer("mathml", (visit_math, None), (visit_math_block, None))
    return {"parallel_read_safe": True, "parallel_write_safe": True}
