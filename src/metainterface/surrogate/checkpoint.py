"""Model files and training checkpoints: plain state dicts, loaded with weights_only=True.

A model file holds {"format", "config", "state_dict"}: config is JSON-ready (cell settings,
architecture, training summary, package version); nothing is ever unpickled.
"""

from __future__ import annotations

import functools
import io
import os
from pathlib import Path
from typing import Any

import torch

from metainterface._files.atomic import write_bytes
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings
from metainterface.surrogate.model import InverseMLP

MODEL_FORMAT = "metainterface/surrogate-v1"


def _on_cpu(obj: Any) -> Any:
    """``obj`` with every tensor in it (nested dicts, lists, tuples) moved to the CPU."""
    if isinstance(obj, torch.Tensor):
        return obj.cpu()  # the tensor itself when it is there already
    if isinstance(obj, dict):
        return {k: _on_cpu(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return type(obj)(_on_cpu(v) for v in obj)
    return obj


def save_torch(path: str | os.PathLike[str], obj: Any) -> Path:
    """torch.save, atomically (write then rename); tensors are saved from the CPU, so a file
    made on a GPU loads anywhere."""
    buf = io.BytesIO()
    torch.save(_on_cpu(obj), buf)
    return write_bytes(path, buf.getvalue())


def load_torch(path: str | os.PathLike[str], what: str = "file") -> Any:
    """torch.load with weights_only=True; one-line errors for missing or foreign files."""
    path = Path(path)
    if path.is_dir():
        raise MetainterfaceError(f"{what} {path}: is a folder, expected a file")
    if not path.is_file():
        raise MetainterfaceError(f"{what} {path}: file not found")
    try:
        return torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:  # corrupt, truncated or unsafe content
        if "weights only" in str(exc).lower():  # torch's long advice to unpickle: never
            why = "it holds Python objects beyond tensors, which are never unpickled"
        else:
            why = "not a PyTorch file, or a truncated or corrupt one"
        raise MetainterfaceError(f"{what} {path}: not a readable weights file ({why})") from None


def save_model(path: str | os.PathLike[str], model: InverseMLP, config: dict[str, Any]) -> Path:
    """Write a model file (weights + JSON-ready config) atomically."""
    state = {k: v.detach().clone() for k, v in model.state_dict().items()}
    return save_torch(path, {"format": MODEL_FORMAT, "config": config, "state_dict": state})


def load_model(path: str | os.PathLike[str]) -> tuple[InverseMLP, CellSettings, dict[str, Any]]:
    """Read a model file -> (model in eval mode, its cell settings, its config)."""
    blob = load_torch(path, "model")
    if not isinstance(blob, dict) or blob.get("format") != MODEL_FORMAT:
        raise MetainterfaceError(f"model {path}: not a metainterface surrogate ({MODEL_FORMAT})")
    config = blob["config"]
    try:
        settings = CellSettings(**config["settings"])
        # files made before the gap scale was a setting used the paper's (max_gap None)
        arch = config.get("model", {"max_gap": None})
        model = InverseMLP(
            settings.n_asperities,
            settings.n_steps,
            arch["max_gap"],
            adhesion_input=bool(arch.get("adhesion_input", False)),
        )
        model.load_state_dict(blob["state_dict"])
    except (KeyError, TypeError, RuntimeError, MetainterfaceError) as exc:
        raise MetainterfaceError(f"model {path}: inconsistent weights file ({exc})") from None
    model.eval()
    return model, settings, config


def design_model(path: str | os.PathLike[str]) -> tuple[InverseMLP, CellSettings, dict[str, Any]]:
    """:func:`load_model` for designing, read once per file version: the same (model,
    settings, config) back while the file's path, size and modification time stay the
    same (a design used to spend ~10 ms reading the weights at every call). The model is
    shared: read it, never change it (``predict`` works on a copy)."""
    path = Path(path).resolve()
    try:
        st = path.stat()
    except OSError:
        return load_model(path)  # the one-line error of a missing file
    return _design_model(path, st.st_size, st.st_mtime_ns)


@functools.lru_cache(maxsize=4)
def _design_model(
    path: Path, size: int, mtime_ns: int
) -> tuple[InverseMLP, CellSettings, dict[str, Any]]:
    return load_model(path)


def default_model_path() -> Path:
    """The surrogate shipped with the package."""
    return Path(__file__).resolve().parents[1] / "weights" / "surrogate.pt"


def default_laws_model_path() -> Path:
    """The shipped friction-law network: the shipped surrogate fine-tuned on targets made the
    way friction laws arrive (``metainterface.surrogate.laws``); `design` also reads targets
    without stiffness with it when it uses the shipped surrogate."""
    return default_model_path().with_name("surrogate_laws.pt")


def default_adhesive_model_path() -> Path:
    """The shipped network for adhesive targets: the friction-law network fine-tuned on
    adhesive loading curves (``metainterface.surrogate.adhesive``); `design` reads a target
    with it too when its model has adhesion and it uses the shipped surrogate."""
    return default_model_path().with_name("surrogate_adhesive.pt")
