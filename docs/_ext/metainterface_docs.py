"""Sphinx extension of the metainterface docs: the API reference from ``__all__``, the
reproduced figures from ``docs/figures``, and references to public names by any path.

* At ``builder-inited`` the pages of ``reference/generated/`` are (re)written: one per name
  in ``metainterface.__all__``, grouped by the section list of the package docstring (what
  ``help(mi)`` prints), plus one per type that a public signature mentions but that is not
  public itself (``RefineSettings``, ``PressureCheck``, ...). A name added to ``__all__``
  appears without anyone editing the docs; a public name without a docstring is a warning,
  and so (with ``-W``) a failed build.
* ``missing-reference``: autodoc writes type hints with the defining module
  (``metainterface.designer.results.DesignResult``); such a reference resolves to the public
  name (``metainterface.DesignResult``) when that is the same object.
* The ``reproduced-figures`` directive shows every PNG of a folder with its caption ``.txt``
  (what ``metainterface reproduce`` writes), in the order of its ``results.md``.
"""

from __future__ import annotations

import builtins
import importlib
import inspect
import itertools
import re
import sys
from pathlib import Path
from typing import Any, ClassVar

from docutils import nodes
from docutils.parsers.rst import directives
from sphinx.application import Sphinx
from sphinx.pycode import ModuleAnalyzer
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective

logger = logging.getLogger(__name__)

PACKAGE = "metainterface"
GENERATED = Path("reference") / "generated"
OTHER = "Other public names"


# --- what is public, and its documentation -------------------------------------------------


def public_names(module: Any) -> list[str]:
    """The names of ``module.__all__``, in its order."""
    return list(getattr(module, "__all__", []))


def sections(module: Any) -> dict[str, list[str]]:
    """{section title: names} from the package docstring's section list (a title line, then
    an indented line of comma-separated names); names of ``__all__`` that no section lists
    go to ``OTHER``."""
    public = public_names(module)
    out: dict[str, list[str]] = {}
    lines = (module.__doc__ or "").splitlines()
    for title, body in itertools.pairwise(lines):
        if not title.strip() or title.startswith(" ") or not body.startswith("    "):
            continue
        names = [n.strip() for n in re.sub(r"\(.*?\)", "", body).split(",")]
        names = [n for n in names if n in public]
        if names:
            out.setdefault(title.strip(), []).extend(n for n in names if n not in _listed(out))
    listed = _listed(out)
    rest = [n for n in public if n not in listed]
    if rest:
        out[OTHER] = rest
    return out


def _listed(groups: dict[str, list[str]]) -> set[str]:
    return {n for names in groups.values() for n in names}


def attribute_comment(obj: Any, name: str) -> str | None:
    """The ``#:`` doc comment of a module-level binding of ``obj`` (the package's own module
    first, then the module where ``name`` is bound to the same object)."""
    for modname in [PACKAGE, *sorted(m for m in sys.modules if m.startswith(PACKAGE + "."))]:
        mod = sys.modules.get(modname)
        if mod is None or getattr(mod, name, None) is not obj:
            continue
        try:
            docs = ModuleAnalyzer.for_module(modname).find_attr_docs()
        except Exception:  # a module without source (compiled): no comments to read
            continue
        lines = docs.get(("", name))
        if lines and "".join(lines).strip():
            return "\n".join(lines).strip()
    return None


def own_docstring(obj: Any) -> str | None:
    """The docstring a class or function wrote itself (not the one dataclasses make up, nor
    one inherited from a base class)."""
    doc = obj.__dict__.get("__doc__") if isinstance(obj, type) else getattr(obj, "__doc__", None)
    if not doc or not doc.strip():
        return None
    if isinstance(obj, type) and doc.startswith(f"{obj.__name__}("):
        return None  # dataclasses' generated "Name(field: type, ...)"
    return doc


def missing_docs(module: Any) -> list[str]:
    """Public names of ``module`` with no docstring (classes and functions) or no ``#:``
    doc comment (data)."""
    out = []
    for name in public_names(module):
        obj = getattr(module, name)
        if inspect.isclass(obj) or callable(obj):
            if own_docstring(obj) is None:
                out.append(name)
        elif attribute_comment(obj, name) is None:
            out.append(name)
    return out


