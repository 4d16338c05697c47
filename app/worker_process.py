"""The editor's worker process: a compute function run in a persistent child process.

Work that holds the GIL for long stretches (pure-Python loops) starves the UI thread; such work
runs in a worker process (:class:`ProcessCompute`, the same request → compute → apply interface
as a thread of :class:`~app.workers.LatestRunner`): the runner's worker thread then only waits
on a pipe, cancellation is forwarded to the process's own token, and a process that ignores it
is killed.  This module imports no Qt, so neither does the process.
"""

from __future__ import annotations

import logging
import multiprocessing as mp
import threading
import time
import traceback
from collections.abc import Callable
from typing import Any

from lsys_core.cancel import CancelToken, Progress
from lsys_core.errors import Cancelled, LsysError
from lsys_core.parallel import switching_often

__all__ = [
    "CANCEL_GRACE_S",
    "PROGRESS_INTERVAL",
    "Compute",
    "ProcessCompute",
    "RemoteBug",
    "RemoteError",
    "error_message",
]

log = logging.getLogger(__name__)

#: ``compute(request, cancel, progress) -> result``; runs on a worker thread.
Compute = Callable[[Any, CancelToken, Progress], Any]

PROGRESS_INTERVAL = 0.03  # seconds between two forwarded progress reports of one stage
CANCEL_GRACE_S = 1.0  # a process that does not stop this long after a cancel is killed


class RemoteError(LsysError):
    """A user-caused failure reported by the worker process (its one-line message)."""


class RemoteBug(RuntimeError):
    """An unexpected exception in the worker process (logged there and here)."""


def _child_main(conn, compute: Compute, preload: tuple[str, ...]) -> None:
    """Serve requests in a worker process until the pipe closes."""
    import importlib

    for name in preload:  # import the heavy modules while the parent is still busy
        importlib.import_module(name)
    send_lock = threading.Lock()

    def send(msg) -> None:
        with send_lock:
            conn.send(msg)

    while True:
        try:
            msg = conn.recv()
        except (EOFError, OSError):
            return
        if msg[0] != "run":
            continue  # a late cancel for a job that already ended
        token = CancelToken()
        stop = threading.Event()

        def watch(token=token, stop=stop) -> None:
            # The parent sends ("cancel",) while a job runs; poll so the job can end on its own.
            while not stop.is_set():
                try:
                    if conn.poll(0.02) and conn.recv()[0] == "cancel":
                        token.cancel()
                except (EOFError, OSError):
                    token.cancel()
                    return

        watcher = threading.Thread(target=watch, daemon=True)
        watcher.start()
        last = {"stage": None, "t": 0.0}

        def progress(stage: str, fraction: float, last=last, token=token) -> None:
            now = time.monotonic()
            if stage != last["stage"] or fraction >= 1.0 or now - last["t"] >= PROGRESS_INTERVAL:
                last["stage"], last["t"] = stage, now
                try:
                    send(("progress", stage, float(fraction)))
                except OSError:  # the editor has gone away: stop working
                    token.cancel()

        try:
            with switching_often():  # the process's threads share its interpreter (see the function)
                reply = ("done", compute(msg[1], token, progress))
        except Cancelled:
            reply = ("cancelled",)
        except Exception as exc:
            reply = ("error", error_message(exc), traceback.format_exc(), isinstance(exc, LsysError))
        stop.set()
        watcher.join()
        try:
            send(reply)
        except OSError:  # the editor has gone away
            return


class ProcessCompute:
    """Run a picklable compute function in a persistent worker process.

    Use it as the ``compute`` of a :class:`LatestRunner`: the runner's worker thread sends the
    request through a pipe and waits for progress messages and the result, so the UI thread
    never competes for the GIL with the computation.  Cancelling the runner's token is
    forwarded to the process (which raises :class:`~lsys_core.errors.Cancelled` there); a
    process that does not stop within :data:`CANCEL_GRACE_S` is killed and restarted on the
    next request, so cancellation always takes effect.

    Parameters
    ----------
    compute : callable
        A module-level (picklable) ``compute(request, cancel, progress) -> result``; its module
        should not import Qt (the process does not need it).
    preload : sequence of str
        Modules the process imports as soon as it starts.
    """

    def __init__(self, compute: Compute, preload: tuple[str, ...] = ()) -> None:
        self._compute = compute
        self._preload = tuple(preload)
        self._lock = threading.Lock()
        self._proc: Any = None
        self._conn: Any = None

    def start(self) -> None:
        """Start the worker process now (it imports the preloads while the caller goes on).

        Never waits: if a job is running, the process is already there.
        """
        if self._lock.acquire(blocking=False):
            try:
                self._ensure()
            finally:
                self._lock.release()

    def _ensure(self) -> None:
        if self._proc is not None and self._proc.is_alive():
            return
        self._kill()
        ctx = mp.get_context("spawn")
        parent, child = ctx.Pipe()
        self._proc = ctx.Process(
            target=_child_main, args=(child, self._compute, self._preload), name="lsys-worker", daemon=True
        )
        self._proc.start()
        child.close()
        self._conn = parent

    def _kill(self) -> None:
        if self._conn is not None:
            self._conn.close()
            self._conn = None
        if self._proc is not None:
            if self._proc.is_alive():
                self._proc.kill()
            self._proc.join(5.0)
            self._proc = None

    def __call__(self, request: Any, cancel: CancelToken, progress: Progress) -> Any:
        """Compute ``request`` in the worker process (called on a worker thread)."""
        with self._lock:
            self._ensure()
            conn = self._conn
            conn.send(("run", request))
            cancelled_at = None
            while True:
                if cancel.cancelled and cancelled_at is None:
                    conn.send(("cancel",))
                    cancelled_at = time.monotonic()
                if cancelled_at is not None and time.monotonic() - cancelled_at > CANCEL_GRACE_S:
                    log.warning("worker process ignored a cancel for %.1f s: restarting it", CANCEL_GRACE_S)
                    self._kill()
                    raise Cancelled("cancelled")
                try:
                    ready = conn.poll(0.02)
                    msg = conn.recv() if ready else None
                except (EOFError, OSError):
                    msg = None
                    ready = True
                if msg is None:
                    if ready or not self._proc.is_alive():
                        self._kill()
                        raise RemoteBug("the worker process ended unexpectedly")
                    continue
                if msg[0] == "progress":
                    progress(msg[1], msg[2])
                elif msg[0] == "done":
                    return msg[1]
                elif msg[0] == "cancelled":
                    raise Cancelled("cancelled")
                else:
                    _, message, tb, user = msg
                    if user:
                        raise RemoteError(message)
                    log.error("worker process failed:\n%s", tb)
                    raise RemoteBug(message)

    def close(self) -> None:
        """End the worker process."""
        with self._lock:
            if self._conn is not None:
                self._conn.close()  # the process sees EOF and returns
                self._conn = None
            if self._proc is not None:
                self._proc.join(2.0)
            self._kill()


def error_message(exc: BaseException) -> str:
    """Return the one-line message shown to the user for ``exc``.

    An :class:`~lsys_core.errors.LsysError` is a user-caused failure and shows its own
    message; anything else is a bug, logged with its traceback and shown as such.
    """
    if isinstance(exc, LsysError):
        return str(exc) or type(exc).__name__
    if isinstance(exc, RemoteBug):
        return str(exc)
    return f"internal error ({type(exc).__name__}: {exc}); see the log"
