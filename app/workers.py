"""Background computation for the editor: request → compute → apply, the newest result wins.

This is the only module of the editor that starts threads.  A :class:`LatestRunner` takes
requests on the UI thread (a snapshot of immutable values), computes them one at a time on a
worker thread, and hands the result back to the UI thread through a queued signal.  A new
request cancels the running computation through its :class:`~lsys_core.cancel.CancelToken`,
replaces any request still waiting, and only the result of the newest request is applied.
Requests can be debounced so that a slider drag runs one computation per pause, not per pixel.

Work that holds the GIL for long stretches (pure-Python loops) would starve the UI thread; such
work can run in a worker process instead (:class:`ProcessCompute`): the worker thread then only
waits on a pipe, and cancellation is forwarded to the process's own token.
"""

from __future__ import annotations

import logging
import multiprocessing as mp
import threading
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from PySide6.QtCore import QObject, Qt, QTimer, Signal

from lsys_core.cancel import CancelToken, Progress
from lsys_core.errors import Cancelled, LsysError

__all__ = ["Compute", "LatestRunner", "ProcessCompute", "error_message"]

log = logging.getLogger(__name__)

#: ``compute(request, cancel, progress) -> result``; runs on a worker thread.
Compute = Callable[[Any, CancelToken, Progress], Any]

_PROGRESS_INTERVAL = 0.03  # seconds between two forwarded progress reports of one stage


def error_message(exc: BaseException) -> str:
    """Return the one-line message shown to the user for ``exc``.

    An :class:`~lsys_core.errors.LsysError` is a user-caused failure and shows its own
    message; anything else is a bug, logged with its traceback and shown as such.
    """
    if isinstance(exc, LsysError):
        return str(exc) or type(exc).__name__
    return f"internal error ({type(exc).__name__}: {exc}); see the log"


class _JobSignals(QObject):
    """Signals a worker thread emits; they are queued to the runner on the UI thread."""

    progress = Signal(int, str, float)
    done = Signal(int, object)
    failed = Signal(int, str)
    cancelled = Signal(int)


@dataclass
class _Job:
    generation: int
    request: Any
    token: CancelToken
    signals: _JobSignals
    thread: threading.Thread | None = None


class LatestRunner(QObject):
    """Run a computation off the UI thread, one job at a time, applying only the newest result.

    Parameters
    ----------
    compute : callable
        ``compute(request, cancel, progress) -> result``, called on a worker thread; it must
        only read ``request`` (an immutable snapshot) and check ``cancel`` regularly.
    debounce_ms : int
        Delay before a submitted request starts; every new request restarts the delay.
    name : str
        Name of the worker threads (for logs and debuggers).
    prepare : callable, optional
        ``prepare(request) -> request``, called on the UI thread just before a job starts, to
        complete the snapshot with resources that depend on what is on screen at that moment.

    Signals
    -------
    started()
        A job started on the worker thread.
    progress(stage, fraction)
        Progress of the newest job.
    resultReady(result)
        The newest request's result, on the UI thread.
    failed(message)
        The newest request failed; ``message`` is one readable line.
    busyChanged()
        :attr:`busy` changed.
    """

    started = Signal()
    progress = Signal(str, float)
    resultReady = Signal(object)
    failed = Signal(str)
    busyChanged = Signal()

    def __init__(
        self,
        compute: Compute,
        *,
        debounce_ms: int = 0,
        name: str = "worker",
        prepare: Callable[[Any], Any] | None = None,
        parent: QObject | None = None,
    ) -> None:
        super().__init__(parent)
        self._compute = compute
        self._prepare = prepare
        self._name = name
        self._generation = 0
        self._pending: tuple[int, Any] | None = None
        self._running: _Job | None = None
        self._busy = False
        self._closed = False
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(debounce_ms)
        self._timer.timeout.connect(self._start_pending)

    # -- requests -------------------------------------------------------------------------
    def submit(self, request: Any, *, immediate: bool = False) -> None:
        """Ask for ``request`` to be computed; supersedes every earlier request.

        The running job (if any) is cancelled through its token; the new request starts when
        it has stopped, after the debounce delay unless ``immediate``.
        """
        if self._closed:
            return
        self._generation += 1
        self._pending = (self._generation, request)
        if self._running is not None:
            self._running.token.cancel()
        if immediate or self._timer.interval() <= 0:
            self._timer.stop()
            self._start_pending()
        else:
            self._timer.start()
        self._update_busy()

    def cancel(self) -> None:
        """Drop the waiting request and cancel the running job; no result will be applied."""
        self._generation += 1
        self._pending = None
        self._timer.stop()
        if self._running is not None:
            self._running.token.cancel()
        self._update_busy()

    def shutdown(self, timeout: float = 10.0) -> bool:
        """Cancel everything and wait for the worker thread to end.

        Returns
        -------
        bool
            Whether the worker thread has ended within ``timeout`` seconds.
        """
        self.cancel()
        self._closed = True
        job = self._running
        if job is not None and job.thread is not None:
            job.thread.join(timeout)
            if job.thread.is_alive():
                log.warning("%s: worker thread still running after %.1f s", self._name, timeout)
                return False
        self._running = None
        self._update_busy()
        return True

    @property
    def busy(self) -> bool:
        """Whether a request is waiting (debounce) or a job is running."""
        return self._running is not None or self._pending is not None

    @property
    def running(self) -> bool:
        """Whether a job is running on the worker thread."""
        return self._running is not None

    # -- internals (UI thread) ---------------------------------------------------------------
    def _update_busy(self) -> None:
        busy = self.busy
        if busy != self._busy:
            self._busy = busy
            self.busyChanged.emit()

    def _start_pending(self) -> None:
        if self._running is not None or self._pending is None or self._closed:
            return
        if self._timer.isActive():
            return
        generation, request = self._pending
        self._pending = None
        if self._prepare is not None:
            request = self._prepare(request)
        signals = _JobSignals()
        queued = Qt.ConnectionType.QueuedConnection
        signals.progress.connect(self._on_progress, queued)
        signals.done.connect(self._on_done, queued)
        signals.failed.connect(self._on_failed, queued)
        signals.cancelled.connect(self._on_cancelled, queued)
        job = _Job(generation, request, CancelToken(), signals)
        job.thread = threading.Thread(target=self._work, args=(job,), name=self._name, daemon=True)
        self._running = job
        job.thread.start()
        self.started.emit()

    def _finish(self, generation: int) -> bool:
        """Forget the finished job; return whether its result is the newest."""
        job = self._running
        if job is not None and job.generation == generation:
            if job.thread is not None:
                job.thread.join(1.0)
            self._running = None
        return generation == self._generation

    def _after(self) -> None:
        self._start_pending()
        self._update_busy()

    def _on_progress(self, generation: int, stage: str, fraction: float) -> None:
        if generation == self._generation:
            self.progress.emit(stage, fraction)

    def _on_done(self, generation: int, result: Any) -> None:
        newest = self._finish(generation)
        if newest:
            self._update_busy()
            self.resultReady.emit(result)
        self._after()

    def _on_failed(self, generation: int, message: str) -> None:
        newest = self._finish(generation)
        if newest:
            self._update_busy()
            self.failed.emit(message)
        self._after()

    def _on_cancelled(self, generation: int) -> None:
        self._finish(generation)
        self._after()

    # -- worker thread -------------------------------------------------------------------------
    def _work(self, job: _Job) -> None:
        signals = job.signals
        last = {"stage": None, "t": 0.0}

        def progress(stage: str, fraction: float) -> None:
            now = time.monotonic()
            if stage != last["stage"] or fraction >= 1.0 or now - last["t"] >= _PROGRESS_INTERVAL:
                last["stage"], last["t"] = stage, now
                signals.progress.emit(job.generation, stage, float(fraction))

        try:
            job.token.check()
            result = self._compute(job.request, job.token, progress)
        except Cancelled:
            signals.cancelled.emit(job.generation)
        except Exception as exc:
            if not isinstance(exc, LsysError):
                log.error("%s failed:\n%s", self._name, traceback.format_exc())
            signals.failed.emit(job.generation, error_message(exc))
        else:
            signals.done.emit(job.generation, result)