# --- types a public signature mentions -----------------------------------------------------

_IDENT = re.compile(r"[A-Za-z_][A-Za-z_0-9.]*")


def _annotations(obj: Any) -> list[tuple[str, dict[str, Any]]]:
    """(annotation string, namespace to resolve it in) of a function, or of a class's
    fields, public methods and properties."""
    items: list[tuple[Any, Any]] = []
    if inspect.isclass(obj):
        items.append((obj, obj))
        for attr, member in vars(obj).items():
            if attr.startswith("_") and attr != "__init__":
                continue
            if isinstance(member, property):
                member = member.fget
            if isinstance(member, staticmethod | classmethod):
                member = member.__func__
            if inspect.isfunction(member):
                items.append((member, member))
    elif callable(obj):
        items.append((obj, obj))
    out = []
    for holder, owner in items:
        try:
            ann = inspect.get_annotations(holder)
        except TypeError:
            continue
        namespace = vars(sys.modules.get(getattr(owner, "__module__", ""), builtins))
        out.extend((a if isinstance(a, str) else repr(a), namespace) for a in ann.values())
    return out


def supporting_types(module: Any) -> list[type]:
    """Classes of the package that public signatures (or the signatures of these classes,
    recursively) mention but that are not public themselves, in a stable order."""
    public_objs = {id(getattr(module, n)) for n in public_names(module)}
    todo = [getattr(module, n) for n in public_names(module)]
    seen: dict[int, type] = {}
    while todo:
        obj = todo.pop(0)
        for text, namespace in _annotations(obj):
            for ident in _IDENT.findall(text):
                head, *rest = ident.split(".")
                found = namespace.get(head)
                for part in rest:
                    found = getattr(found, part, None)
                if not (
                    inspect.isclass(found)
                    and found.__module__.startswith(PACKAGE + ".")
                    and id(found) not in public_objs
                    and id(found) not in seen
                ):
                    continue
                seen[id(found)] = found
                todo.append(found)
    return sorted(seen.values(), key=lambda c: (c.__module__, c.__qualname__))


# --- the generated pages ---------------------------------------------------------------------


def _title(text: str, char: str = "=") -> list[str]:
    return [text, char * len(text), ""]


def _object_page(name: str, obj: Any, full: str, module: str) -> str:
    """The rst page of one object, documented as ``full`` (module.name)."""
    lines = [*_title(name), f".. currentmodule:: {module}", ""]
    if inspect.isclass(obj):
        lines += [f".. autoclass:: {full}", "   :members:", "   :special-members: __call__"]
        if obj.__bases__ != (object,):
            lines += ["   :show-inheritance:"]
    elif callable(obj):
        lines += [f".. autofunction:: {full}"]
    else:
        value = repr(obj)
        if len(value) > 200:
            value = f"{type(obj).__name__} of {len(obj)}" if hasattr(obj, "__len__") else ""
        lines += [f".. py:data:: {name}", f"   :type: {type(obj).__name__}"]
        if value:
            lines += [f"   :value: {value}"]
        lines += [""]
        doc = attribute_comment(obj, name) or ""
        lines += ["   " + line if line else "" for line in doc.splitlines()]
    return "\n".join(lines) + "\n"


def first_sentence(text: str) -> str:
    """The first sentence of a docstring's first paragraph: up to a full stop followed by a
    capital letter or the end ("paper sec. 2.3" and "fig. 5" do not end it)."""
    para = " ".join(text.strip().split("\n\n")[0].split())
    match = re.search(r"\.(?=\s+[A-Z`(]|$)", para)
    return para[: match.end()] if match else para


def _summary(names: list[str], module: str, docs: dict[str, str]) -> list[str]:
    """A two-column table: each name linked to its page, and its docstring's first sentence."""
    lines = [f".. currentmodule:: {module}", "", ".. list-table::", "   :widths: 25 75", ""]
    for n in names:
        lines += [f"   * - :py:obj:`{n}`", f"     - {first_sentence(docs.get(n, '')) or ' '}"]
    return [*lines, ""]


