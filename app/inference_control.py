"""Inference runs of the document: what each run is for, and what became of it.

An :class:`InferenceControl` owns the inference worker (a :class:`~app.workers.LatestRunner`
over a worker process by default) and remembers the *purpose* of the run in flight: opening a
file, reloading the input, new settings, Re-infer or Symmetrize.  It knows nothing of the
document: it reports each run's end with its purpose (``done``, ``failed``) and the document
decides what to apply.  A new run supersedes the previous one; a cancelled run reports
``stopped`` and nothing else.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from PySide6.QtCore import QObject, Signal

from .jobs import InferOutcome, InferRequest, run_inference
from .workers import LatestRunner, ProcessCompute

__all__ = ["INFER_DELAY_MS", "INFER_PRELOAD", "RULE_PURPOSES", "InferenceControl", "Purpose"]

#: Debounce of inference requests in ms (steps of a weight slider): short, as a newer request
#: cancels the running one anyway; it was 80 ms, a third of a weight change's 1,200-element budget.
INFER_DELAY_MS = 40
#: Modules the inference process imports as it starts (while the window opens).
INFER_PRELOAD = (
    "lsys_core.pipeline",
    "lsys_core.instancing.similarity",
    "lsys_core.svg.parse",
    "lsys_core.grammar",
)
#: Purposes whose result would replace the rules (an edit of the rules makes them stale).
RULE_PURPOSES = ("settings", "reinfer", "symmetrize")


@dataclass(frozen=True)
class Purpose:
    """Why a run was started: ``kind`` (``open``, ``reload``, ``prepare``, ``settings``, ``reinfer``,
    ``symmetrize``) and what the document needs to apply its result (a path, the settings and
    the undo merge key of a slider drag)."""

    kind: str
    path: str | None = None
    settings: Any = None
    merge_key: Any = None


class InferenceControl(QObject):
    """The inference worker and the purpose of its current run.

    Parameters
    ----------
    compute : callable, optional
        Runs inference jobs (default: a worker process of its own, see :data:`INFER_PRELOAD`);
        pass a shared :class:`~app.workers.ProcessCompute` or :func:`~app.jobs.run_inference`
        itself (a worker thread) to override.

    Signals
    -------
    started(), progress(stage, fraction)
        A run started / reports progress.
    done(purpose, outcome)
        The newest run finished with an :class:`~app.jobs.InferOutcome`.
    failed(purpose, message)
        The newest run failed (one readable line).
    stopped(purpose)
        A run ended without result: cancelled, or superseded by an edit of the rules.
    """

    started = Signal()
    progress = Signal(str, float)
    done = Signal(object, object)
    failed = Signal(object, str)
    stopped = Signal(object)

    def __init__(self, compute: Any = None, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self._own_process = compute is None
        self._compute = ProcessCompute(run_inference, preload=INFER_PRELOAD) if compute is None else compute
        self.runner = LatestRunner(
            self._compute, debounce_ms=INFER_DELAY_MS, name="lsys-inference", parent=self
        )
        self.purpose: Purpose | None = None
        self.runner.started.connect(self.started)
        self.runner.progress.connect(self.progress)
        self.runner.resultReady.connect(self._on_done)
        self.runner.failed.connect(self._on_failed)

    @property
    def busy(self) -> bool:
        """Whether a run is waiting or running."""
        return self.runner.busy

    @property
    def kind(self) -> str:
        """The purpose of the run in flight (``"none"`` when there is none)."""
        return self.purpose.kind if self.purpose is not None else "none"

    def submit(self, purpose: Purpose, request: InferRequest, *, immediate: bool = True) -> None:
        """Start a run for ``purpose`` (after the debounce delay unless ``immediate``)."""
        self.purpose = purpose
        self.runner.submit(request, immediate=immediate)

    def cancel(self) -> Purpose | None:
        """Cancel the run in flight (if any) and report ``stopped``; return its purpose."""
        purpose, self.purpose = self.purpose, None
        self.runner.cancel()
        if purpose is not None:
            self.stopped.emit(purpose)
        return purpose

    def supersede(self) -> None:
        """Cancel a run whose result would replace rules the user is now editing.

        Opening a file or reloading the input scene is not cancelled: it is not about the rules.
        """
        if self.kind in RULE_PURPOSES:
            self.cancel()

    def warm_up(self) -> None:
        """Start the inference process early, so the first run does not wait for imports."""
        start = getattr(self._compute, "start", None)
        if start is not None:
            start()

    def shutdown(self) -> None:
        """Cancel the run and end the worker (and the process if it is our own)."""
        self.purpose = None
        self.runner.shutdown()
        if self._own_process:
            self._compute.close()

    def _on_done(self, outcome: InferOutcome) -> None:
        purpose, self.purpose = self.purpose, None
        if purpose is not None:
            self.done.emit(purpose, outcome)

    def _on_failed(self, message: str) -> None:
        purpose, self.purpose = self.purpose, None
        if purpose is not None:
            self.failed.emit(purpose, message)
