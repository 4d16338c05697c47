"""Background computation for the editor: request → compute → apply, the newest result wins.

This is the only module of the editor that starts threads.  A :class:`LatestRunner` takes
requests on the UI thread (a snapshot of immutable values), computes them one at a time on a
worker thread, and hands the result back to the UI thread through a queued signal.  A new
request cancels the running computation through its :class:`~lsys_core.cancel.CancelToken`,
replaces any request still waiting, and only the result of the newest request is applied.
Requests can be debounced so that a slider drag runs one computation per pause, not per pixel.

Work that holds the GIL for long stretches (pure-Python loops) starves the UI thread; such work
runs in a worker process instead (:class:`ProcessCompute`, the same request → compute → apply
interface): the worker thread then only waits on a pipe, cancellation is forwarded to the
process's own token, and a process that ignores it is killed.  Measured with
``tests/bench/bench_editor.py`` (2 cores): inference of a 1,200-element scene in a worker thread
stalled the UI thread for 80–110 ms at worst; in a worker process, under 5 ms.  Inference therefore
runs in a process; derivation and rendering (numpy and skia, short GIL holds) in threads.
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

__all__ = ["Compute", "LatestRunner", "ProcessCompute", "RemoteBug", "RemoteError", "error_message"]

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
    if isinstance(exc, RemoteBug):
        return str(exc)
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
        # One long-lived worker thread per runner (started on the first job): starting a thread
        # per job would cost the UI thread milliseconds each time.
        self._thread: threading.Thread | None = None
        self._cv = threading.Condition()
        self._handoff: _Job | None = None
        self._stop = False
        self._signals = _JobSignals()
        queued = Qt.ConnectionType.QueuedConnection
        self._signals.progress.connect(self._on_progress, queued)
        self._signals.done.connect(self._on_done, queued)
        self._signals.failed.connect(self._on_failed, queued)
        self._signals.cancelled.connect(self._on_cancelled, queued)
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
        with self._cv:
            self._stop = True
            self._cv.notify()
        if self._thread is not None:
            self._thread.join(timeout)
            if self._thread.is_alive():
                log.warning("%s: worker thread still running after %.1f s", self._name, timeout)
                return False
            self._thread = None
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
        job = _Job(generation, request, CancelToken())
        self._running = job
        with self._cv:
            self._handoff = job
            self._cv.notify()
        if self._thread is None:
            self._thread = threading.Thread(target=self._loop, name=self._name, daemon=True)
            self._thread.start()
        self.started.emit()

    def _finish(self, generation: int) -> bool:
        """Forget the finished job; return whether its result is the newest."""
        job = self._running
        if job is not None and job.generation == generation:
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
    def _loop(self) -> None:
        while True:
            with self._cv:
                while self._handoff is None and not self._stop:
                    self._cv.wait()
                if self._stop:
                    return
                job, self._handoff = self._handoff, None
            self._work(job)

    def _work(self, job: _Job) -> None:
        signals = self._signals
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
            if not isinstance(exc, (LsysError, RemoteBug)):
                log.error("%s failed:\n%s", self._name, traceback.format_exc())
            signals.failed.emit(job.generation, error_message(exc))
        else:
            signals.done.emit(job.generation, result)


# -- worker process ------------------------------------------------------------------------------
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
            if stage != last["stage"] or fraction >= 1.0 or now - last["t"] >= _PROGRESS_INTERVAL:
                last["stage"], last["t"] = stage, now
                try:
                    send(("progress", stage, float(fraction)))
                except OSError:  # the editor has gone away: stop working
                    token.cancel()

        try:
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