def _doc_of(obj: Any, name: str) -> str:
    if inspect.isclass(obj) or callable(obj):
        return own_docstring(obj) or ""
    return attribute_comment(obj, name) or ""


def write_reference(srcdir: Path) -> list[str]:
    """(Re)write ``reference/generated`` under ``srcdir``; returns the public names without
    docs (each also logged as a warning)."""
    module = importlib.import_module(PACKAGE)
    out = srcdir / GENERATED
    out.mkdir(parents=True, exist_ok=True)
    pages: dict[str, str] = {}
    body = []
    for title, names in sections(module).items():
        body += _title(title, "-")
        body += _summary(names, PACKAGE, {n: _doc_of(getattr(module, n), n) for n in names})
        for n in names:
            pages[f"{PACKAGE}.{n}"] = _object_page(n, getattr(module, n), f"{PACKAGE}.{n}", PACKAGE)
    extra = supporting_types(module)
    if extra:
        body += _title("Types the public functions take or return", "-")
        body += [
            "Not imported by ``import metainterface``, but met as arguments and results of the",
            "functions above. Each is documented under the module that defines it.",
            "",
        ]
        by_module: dict[str, dict[str, str]] = {}
        for cls in extra:
            by_module.setdefault(cls.__module__, {})[cls.__qualname__] = _doc_of(cls, "")
            full = f"{cls.__module__}.{cls.__qualname__}"
            # titled by the full path: two modules may each have a class of one name
            pages[full] = _object_page(full, cls, full, cls.__module__)
        for mod, docs in by_module.items():
            body += _summary(list(docs), mod, docs)
    body += [".. toctree::", "   :hidden:", "", *(f"   generated/{p}" for p in pages), ""]
    files = {f"{p}.rst": text for p, text in pages.items()}
    files["_body.inc"] = "\n".join(body) + "\n"
    for old in out.iterdir():
        if old.name not in files:
            old.unlink()
    for fname, text in files.items():
        path = out / fname
        # unchanged pages keep their time stamp, so an incremental build does not redo them
        if not path.exists() or path.read_text(encoding="utf-8") != text:
            path.write_text(text, encoding="utf-8")
    missing = missing_docs(module)
    for name in missing:
        logger.warning(
            "public name %s.%s has no docstring (or, for data, no '#:' comment)", PACKAGE, name
        )
    return missing


def _on_builder_inited(app: Sphinx) -> None:
    if (Path(app.srcdir) / "reference" / "index.rst").exists():  # the docs, not a test page
        write_reference(Path(app.srcdir))


def _prose_types(
    app: Sphinx, what: str, name: str, obj: Any, options: Any, lines: list[str]
) -> None:
    """Show napoleon's ``:vartype x: ndarray, shape (K,)`` as prose in front of the ``:ivar:``
    description: Sphinx would make a cross-reference of every word of it. Runs after
    napoleon."""
    # ":ivar a, b: ..." would read as a variable b of type "a,": one word, a zero-width space
    # after each comma
    lines[:] = [
        re.sub(
            r"^:ivar ([^:]+):", lambda m: ":ivar " + m.group(1).replace(", ", ",\u200b") + ":", line
        )
        if line.startswith(":ivar ")
        else line
        for line in lines
    ]
    types = {}
    for line in lines:
        match = re.match(r":vartype (.+?): (.*)$", line)
        if match:
            types[match.group(1).replace(", ", ",\u200b")] = match.group(2)
    out = []
    for line in lines:
        if line.startswith(":vartype "):
            continue
        match = re.match(r"(:ivar (.+?):)( ?)(.*)$", line)
        if match and match.group(2) in types:
            line = f"{match.group(1)} *({types[match.group(2)]})* {match.group(4)}".rstrip()
        out.append(line)
    lines[:] = out


