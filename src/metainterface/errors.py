"""The one exception type users see.

Every check on user input raises :class:`MetainterfaceError` with a message that names the
field and the allowed range; the CLI turns it into a one-line message and exit status 2.
"""


class MetainterfaceError(ValueError):
    """Invalid user input or an unrecoverable condition explained in one line."""
