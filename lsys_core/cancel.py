"""Cooperative cancellation and progress reporting for long computations."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from lsys_core.errors import Cancelled

__all__ = ["CancelToken", "Progress", "check", "report"]

#: ``progress(stage, fraction)``: ``stage`` names the running stage, ``fraction`` is in [0, 1].
Progress = Callable[[str, float], None]
#: A token made with ``share_gil`` lets other threads run at most this often (seconds) ...
SHARE_EVERY = 0.003
#: ... by sleeping this long (seconds): long enough for a waiting thread to wake up and take the GIL.
SHARE_NAP = 0.0001


class CancelToken:
    """A flag a caller sets to ask a running computation to stop.

    Long loops call :meth:`check` between steps; it raises
    :class:`~lsys_core.errors.Cancelled` once :meth:`cancel` was called.
    Thread-safe: the editor cancels from the UI thread while a worker checks.

    Parameters
    ----------
    share_gil : bool
        Make :meth:`check` also let other threads run: at most every :data:`SHARE_EVERY`
        seconds it sleeps :data:`SHARE_NAP` seconds.  A worker thread making many short numpy
        calls re-takes the GIL before a waiting thread wakes up (CPython's "convoy effect"),
        so the switch interval alone does not let the UI thread in: measured on 2 cores, a
        derivation of 120 small rules in a worker kept a 1 ms UI timer waiting up to 69 ms;
        with the naps, 7 ms, and the derivation takes as long as before.
    """

    def __init__(self, *, share_gil: bool = False) -> None:
        self._event = threading.Event()
        self._share = share_gil
        self._last = time.perf_counter()

    def cancel(self) -> None:
        """Ask the computation to stop at its next check."""
        self._event.set()

    @property
    def cancelled(self) -> bool:
        """Whether :meth:`cancel` was called."""
        return self._event.is_set()

    def check(self) -> None:
        """Raise :class:`Cancelled` if cancellation was requested (and share the GIL if asked)."""
        if self._share:
            now = time.perf_counter()
            if now - self._last >= SHARE_EVERY:
                time.sleep(SHARE_NAP)
                self._last = time.perf_counter()
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