# -- worker process ------------------------------------------------------------------------------
def _child_main(conn, compute: Compute) -> None:
    """Serve requests in a worker process until the pipe closes."""
    while True:
        try:
            msg = conn.recv()
        except (EOFError, OSError):
            return
        if msg[0] != "run":
            continue
        request = msg[1]
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

        def progress(stage: str, fraction: float) -> None:
            conn.send(("progress", stage, float(fraction)))

        try:
            result = compute(request, token, progress)
        except Cancelled:
            reply = ("cancelled",)
        except Exception as exc:
            reply = ("error", error_message(exc), traceback.format_exc(), isinstance(exc, LsysError))
        else:
            reply = ("done", result)
        stop.set()
        watcher.join()
        conn.send(reply)


class ProcessCompute:
    """Run a picklable compute function in a persistent worker process.

    Use it as the ``compute`` of a :class:`LatestRunner`: the runner's worker thread sends
    the request through a pipe and waits for progress messages and the result, so the UI
    thread never competes for the GIL with the computation.  Cancelling the runner's token
    is forwarded to the process, which raises :class:`~lsys_core.errors.Cancelled` there.

    Parameters
    ----------
    compute : callable
        A module-level (picklable) ``compute(request, cancel, progress) -> result``.
    """

    def __init__(self, compute: Compute) -> None:
        self._compute = compute
        self._lock = threading.Lock()
        self._proc: Any = None
        self._conn: Any = None

    def _ensure(self) -> None:
        if self._proc is not None and self._proc.is_alive():
            return
        ctx = mp.get_context("spawn")
        parent, child = ctx.Pipe()
        self._proc = ctx.Process(target=_child_main, args=(child, self._compute), daemon=True)
        self._proc.start()
        child.close()
        self._conn = parent

    def __call__(self, request: Any, cancel: CancelToken, progress: Progress) -> Any:
        """Compute ``request`` in the worker process (called on a worker thread)."""
        with self._lock:
            self._ensure()
            conn = self._conn
            conn.send(("run", request))
            sent_cancel = False
            while True:
                if cancel.cancelled and not sent_cancel:
                    conn.send(("cancel",))
                    sent_cancel = True
                if not conn.poll(0.02):
                    if not self._proc.is_alive():
                        self._proc = None
                        raise RuntimeError("the worker process ended unexpectedly")
                    continue
                msg = conn.recv()
                if msg[0] == "progress":
                    progress(msg[1], msg[2])
                elif msg[0] == "done":
                    return msg[1]
                elif msg[0] == "cancelled":
                    raise Cancelled("cancelled")
                else:
                    _, message, tb, user = msg
                    if not user:
                        log.error("worker process failed:\n%s", tb)
                        raise RuntimeError(message)
                    raise _RemoteError(message)

    def close(self) -> None:
        """End the worker process."""
        with self._lock:
            if self._conn is not None:
                self._conn.close()
                self._conn = None
            if self._proc is not None:
                self._proc.join(2.0)
                if self._proc.is_alive():
                    self._proc.terminate()
                    self._proc.join(2.0)
                self._proc = None


class _RemoteError(LsysError):
    """A user-caused failure reported by the worker process (its one-line message)."""
