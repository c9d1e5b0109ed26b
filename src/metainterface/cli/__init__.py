"""The `metainterface` command: argument parsing only, each subcommand calls the library.

Each subcommand lives in its own module here with ``register(subparsers)``, which adds its
parser and sets ``func`` to a ``run(args) -> int`` function. Modules import heavy libraries
inside ``run`` so that ``--help`` stays fast.

Every failure a user can cause ends in one line on stderr and exit status 2: argparse's own
errors too (no usage block), and the library's errors name the option as typed (``--starts``,
not ``starts``). SIGTERM and SIGHUP end a run like Ctrl-C (exit 130), temporaries removed.
"""

from __future__ import annotations

import argparse
import atexit
import contextlib
import importlib
import os
import re
import sys
import threading
import warnings
from collections.abc import Iterator, Sequence
from typing import Any, NoReturn

from metainterface.cli.common import positive_int
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
    "measure",
    "calibrate",
)

#: Commands whose files are written as one set, all or none (the others write as they go,
#: so that an interrupted run resumes: train's checkpoints, reproduce's stages, a sweep).
#: design's files are one set inside mi.design / mi.compare already, so that --html can
#: read them back to make the page (a file staged in a set is not there yet).
ALL_OR_NOTHING = frozenset({"curve", "export", "generate", "evaluate", "measure"})

#: Commands whose torch work is large batched kernels (all of torch's threads where they
#: sleep while waiting); the others run on one thread a process (metainterface._threads).
HEAVY = frozenset({"generate", "train", "evaluate"})

#: Library argument names that a command's options spell differently.
OPTION_NAMES = {
    "design": {
        "model": "--physics",
        "surrogate": "--model",
        "grid": "--verify-grid",
        "loads": "--verify-loads",
        "engine": "--verify-engine",
    },
    "curve": {"model": "--physics"},
    "validate": {"model": "--physics"},
}


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``metainterface design: error: argument --starts: ...``.

    A value that starts with a minus and a digit is a value, units and all
    (``--work-of-adhesion -5mJ/m2``), so that its own check says what range it must be in,
    not "expected one argument" (argparse takes only bare numbers so; no option here starts
    with a digit)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?\d")

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {' '.join(message.split())}\n")


