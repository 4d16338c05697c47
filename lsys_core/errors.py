"""One exception family for everything the library reports to a user.

Every error a user can cause (bad SVG, bad rule text, absurd parameters) is an
:class:`LsysError`; its ``str()`` is a single readable line.  The CLI and the
editor catch ``LsysError`` only, so anything else is a bug and shows as one.
"""

from __future__ import annotations

__all__ = [
    "Cancelled",
    "GrammarError",
    "GrammarSyntaxError",
    "InferenceError",
    "LimitError",
    "LsysError",
    "SvgError",
]


class LsysError(Exception):
    """Base class of every error the library reports to a user."""


class SvgError(LsysError):
    """An SVG file cannot be read, or holds nothing usable."""


class GrammarError(LsysError):
    """A grammar is invalid (undefined symbol, non-terminating rule, bad value)."""


class GrammarSyntaxError(GrammarError):
    """Rule text cannot be parsed; carries the 1-based ``line`` and ``column``."""

    def __init__(self, message: str, line: int, column: int) -> None:
        super().__init__(f"{line}:{column}: {message}")
        self.message = message
        self.line = line
        self.column = column


class InferenceError(LsysError):
    """Inference failed on an input (e.g. nothing drawable)."""


class LimitError(LsysError):
    """A configured limit (element count, file size, recursion) was reached."""


class Cancelled(LsysError):
    """A long computation was cancelled through its :class:`~lsys_core.cancel.CancelToken`."""
