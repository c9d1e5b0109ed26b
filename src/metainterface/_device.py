"""The one ``device`` option: where torch work runs ("auto", "cpu", "cuda", "cuda:N").

Every function that takes ``device=`` (and every ``--device`` option) resolves it here, so
the accepted values and the error a user sees are the same everywhere.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from metainterface.errors import MetainterfaceError

if TYPE_CHECKING:  # torch is imported only when a device is resolved
    import torch

#: What ``device=`` accepts (besides "cuda:N" and a ``torch.device``).
DEVICES = ("auto", "cpu", "cuda")


def resolve_device(
    device: Any = "auto", *, name: str = "device", small: bool = False
) -> torch.device:
    """The torch device for ``device``.

    "auto" takes the first CUDA device when torch sees one, else the CPU, except for
    ``small`` work, which "auto" keeps on the CPU: a design's refinement is thousands of
    small sequential steps on a few rows, bound by kernel-launch latency on a GPU
    (``benchmarks/results/devices.md``). "cpu"; "cuda" or "cuda:N" (refused, in one line,
    when torch sees no such device); a ``torch.device`` as is. Raises MetainterfaceError
    naming ``name`` and the allowed values on anything else.
    """
    import torch

    if isinstance(device, torch.device):
        text = str(device)
    elif isinstance(device, str):
        text = device.strip().lower()
    else:
        raise MetainterfaceError(
            f"{name} must be one of {', '.join(DEVICES)} or cuda:N, got {device!r}", argument=name
        )
    if text == "auto":
        return torch.device("cuda" if torch.cuda.is_available() and not small else "cpu")
    if text == "cpu":
        return torch.device("cpu")
    if text == "cuda" or text.startswith("cuda:"):
        index = text.partition(":")[2]
        if index and not index.isdigit():
            raise MetainterfaceError(
                f"{name} must be one of {', '.join(DEVICES)} or cuda:N, got {device!r}",
                argument=name,
            )
        if not torch.cuda.is_available():
            raise MetainterfaceError(
                f"{name}={text!r}: torch sees no CUDA device here (use device='cpu' or 'auto')",
                argument=name,
            )
        if index and int(index) >= torch.cuda.device_count():
            raise MetainterfaceError(
                f"{name}={text!r}: torch sees {torch.cuda.device_count()} CUDA device(s), "
                f"allowed cuda:0 .. cuda:{torch.cuda.device_count() - 1}",
                argument=name,
            )
        return torch.device(text)
    raise MetainterfaceError(
        f"{name} must be one of {', '.join(DEVICES)} or cuda:N, got {device!r}", argument=name
    )
