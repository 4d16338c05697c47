"""The editor's document: input scene, rules text, grammar, drawing, settings and undo stack.

The :class:`Document` holds the state every widget shows and is the only thing widgets edit.
It contains no algorithm: parsing, inference, derivation and editing are calls into
``lsys_core``; inference and derivation run on worker threads through
:class:`~app.workers.LatestRunner` (request → compute → apply, newest result wins).

State flows one way: an edit changes the rules *text* (the source of truth, pushed as an
undoable command), the text is parsed into a *grammar*, the grammar is derived into a
*drawing*.  While the text does not parse, the last valid grammar and drawing stay.
"""

from __future__ import annotations

import dataclasses
import itertools
import os
from pathlib import Path
from typing import Any

from PySide6.QtCore import QObject, QTimer, Signal
from PySide6.QtGui import QUndoStack

from lsys_core.derive.derivation import Randomize
from lsys_core.errors import GrammarError, LsysError

from . import core
from .commands import RandomizeCommand, SettingsCommand, TextCommand
from .jobs import DeriveRequest, InferOutcome, InferRequest, run_derive, run_inference
from .workers import LatestRunner, ProcessCompute

__all__ = ["Document"]

PARSE_DELAY_MS = 150
INFER_DELAY_MS = 80
#: Modules the inference process imports as it starts (while the window opens).
INFER_PRELOAD = (
    "lsys_core.pipeline",
    "lsys_core.instancing.similarity",
    "lsys_core.svg.parse",
    "lsys_core.grammar",
)


