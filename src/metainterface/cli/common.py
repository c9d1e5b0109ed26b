"""Argument types shared by subcommands: they turn bad values into one-line errors."""

from __future__ import annotations

import argparse
import math

#: The one-line warnings this command has printed (each printed once; the notes that repeat
#: one are not printed again).
SHOWN: set[str] = set()


def positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {value}")
    return value


def positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text}")
    return value


def add_device(parser: argparse.ArgumentParser) -> None:
    """``--device``: where the command's torch work runs, checked by the library
    (``metainterface._device.resolve_device``) so the values and errors match the API's."""
    parser.add_argument(
        "--device",
        default="auto",
        metavar="DEVICE",
        help="auto, cpu, cuda or cuda:N (default auto: CUDA when torch sees it, but a design's "
        "refinement on the CPU, faster there)",
    )
