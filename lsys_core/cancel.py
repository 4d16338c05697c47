"""Cooperative cancellation and progress reporting for long computations."""

from __future__ import annotations

import threading
from collections.abc import Callable

from lsys_core.errors import Cancelled

__all__ = ["CancelToken", "Progress", "check", "report"]

#: ``progress(stage, fraction)``: ``stage`` names the running stage, ``fraction`` is in [0, 1].
Progress = Callable[[str, float], None]


class CancelToken:
    """A flag a caller sets to ask a running computation to stop.

    Long loops call :meth:`check` between steps; it raises
    :class:`~lsys_core.errors.Cancelled` once :meth:`cancel` was called.
    Thread-safe: the editor cancels from the UI thread while a worker checks.
    """

    def __init__(self) -> None:
        self._event = threading.Event()

    def cancel(self) -> None:
        """Ask the computation to stop at its next check."""
        self._event.set()

    @property
    def cancelled(self) -> bool:
        """Whether :meth:`cancel` was called."""
        return self._event.is_set()

    def check(self) -> None:
        """Raise :class:`Cancelled` if cancellation was requested."""
        if self._event.is_set():
            raise Cancelled("cancelled")


def check(token: CancelToken | None) -> None:
    """Raise :class:`Cancelled` if ``token`` is set (no-op for ``None``)."""
    if token is not None:
        token.check()


def report(progress: Progress | None, stage: str, fraction: float) -> None:
    """Call ``progress(stage, fraction)`` if a callback was given."""
    if progress is not None:
        progress(stage, min(1.0, max(0.0, float(fraction))))