def _prose_first_line(
    app: Sphinx, what: str, name: str, obj: Any, options: Any, lines: list[str]
) -> None:
    """Keep a property's first line as prose. Napoleon reads "P* at Delta_max: the largest
    load" as a type ("P* at Delta_max") and a description; this project's docstrings mean
    prose, so the ":type:" napoleon made goes back in front of the text. Runs after it."""
    if what not in ("property", "attribute"):
        return
    typed = [i for i, line in enumerate(lines) if line.startswith(":type: ")]
    if not typed:
        return
    head = lines.pop(typed[0])[len(":type: ") :]
    first = next((i for i, line in enumerate(lines) if line.strip()), None)
    if first is None:
        lines.append(head)
    else:
        lines[first] = f"{head}: {lines[first].lstrip()}"


def _parsable_signature(
    app: Sphinx,
    what: str,
    name: str,
    obj: Any,
    options: Any,
    signature: str | None,
    annotation: str | None,
) -> tuple[str | None, str | None] | None:
    """Dataclass fields with a default factory show as ``= <factory>``, which is no Python:
    the signature parser would then split ``tuple[str, ...]`` at its comma."""
    if signature and "<factory>" in signature:
        return signature.replace("<factory>", "..."), annotation
    return None


def _on_missing_reference(app: Sphinx, env: Any, node: Any, contnode: Any) -> Any:
    """Resolve ``metainterface.sub.module.Name`` to ``metainterface.Name`` when public."""
    if node.get("refdomain") != "py":
        return None
    target = node.get("reftarget", "")
    if not target.startswith(PACKAGE + ".") or target.count(".") < 2:
        return None
    modname, _, attr = target.rpartition(".")
    try:
        obj = getattr(importlib.import_module(modname), attr)
    except (ImportError, AttributeError):
        return None
    package = sys.modules[PACKAGE]
    for name in public_names(package):
        if getattr(package, name) is obj:
            domain = env.get_domain("py")
            return domain.resolve_xref(
                env,
                node["refdoc"],
                app.builder,
                node["reftype"],
                f"{PACKAGE}.{name}",
                node,
                contnode,
            )
    return None


# --- the reproduced figures ------------------------------------------------------------------


class ReproducedFigures(SphinxDirective):
    """Every ``NAME.png`` of a folder with ``NAME.txt`` as its caption.

    The folder is relative to the document; figures come in the order of the folder's
    ``results.md`` "Files" list, then any others by name.
    """

    required_arguments = 1
    option_spec: ClassVar[dict[str, Any]] = {"width": directives.unchanged}

    def run(self) -> list[nodes.Node]:
        rel = self.arguments[0]
        docdir = Path(self.env.doc2path(self.env.docname)).parent
        folder = (docdir / rel).resolve()
        if not folder.is_dir():
            raise self.error(f"reproduced-figures: no folder {folder}")
        pngs = {p.stem: p for p in folder.glob("*.png")}
        order = []
        results = folder / "results.md"
        if results.exists():
            order = re.findall(r"^- `([^`]+)`:", results.read_text(encoding="utf-8"), re.M)
        stems = [s for s in order if s in pngs] + sorted(s for s in pngs if s not in order)
        if not stems:
            raise self.error(f"reproduced-figures: no PNG in {folder}")
        width = self.options.get("width", "100%")
        lines: list[str] = []
        for stem in stems:
            caption = folder / f"{stem}.txt"
            text = caption.read_text(encoding="utf-8").strip() if caption.exists() else stem
            self.env.note_dependency(str(caption))
            lines += [f"```{{figure}} {rel}/{stem}.png", f":width: {width}", f":name: {stem}", ""]
            lines += [f"**{stem}.** " + text.replace("\n\n", "\n\n"), "```", ""]
        return self.parse_text_to_nodes("\n".join(lines))


def setup(app: Sphinx) -> dict[str, Any]:
    app.connect("builder-inited", _on_builder_inited)
    app.connect("autodoc-process-docstring", _prose_first_line, priority=600)
    app.connect("autodoc-process-docstring", _prose_types, priority=600)
    app.connect("autodoc-process-signature", _parsable_signature)
    app.connect("missing-reference", _on_missing_reference)
    app.add_directive("reproduced-figures", ReproducedFigures)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
