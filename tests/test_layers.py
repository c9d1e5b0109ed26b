"""The package's rooms import one way: no import circle between modules, and no import up
the layer order (a lower room never imports a higher one, even inside a function).

Read from the source with ``ast`` (every import, those inside functions and under
``TYPE_CHECKING`` included), so it costs no import of the package.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "src" / "metainterface"

#: Each room's rank: a module may import rooms of its own rank or lower. Private helpers
#: (``_checks``, ``_files``, ...) and ``errors`` are the ground floor.
RANKS = {
    "physics": 1,
    "data": 2,
    "units": 2,
    "surrogate": 2,
    "inverse": 2,
    "validation": 2,
    "verify": 2,
    "io": 3,
    "plots": 4,
    "designer": 5,
    "scaling": 5,
    "sweep": 5,
    # the studies of a made design (tolerance, printer sizing); the batched errors of made
    # cells that robust design uses too live below, in inverse.scatter
    "manufacture": 6,
    "measure": 6,
    # fits tau and w to a friction test: units and the physics, used by the face and the CLI
    "calibration": 3,
    # data made for the tests and benchmarks (laws near the edge of reach)
    "_testing": 2,
    "api": 7,
    "__init__": 7,  # the lazy face, ``import metainterface as mi``
    "reproduce": 7,
    "cli": 8,
    "__main__": 9,
}


def _module(path: Path) -> str:
    parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _imports() -> dict[str, set[str]]:
    """{module: the package's modules it imports} (``from a import b`` counts ``a.b`` when
    that is a module, else ``a``)."""
    files = {_module(f): f for f in ROOT.rglob("*.py")}
    edges: dict[str, set[str]] = {}
    for name, f in files.items():
        package = name if f.name == "__init__.py" else name.rpartition(".")[0]
        out = edges.setdefault(name, set())
        for node in ast.walk(ast.parse(f.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join([*up, base] if base else up)
                targets = [
                    f"{base}.{a.name}" if f"{base}.{a.name}" in files else base
                    for a in node.names
                    if not (base == "metainterface" and a.name == "__version__")  # metadata
                ]
            else:
                continue
            out.update(t for t in targets if t in files and t != name)
    return edges


def _room(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def _rank(module: str) -> int:
    return RANKS.get(_room(module), 0)


def _cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in edges.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return found


def upward(edges: dict[str, set[str]]) -> list[str]:
    return sorted(f"{a} -> {b}" for a, bs in edges.items() for b in bs if _rank(b) > _rank(a))


def test_every_room_has_a_rank() -> None:
    rooms = {p.name for p in ROOT.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    private = {r for r in rooms if r.startswith("_")}
    assert rooms - private - set(RANKS) == set()


def test_no_import_circle_between_modules() -> None:
    assert _cycles(_imports()) == []


def rooms(edges: dict[str, set[str]]) -> dict[str, set[str]]:
    """{room: the rooms its modules import} (a room: a subpackage or a top-level module)."""
    out: dict[str, set[str]] = {}
    for a, bs in edges.items():
        out.setdefault(_room(a), set()).update(_room(b) for b in bs if _room(b) != _room(a))
    return out


def test_no_import_circle_between_rooms() -> None:
    # rooms of one rank may import each other, but one way only: a circle (inverse ->
    # units -> inverse) means two rooms share a concern
    assert _cycles(rooms(_imports())) == []


def test_no_import_up_the_layers() -> None:
    assert upward(_imports()) == []


if __name__ == "__main__":  # list what the tests would refuse
    e = _imports()
    print("\n".join(map(str, _cycles(e) + _cycles(rooms(e)))))
    print("\n".join(upward(e)))