def build_parser() -> argparse.ArgumentParser:
    from metainterface import __version__

    parser = _Parser(
        prog="metainterface",
        description="Inverse design of tribological metainterfaces (alpha(P*) contact laws).",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS:
        importlib.import_module(f"metainterface.cli.{name}").register(sub)
    for command in sub.choices.values():  # one --threads for every command, said once here
        command.add_argument(
            "--threads",
            type=positive_int,
            metavar="N",
            help="torch CPU threads (default: chosen per task, one for designs and BEM, all for "
            "training; OMP_NUM_THREADS is honoured)",
        )
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit status (2 for bad input, with a one-line message)."""
    parser = build_parser()
    args = parser.parse_args(argv)  # --help and argument errors end here, before numpy loads

    from metainterface._files import output_set, terminate_as_interrupt
    from metainterface._threads import set_threads, threads_for
    from metainterface.runtime import tune_allocator

    tune_allocator()
    if args.threads is not None:
        set_threads(args.threads)
    whole = output_set() if args.command in ALL_OR_NOTHING else contextlib.nullcontext()
    work = "heavy" if args.command in HEAVY else "light"
    try:
        with terminate_as_interrupt(), whole, threads_for(work), _unit_slips_in_one_line(args):
            return int(args.func(args) or 0)
    except MetainterfaceError as exc:
        message = " ".join(_as_option(parser, args.command, exc).split())
        print(f"metainterface {args.command}: error: {message}", file=sys.stderr)
        return 2
    except MemoryError:
        print(f"metainterface {args.command}: error: out of memory", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"metainterface {args.command}: interrupted", file=sys.stderr)
        return 130


def run() -> NoReturn:
    """The ``metainterface`` console script and ``python -m metainterface``: ``main()``, then
    a quick exit.

    Python's own exit tears down every module torch and matplotlib loaded, one garbage
    collection after another: 0.8-1.1 s after a design (benchmarks/results/loaded.md), a sixth
    of the main job. Once the command is done and no other thread runs, the exit handlers
    are run (logging, multiprocessing, Dask), the streams flushed, and the process ends at
    once; files were already closed (every write is atomic). With a thread still running,
    Python's ordinary exit waits for it.

    A reader that closes the pipe early (``| head``) ends the printed report, not the
    command: its files are written and its status stands (``_ReaderMayLeave``).
    """
    sys.stdout = _ReaderMayLeave(sys.stdout)
    code = main()
    exit_handlers = getattr(atexit, "_run_exitfuncs", None)  # CPython's, run by every exit
    if threading.active_count() > 1 or exit_handlers is None:
        sys.exit(code)
    exit_handlers()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):  # a pipe closed by `| head`: no loss
            stream.flush()
    os._exit(code)


class _ReaderMayLeave:
    """Standard output whose reader may close the pipe: from the first BrokenPipeError on,
    what is printed goes to os.devnull (the descriptor too, so that the buffered rest
    flushes there at exit), instead of a traceback that aborts the command's files."""

    def __init__(self, stream: Any) -> None:
        self._stream = stream

    def _reader_left(self) -> None:
        with contextlib.suppress(OSError, ValueError):  # no descriptor: nothing to redirect
            os.dup2(os.open(os.devnull, os.O_WRONLY), self._stream.fileno())

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            self._reader_left()
            return len(text)

    def flush(self) -> None:
        try:
            self._stream.flush()
        except BrokenPipeError:
            self._reader_left()

    def __getattr__(self, name: str) -> Any:  # encoding, isatty, fileno, buffer, ...
        return getattr(self._stream, name)


@contextlib.contextmanager
def _unit_slips_in_one_line(args: argparse.Namespace) -> Iterator[None]:
    """Show each unit-slip warning (``--modulus 2.4`` read as 2.4 Pa), each reach warning
    (a target partly out of reach) and any other caution the package raises once, as one
    line on stderr: ``metainterface design:
    warning: modulus 2.4 Pa is below 1 kPa: ...``. The same value is checked on every path
    that reads it (the law, its feasible scale, the design)."""
    from metainterface.cli.common import SHOWN
    from metainterface.errors import ReachWarning, UnitSlipWarning

    default = warnings.showwarning
    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) + os.sep

    def ours(category: type, filename: Any) -> bool:
        # the package's own cautions (the user's inputs, its results), not a library's
        if issubclass(category, UnitSlipWarning | ReachWarning):
            return True
        return issubclass(category, UserWarning) and os.path.abspath(str(filename)).startswith(
            package
        )

    def show(message: Any, category: type, *rest: Any, **kw: Any) -> None:
        if not ours(category, rest[0] if rest else kw.get("filename", "")):
            default(message, category, *rest, **kw)
        elif str(message) not in SHOWN:
            SHOWN.add(str(message))
            print(f"metainterface {args.command}: warning: {message}", file=sys.stderr)

    with warnings.catch_warnings():
        warnings.simplefilter("always", UnitSlipWarning)
        warnings.simplefilter("always", ReachWarning)
        warnings.showwarning = show
        yield


def _as_option(parser: argparse.ArgumentParser, command: str, exc: MetainterfaceError) -> str:
    """The error's message with its argument named as the command's option, if it has one."""
    message, name = str(exc), exc.argument
    if not name or not message.startswith(name):
        return message
    option = OPTION_NAMES.get(command, {}).get(name, "--" + name.replace("_", "-"))
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    known = {s for a in sub.choices[command]._actions for s in a.option_strings}
    return option + message[len(name) :] if option in known else message


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
