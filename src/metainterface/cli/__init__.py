"""The `metainterface` command: argument parsing only, each subcommand calls the library.

Each subcommand lives in its own module here with ``register(subparsers)``, which adds its
parser and sets ``func`` to a ``run(args) -> int`` function. Modules import heavy libraries
inside ``run`` so that ``--help`` stays fast.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from metainterface.errors import MetainterfaceError

# Subcommand modules, in the order `--help` lists them.
COMMANDS: tuple[str, ...] = (
    "design",
    "curve",
    "generate",
    "train",
    "evaluate",
    "export",
    "tolerance",
    "validate",
    "reproduce",
    "view",
)


def build_parser() -> argparse.ArgumentParser:
    from metainterface import __version__

    parser = argparse.ArgumentParser(
        prog="metainterface",
        description="Inverse design of tribological metainterfaces (alpha(P*) contact laws).",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS:
        importlib.import_module(f"metainterface.cli.{name}").register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit status (2 for bad input, with a one-line message)."""
    from metainterface.runtime import tune_allocator

    parser = build_parser()
    args = parser.parse_args(argv)
    tune_allocator()
    try:
        return int(args.func(args) or 0)
    except MetainterfaceError as exc:
        print(f"metainterface {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"metainterface {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