class Document(QObject):
    """The open document and the computations that keep it consistent.

    Signals
    -------
    sceneChanged()
        A new input scene was loaded (or cleared).
    textChanged(text)
        The rules text changed (typing, undo, parameter change, inference).
    grammarChanged(grammar)
        A new valid grammar was parsed.
    grammarError(error)
        The text does not parse (a ``GrammarError``, with line/column if a syntax error),
        or ``None`` when it parses again.
    drawingChanged(drawing)
        A new derivation is available.
    settingsChanged(settings), randomizeChanged(randomize)
        The inference settings / the randomization changed.
    inferenceStarted(), inferenceProgress(stage, fraction), inferenceFinished()
        Inference runs in the background; ``inferenceFinished`` also follows failures.
    message(text)
        A readable error or note for the user.
    pathChanged(), gestureFinished()
    """

    sceneChanged = Signal()
    textChanged = Signal(str)
    grammarChanged = Signal(object)
    grammarError = Signal(object)
    drawingChanged = Signal(object)
    settingsChanged = Signal(object)
    randomizeChanged = Signal(object)
    inferenceStarted = Signal()
    inferenceProgress = Signal(str, float)
    inferenceFinished = Signal()
    message = Signal(str)
    pathChanged = Signal()
    gestureFinished = Signal()

    def __init__(self, parent: QObject | None = None, *, infer_compute: Any = None) -> None:
        """Create an empty document.

        ``infer_compute`` runs inference jobs (default: a worker process of its own, see
        :data:`INFER_PRELOAD`); pass a shared :class:`~app.workers.ProcessCompute` or
        :func:`~app.jobs.run_inference` itself (a worker thread) to override.
        """
        super().__init__(parent)
        self.undo_stack = QUndoStack(self)
        self.scene: Any = None
        self.scene_path: str | None = None
        self.path: str | None = None
        self.text = ""
        self.grammar: Any = None
        self.drawing: Any = None
        self.error: LsysError | None = None
        self.result: Any = None
        self.settings: Any = core.default_settings()
        self.randomize: Randomize | None = None
        self._gesture: int | None = None
        self._gestures = itertools.count(1)
        self._infer_purpose: tuple[str, Any] = ("none", None)

        self._parse_timer = QTimer(self)
        self._parse_timer.setSingleShot(True)
        self._parse_timer.setInterval(PARSE_DELAY_MS)
        self._parse_timer.timeout.connect(self._parse_now)

        self._own_process = infer_compute is None
        if infer_compute is None:
            infer_compute = ProcessCompute(run_inference, preload=INFER_PRELOAD)
        self._infer_compute = infer_compute
        self.inference = LatestRunner(
            infer_compute, debounce_ms=INFER_DELAY_MS, name="lsys-inference", parent=self
        )
        self.inference.started.connect(self.inferenceStarted)
        self.inference.progress.connect(self.inferenceProgress)
        self.inference.resultReady.connect(self._on_inferred)
        self.inference.failed.connect(self._on_infer_failed)
        self.deriver = LatestRunner(run_derive, name="lsys-derive", parent=self)
        self.deriver.resultReady.connect(self._on_derived)
        self.deriver.failed.connect(self._on_derive_failed)

    # -- queries --------------------------------------------------------------------------------
    @property
    def busy(self) -> bool:
        """Whether inference, parsing or derivation is waiting or running."""
        return self.inference.busy or self.deriver.busy or self._parse_timer.isActive()

    @property
    def modified(self) -> bool:
        """Whether there are edits not saved to :attr:`path`."""
        return not self.undo_stack.isClean()

    @property
    def interactive(self) -> bool:
        """Whether a gesture (slider drag) is in progress: draw drafts."""
        return self._gesture is not None

    @property
    def loading(self) -> bool:
        """Whether a file is being opened (or the input reloaded) in the background."""
        return self._infer_purpose[0] in ("open", "reload")

    @property
    def can_infer(self) -> bool:
        """Whether an input scene is loaded and no file is loading, so inference can run."""
        return self.scene is not None and not self.loading

    def stats(self) -> dict[str, Any]:
        """Return figures for the status bar (elements, symbols, rules, compression, time)."""
        g = self.grammar
        text_bytes = len(self.text.encode())
        source = getattr(self.scene, "source_bytes", 0) if self.scene is not None else 0
        return {
            "elements": len(self.drawing) if self.drawing is not None else None,
            "terminals": len(g.terminals) if g is not None else None,
            "nonterminals": len(g.rules) if g is not None else None,
            "rules": g.production_count if g is not None else None,
            "compression": source / text_bytes if source and text_bytes else None,
            "seconds": getattr(self.result, "seconds", None),
        }

    def display_name(self) -> str:
        """Return the file name shown in the title bar."""
        for p in (self.path, self.scene_path):
            if p:
                return os.path.basename(p)
        return "Untitled"

    # -- files ------------------------------------------------------------------------------------
    def open_svg(self, path: str) -> None:
        """Load an SVG and infer its grammar in the background (replaces the document when done)."""
        self._infer_purpose = ("open", str(path))
        self.inference.submit(InferRequest(None, self.settings, svg_path=str(path)), immediate=True)

    def open_lsys(self, path: str) -> None:
        """Open an .lsys rules file; the input scene is cleared.

        Raises
        ------
        LsysError
            If the file cannot be read (a parse error only marks the text).
        """
        text = core.read_text(path)
        self.cancel_inference()
        self._set_randomize_silently(None)
        self.scene = None
        self.scene_path = None
        self.result = None
        self.path = str(path)
        self.grammar = None
        self.drawing = None
        self.undo_stack.clear()
        self.sceneChanged.emit()
        self._apply_text(text)
        self.undo_stack.setClean()
        self.pathChanged.emit()

    def save(self, path: str | None = None) -> None:
        """Write the rules text to ``path`` (default: the current path) atomically."""
        target = str(path or self.path or "")
        if not target:
            raise LsysError("no file name to save to")
        core.write_atomic(target, self.text.encode("utf-8"))
        self.path = target
        self.undo_stack.setClean()
        self.pathChanged.emit()

    def restore(self, state: dict[str, Any]) -> None:
        """Restore a recovered session (rules text, settings, randomization, file names)."""
        self.cancel_inference()
        self.undo_stack.clear()
        self.settings = core.settings_from_dict(state.get("settings") or {})
        self.settingsChanged.emit(self.settings)
        self._set_randomize_silently(core.randomize_from_dict(state.get("randomize")))
        self.path = state.get("path")
        scene_path = state.get("scene_path")
        self.scene, self.scene_path, self.result = None, None, None
        self.sceneChanged.emit()
        self.undo_stack.push(TextCommand(self, "Restore unsaved work", self.text, state.get("text", "")))
        self.pathChanged.emit()
        if scene_path and Path(scene_path).is_file():  # load the input in the background, no inference
            self._infer_purpose = ("reload", scene_path)
            request = InferRequest(None, self.settings, svg_path=scene_path, load_only=True)
            self.inference.submit(request, immediate=True)

    def snapshot(self) -> dict[str, Any]:
        """Return the state autosave writes (see :meth:`restore`)."""
        return {
            "text": self.text,
            "settings": dataclasses.asdict(self.settings),
            "randomize": dataclasses.asdict(self.randomize) if self.randomize is not None else None,
            "path": self.path,
            "scene_path": self.scene_path,
        }

    # -- edits (each pushes an undoable command) -------------------------------------------------------
    def begin_gesture(self) -> None:
        """Start a gesture (slider drag): its edits merge into one undo step and render as drafts."""
        self._gesture = next(self._gestures)

    def end_gesture(self) -> None:
        """End the current gesture; the canvas then renders at full quality."""
        if self._gesture is not None:
            self._gesture = None
            self.gestureFinished.emit()

    def editable_grammar(self) -> Any:
        """Return the grammar of the current text for an edit, or None if the text does not parse.

        Text typed in the last moments is parsed first, so an edit never starts from a stale
        grammar (and never discards what was just typed).
        """
        if self._parse_timer.isActive():
            self._parse_timer.stop()
            self._parse_now()
        if self.error is not None:
            self.message.emit(f"Fix the rules first: {self.error}")
            return None
        return self.grammar

    def _merge_key(self, what: str) -> Any:
        return (what, self._gesture) if self._gesture is not None else None

    def edit_text(self, text: str) -> None:
        """Record typing in the rules editor (merged with the typing just before)."""
        if text != self.text:
            self._supersede_inference()
            self.undo_stack.push(TextCommand(self, "Edit rules", self.text, text, merge_key="typing"))

    def set_param(self, key: str, value: float) -> None:
        """Change one numeric parameter of the rules; re-derives without re-inference."""
        current = self.editable_grammar()
        if current is None:
            return
        try:
            grammar = core.set_param(current, key, value)
        except LsysError as exc:
            self.message.emit(str(exc))
            return
        self.apply_grammar(grammar, f"Change {key}", merge_key=self._merge_key(f"param:{key}"))

    def apply_grammar(self, grammar: Any, label: str, *, merge_key: Any = None, drawing: Any = None) -> None:
        """Replace the grammar by an edited one (undoable; the text is regenerated)."""
        self._supersede_inference()
        text = core.format_grammar(grammar)
        self.undo_stack.push(
            TextCommand(self, label, self.text, text, merge_key=merge_key, grammar=grammar, drawing=drawing)
        )

    def set_settings(self, settings: Any) -> None:
        """Change the inference settings; re-runs inference in the background (undoable)."""
        if settings == self.settings or self.loading:
            return
        self.undo_stack.push(
            SettingsCommand(self, self.settings, settings, self.text, merge_key=self._merge_key("settings"))
        )

    def set_randomize(self, randomize: Randomize | None) -> None:
        """Set (or clear with None) the seeded perturbation of the derivation (undoable)."""
        if randomize is not None and not randomize.active:
            randomize = None
        if randomize != self.randomize:
            self.undo_stack.push(RandomizeCommand(self, self.randomize, randomize))

    def symmetrize(self) -> None:
        """Re-infer with relaxed tolerance in the background; applied as one undoable step."""
        if not self.can_infer:
            self.message.emit("Symmetrize needs an input SVG: open one first.")
            return
        self._infer_purpose = ("symmetrize", None)
        self.inference.submit(
            InferRequest(self.scene, self.settings, self.randomize, symmetrize=True), immediate=True
        )

    def reinfer(self) -> None:
        """Run inference again with the current settings."""
        if self.can_infer:
            self._infer_purpose = ("reinfer", None)
            self.inference.submit(InferRequest(self.scene, self.settings, self.randomize), immediate=True)

    def cancel_inference(self) -> None:
        """Cancel the running inference; the document keeps its current rules."""
        self.inference.cancel()
        self._infer_purpose = ("none", None)
        self.inferenceFinished.emit()

    def warm_up(self) -> None:
        """Start the inference process early, so the first inference does not wait for imports."""
        start = getattr(self._infer_compute, "start", None)
        if start is not None:
            start()

    def shutdown(self) -> None:
        """Cancel all background work and wait for the worker threads to end."""
        self._parse_timer.stop()
        self.inference.shutdown()
        self.deriver.shutdown()
        if self._own_process:
            self._infer_compute.close()

    # -- appliers (called by commands and results) ---------------------------------------------------
    def _apply_text(
        self, text: str, *, grammar: Any = None, drawing: Any = None, typing: bool = False
    ) -> None:
        changed = text != self.text
        self.text = text
        if grammar is not None:  # derive first: the worker runs while the panels update
            self._parse_timer.stop()
            self._set_grammar(grammar, drawing)
        if changed:
            self.textChanged.emit(text)
        if grammar is not None:
            return
        if typing:
            self._parse_timer.start()
        else:
            self._parse_timer.stop()
            self._parse_now()

    def _parse_now(self) -> None:
        try:
            grammar = core.parse_grammar(self.text)
        except GrammarError as exc:
            self.error = exc
            self.grammarError.emit(exc)
            return
        self._set_grammar(grammar, None)

    def _set_grammar(self, grammar: Any, drawing: Any) -> None:
        had_error = self.error is not None
        self.error = None
        changed = grammar != self.grammar
        self.grammar = grammar
        if drawing is not None:
            self.deriver.cancel()
            self._set_drawing(drawing)
        else:
            self.request_derive()  # before the panels update, so the worker starts at once
        if had_error:
            self.grammarError.emit(None)
        if changed:
            self.grammarChanged.emit(grammar)

    def request_derive(self) -> None:
        """Derive the current grammar again in the background."""
        if self.grammar is not None:
            self.deriver.submit(DeriveRequest(self.grammar, self.randomize))

    def _set_drawing(self, drawing: Any) -> None:
        self.drawing = drawing
        self.drawingChanged.emit(drawing)

    def _apply_settings(self, settings: Any, text: str | None, *, command: SettingsCommand | None) -> None:
        self.settings = settings
        self.settingsChanged.emit(settings)
        if text is not None:
            self._supersede_inference()
            self._apply_text(text)
        elif self.scene is not None:
            self._infer_purpose = ("settings", command)
            self.inference.submit(InferRequest(self.scene, settings, self.randomize))

    def _supersede_inference(self) -> None:
        """Cancel an inference whose result would replace the rules the user is now editing.

        Opening a file or reloading the input scene is not cancelled: it is not about the rules.
        """
        if self._infer_purpose[0] in ("settings", "reinfer", "symmetrize"):
            self.inference.cancel()
            self._infer_purpose = ("none", None)
            self.inferenceFinished.emit()

    def _retarget_inference(self, old: SettingsCommand, new: SettingsCommand) -> None:
        if self._infer_purpose == ("settings", old):
            self._infer_purpose = ("settings", new)

    def _set_randomize_silently(self, randomize: Randomize | None) -> None:
        """Set the randomization of a new document (not an edit: nothing is derived here)."""
        if randomize != self.randomize:
            self.randomize = randomize
            self.randomizeChanged.emit(randomize)

    def _apply_randomize(self, randomize: Randomize | None) -> None:
        self.randomize = randomize
        self.randomizeChanged.emit(randomize)
        self.request_derive()

    # -- worker results --------------------------------------------------------------------------------
    def _on_inferred(self, out: InferOutcome) -> None:
        purpose, data = self._infer_purpose
        self._infer_purpose = ("none", None)
        if purpose == "reload":
            self.scene, self.scene_path = out.scene, data
            self.sceneChanged.emit()
            self.inferenceFinished.emit()
            return
        self.result = out.result
        if out.derive_error:
            self.message.emit(out.derive_error)
        if purpose == "open":
            self.scene, self.scene_path, self.path = out.scene, data, None
            self._set_randomize_silently(None)
            self.undo_stack.clear()
            self.grammar = None
            self.sceneChanged.emit()
            self._apply_text(out.text, grammar=out.result.grammar, drawing=out.drawing)
            self.undo_stack.setClean()
            self.pathChanged.emit()
            warnings = getattr(out.scene, "warnings", ())
            if warnings:  # one line: the message bar shows only the latest message
                self.message.emit("; ".join(warnings))
        elif purpose == "symmetrize":
            self.undo_stack.push(
                TextCommand(
                    self, "Symmetrize", self.text, out.text, grammar=out.result.grammar, drawing=out.drawing
                )
            )
        else:
            if purpose == "settings" and data is not None:
                data.new_text = out.text
            self._apply_text(out.text, grammar=out.result.grammar, drawing=out.drawing)
        self.inferenceFinished.emit()

    def _on_infer_failed(self, message: str) -> None:
        purpose, data = self._infer_purpose
        self._infer_purpose = ("none", None)
        what = {"open": "Could not open", "reload": "Could not reload"}.get(purpose)
        what = f"{what} {os.path.basename(data)}" if what else "Inference failed"
        self.message.emit(f"{what}: {message}")
        self.inferenceFinished.emit()

    def _on_derived(self, drawing: Any) -> None:
        self._set_drawing(drawing)

    def _on_derive_failed(self, message: str) -> None:
        self.message.emit(f"Derivation failed: {message}")
