"""The one exception type users see.

Every check on user input raises :class:`MetainterfaceError` with a message that names the
field and the allowed range; the CLI turns it into a one-line message and exit status 2.
"""

from __future__ import annotations


class MetainterfaceError(ValueError):
    """Invalid user input or an unrecoverable condition explained in one line.

    ``argument``, when set, is the Python name of the argument at fault (``"starts"``); the
    command line shows it under its option name (``--starts``).
    """

    def __init__(self, message: str = "", *, argument: str | None = None) -> None:
        super().__init__(message)
        self.argument = argument


class UnreachableError(MetainterfaceError):
    """A friction law no cell in the design space can follow; ``reachability`` says why
    (the law's friction coefficient, the reachable one and what would make it reachable)."""

    def __init__(self, message: str = "", *, reachability: object = None, target: str = "") -> None:
        super().__init__(message)
        self.reachability = reachability
        self.target = target


class ReachWarning(UserWarning):
    """A target partly outside what a cell reaches (the one reach test of ``reachability``
    and ``feasible_scale``): ``design`` says so once per target, before it starts the work,
    and then designs the closest cell (its ``notes`` keep the same lines)."""


class UnitSlipWarning(UserWarning):
    """A modulus, shear strength or radius that reads as a quantity but is almost surely in
    the wrong unit (``modulus=2.4`` is 2.4 Pa, not 2.4 MPa). The message names the value and
    what was probably meant; silence it with ``warnings.filterwarnings("ignore",
    category=mi.UnitSlipWarning)`` where such a value is meant."""
