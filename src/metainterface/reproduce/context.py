"""What the stages of a reproduction run share (``Context``), and how they name a model file
and a fraction in results.md."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from matplotlib.figure import Figure

from metainterface._files.atomic import write_text
from metainterface.plots import save_figure
from metainterface.reproduce.scales import Scale
from metainterface.surrogate.checkpoint import default_model_path


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
            # the PDF keeps the PNG's layout: laying the text out again costs as much as
            # drawing it, for the same positions
            fig.set_layout_engine("none")
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


def pct(x: float) -> str:
    return f"{100 * x:.2f} %"
