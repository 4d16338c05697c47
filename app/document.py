"""The editor's document: input scene, rules, inference settings, files and the undo stack.

The :class:`Document` holds what every widget shows and is the only thing widgets edit.  It
contains no algorithm and delegates by responsibility:

* :class:`~app.rules_model.RulesModel` keeps text → grammar → drawing consistent;
* :class:`~app.inference_control.InferenceControl` runs inference in the background and says
  what each run was for;
* :mod:`app.commands` are the undoable steps, which call back only :meth:`Document.apply_text`
  and :meth:`Document.apply_settings`.

Invariants: :attr:`settings` are those the rules on the canvas were inferred with (a weight
change in flight is :attr:`pending_settings` until its result arrives, and a cancelled run
restores the panel); every user action that changes the rules is exactly one undo step, and an
action that changes nothing pushes no step and says why.
"""

from __future__ import annotations

import dataclasses
import itertools
import os
from typing import Any

from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QUndoStack

from lsys_core.errors import LsysError

from . import core
from .commands import SettingsCommand, TextCommand
from .doc_files import DocumentFiles
from .inference_control import INFER_PRELOAD, InferenceControl, Purpose
from .jobs import InferOutcome, InferRequest, scene_digest
from .rules_model import RulesModel

__all__ = ["INFER_PRELOAD", "Document"]


class Document(DocumentFiles, QObject):
    """The open document and the computations that keep it consistent.

    Signals
    -------
    sceneChanged()
        A new input scene was loaded (or cleared).
    textChanged(text), grammarChanged(grammar), grammarError(error), drawingChanged(drawing)
        See :class:`~app.rules_model.RulesModel`.
    settingsChanged(settings)
        The settings to show changed (applied, or restored after a cancelled run).
    randomizeChanged(randomize)
        The grammar's randomization changed.
    inferenceStarted(), inferenceProgress(stage, fraction), inferenceFinished()
        Inference runs in the background; ``inferenceFinished`` also follows failures and cancels.
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
        """Create an empty document (``infer_compute``: see :class:`InferenceControl`)."""
        super().__init__(parent)
        self.undo_stack = QUndoStack(self)
        self.scene: Any = None
        self._scene_key: tuple[Any, bytes] = (None, b"")  # (scene, its digest)
        self.scene_path: str | None = None
        self.path: str | None = None
        self.result: Any = None
        self.settings: Any = core.default_settings()
        #: Settings of a re-inference in flight (shown in the panel), or None.
        self.pending_settings: Any = None
        self._gesture: int | None = None
        self._gestures = itertools.count(1)
        self._randomize: Any = None

        self.rules = RulesModel(self)
        self.rules.deriver.finish_running = lambda _request: self.interactive  # a drag's frames keep coming
        for name in ("textChanged", "grammarChanged", "grammarError", "drawingChanged", "message"):
            getattr(self.rules, name).connect(getattr(self, name))
        self.rules.grammarChanged.connect(self._check_randomize)
        self.inference = InferenceControl(infer_compute, self)
        self.inference.started.connect(self.inferenceStarted)
        self.inference.progress.connect(self.inferenceProgress)
        self.inference.done.connect(self._on_inferred)
        self.inference.failed.connect(self._on_infer_failed)
        self.inference.stopped.connect(self._on_infer_stopped)

    # -- queries --------------------------------------------------------------------------------
    @property
    def text(self) -> str:
        """The rules text (the source of truth)."""
        return self.rules.text

    @property
    def grammar(self) -> Any:
        """The last valid grammar of the text (None before the first)."""
        return self.rules.grammar

    @property
    def drawing(self) -> Any:
        """The derivation of the grammar (None before the first)."""
        return self.rules.drawing

    @property
    def error(self) -> LsysError | None:
        """Why the text does not parse, or None."""
        return self.rules.error

    @property
    def randomize(self) -> Any:
        """The grammar's randomization (its ``randomize`` line), or None."""
        return self.grammar.randomize if self.grammar is not None else None

    @property
    def busy(self) -> bool:
        """Whether inference, parsing or derivation is waiting or running."""
        return self.inference.busy or self.rules.busy

    @property
    def modified(self) -> bool:
        """Whether there are edits not saved to :attr:`path`."""
        return not self.undo_stack.isClean()

    @property
    def interactive(self) -> bool:
        """Whether a gesture (slider or handle drag) is in progress: draw drafts."""
        return self._gesture is not None

    @property
    def loading(self) -> bool:
        """Whether a file is being opened (or the input reloaded) in the background."""
        return self.inference.kind in ("open", "reload")

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

    # -- the command interface (see app.commands.EditTarget) ---------------------------------------
    def apply_text(
        self, text: str, *, grammar: Any = None, drawing: Any = None, typing: bool = False
    ) -> None:
        """Show ``text`` as the rules; a re-inference in flight is stale and stops."""
        self.inference.supersede()
        self.rules.apply_text(text, grammar=grammar, drawing=drawing, typing=typing)

    def apply_settings(self, settings: Any) -> None:
        """Record ``settings`` as those of the rules shown (no inference runs)."""
        self.pending_settings = None
        self.settings = settings
        self.settingsChanged.emit(settings)

    # -- edits (each pushes one undoable command) ---------------------------------------------------
    def begin_gesture(self) -> None:
        """Start a gesture (slider or handle drag): its edits merge into one undo step, drawn as drafts."""
        self._gesture = next(self._gestures)

    def end_gesture(self) -> None:
        """End the current gesture; the canvas then renders at full quality."""
        if self._gesture is not None:
            self._gesture = None
            self.gestureFinished.emit()

    def merge_key(self, what: str) -> Any:
        """Return the undo merge key of an edit ``what`` (None outside a gesture)."""
        return (what, self._gesture) if self._gesture is not None else None

    def editable_grammar(self) -> Any:
        """Return the grammar of the current text for an edit, or None if the text does not parse.

        Text typed in the last moments is parsed first, so an edit never starts from a stale
        grammar (and never discards what was just typed).
        """
        self.rules.flush()
        if self.error is not None:
            self.message.emit(f"Fix the rules first: {self.error}")
            return None
        return self.grammar

    def edit_text(self, text: str) -> None:
        """Record typing in the rules editor (merged with the typing just before)."""
        if text != self.text:
            self.undo_stack.push(TextCommand(self, "Edit rules", self.text, text, merge_key="typing"))

    def set_param(self, key: str, value: float) -> None:
        """Change one numeric parameter of the rules; re-derives without re-inference."""
        self.set_params({key: value}, f"Change {key}", f"param:{key}")

    def set_params(self, values: dict[str, float], label: str, what: str | None = None) -> None:
        """Change several parameters at once (one semantic parameter, a handle drag): one step."""
        current = self.editable_grammar()
        if current is None:
            return
        try:
            grammar = core.set_params(current, values)
        except LsysError as exc:
            self.message.emit(str(exc))
            return
        self.apply_grammar(grammar, label, merge_key=self.merge_key(what or label))

    def apply_grammar(self, grammar: Any, label: str, *, merge_key: Any = None, drawing: Any = None) -> bool:
        """Replace the grammar by an edited one (undoable; the text is regenerated).

        Returns whether anything changed (an identical grammar pushes no step).
        """
        text = core.format_grammar(grammar)
        if text == self.text:
            return False
        self.undo_stack.push(
            TextCommand(self, label, self.text, text, merge_key=merge_key, grammar=grammar, drawing=drawing)
        )
        return True

    def set_settings(self, settings: Any) -> None:
        """Ask for new inference settings: re-infers in the background (at once, or after a short
        pause while a slider is dragged).

        The undo step is pushed when the new rules arrive; until then the settings are
        :attr:`pending_settings`, and cancelling restores :attr:`settings`.
        """
        if self.loading or settings == (self.pending_settings or self.settings):
            return
        if self.scene is None:  # nothing to infer from: the settings only matter for the next file
            self.apply_settings(settings)
            return
        self.pending_settings = settings
        request = InferRequest(self.scene, settings, self.randomize, scene_key=self.scene_key())
        purpose = Purpose("settings", settings=settings, merge_key=self.merge_key("settings"))
        # Debounced only in a slider drag; a typed value (or a step) is one edit: it starts now
        # (the debounce was 40 ms of a 1,200-element weight change's ~300).
        self.inference.submit(purpose, request, immediate=not self.interactive)

    def set_randomize(self, randomize: Any) -> None:
        """Set (or clear with None) the grammar's seeded perturbation: one undo step.

        An inactive randomization (all amounts 0) clears it; setting the current one again
        pushes nothing and says so.
        """
        self.rules.set_preview_randomize(None)
        if randomize is not None and not randomize.active:
            randomize = None
        grammar = self.editable_grammar()
        if grammar is None:
            return
        if randomize == grammar.randomize:
            self.message.emit(
                "Randomize: nothing changed (same seed and amounts)."
                if randomize is not None
                else "The rules are not randomized."
            )
            return
        label = "Randomize" if randomize is not None else "Clear randomization"
        self.apply_grammar(dataclasses.replace(grammar, randomize=randomize), label)

    def clean_numbers(self) -> None:
        """Snap every number of the rules to its simplest value within tolerance: one step, or a message."""
        grammar = self.editable_grammar()
        if grammar is None:
            return
        if not self.apply_grammar(core.snap_params(grammar), "Clean numbers"):
            self.message.emit(
                "Clean numbers: nothing changed (the numbers are already as simple as they can be)."
            )

    def preview_randomize(self, randomize: Any) -> None:
        """Draw with ``randomize`` without changing the rules (None ends the preview)."""
        self.rules.set_preview_randomize(randomize)

    def symmetrize(self) -> None:
        """Re-infer with relaxed tolerance in the background; applied as one undoable step."""
        if not self.can_infer:
            self.message.emit("Symmetrize needs an input SVG: open one first.")
            return
        request = InferRequest(self.scene, self.settings, self.randomize, symmetrize=True)
        self.inference.submit(Purpose("symmetrize"), request)

    def reinfer(self) -> None:
        """Run inference again with the current settings (one undo step if the rules change)."""
        if self.can_infer:
            request = InferRequest(self.scene, self.settings, self.randomize, scene_key=self.scene_key())
            self.inference.submit(Purpose("reinfer"), request)

    def scene_key(self) -> bytes | None:
        """Return the digest of the input scene (computed once per scene; None: no scene).

        Weight changes send it with the scene, so the worker finds its kept analysis without
        digesting the scene again.  A scene the worker loaded comes with the key its analysis is
        kept under; others are digested here once.
        """
        if self.scene is None:
            return None
        if self._scene_key[0] is not self.scene:
            self._scene_key = (self.scene, scene_digest(self.scene))
        return self._scene_key[1]

    def cancel_inference(self) -> None:
        """Cancel the running inference; the document keeps its rules and their settings."""
        if self.inference.cancel() is None:
            self.inferenceFinished.emit()

    def request_derive(self) -> None:
        """Derive the current grammar again in the background."""
        self.rules.request_derive()

    def warm_up(self) -> None:
        """Start the inference process early, so the first inference does not wait for imports."""
        self.inference.warm_up()

    def shutdown(self) -> None:
        """Cancel all background work and wait for the worker threads to end."""
        self.inference.shutdown()
        self.rules.shutdown()

    # -- results of the background work -----------------------------------------------------------------
    def _check_randomize(self, grammar: Any) -> None:
        if grammar.randomize != self._randomize:
            self._randomize = grammar.randomize
            self.randomizeChanged.emit(self._randomize)

    def _on_inferred(self, purpose: Purpose, out: InferOutcome) -> None:
        kind = purpose.kind
        if out.scene is not None and out.scene_key is not None:
            # the worker keeps the analysis of the scene it loaded under this key: later
            # requests name it (the UI thread need not digest the scene)
            self._scene_key = (out.scene, out.scene_key)
        if kind == "prepare":  # the analysis is kept in the worker: nothing to show
            self.inferenceFinished.emit()
            return
        if kind == "reload":
            self.scene, self.scene_path = out.scene, purpose.path
            self.sceneChanged.emit()
            self._prepare_analysis()
        elif kind == "open":
            self.result = out.result
            self.replace_document(
                out.scene, purpose.path, None, out.text, grammar=out.grammar, drawing=out.drawing
            )
            self.pathChanged.emit()
            warnings = getattr(out.scene, "warnings", ())
            if warnings:  # one line: the message bar shows only the latest message
                self.message.emit("; ".join(warnings))
        elif kind == "settings":
            self.result = out.result
            command = SettingsCommand(
                self,
                self.settings,
                purpose.settings,
                self.text,
                out.text,
                merge_key=purpose.merge_key,
                grammar=out.grammar,
                drawing=out.drawing,
            )
            self.undo_stack.push(command)
            if out.text == command.old_text:
                self.message.emit("The rules are the same with these settings.")
        else:
            self._apply_inferred(kind, out)
        if out.derive_error:
            self.message.emit(out.derive_error)
        self.inferenceFinished.emit()

    def _apply_inferred(self, kind: str, out: InferOutcome) -> None:
        """Apply a Re-infer or Symmetrize result: one step, or none and a message if nothing changed."""
        self.result = out.result
        label = "Symmetrize" if kind == "symmetrize" else "Re-infer"
        if out.text == self.text:
            why = "the rules are already regular" if kind == "symmetrize" else "the rules are the same"
            self.message.emit(f"{label}: nothing changed ({why}).")
            return
        self.undo_stack.push(
            TextCommand(self, label, self.text, out.text, grammar=out.grammar, drawing=out.drawing)
        )

    def _prepare_analysis(self) -> None:
        """Analyse the reloaded scene in the background (a restored session has rules but no analysis).

        The worker keeps the analysis and the candidates of its rule levels (the rules it
        generates are dropped: the restored ones stay), so the first weight change re-runs only
        the choice of rules, as after opening a file (1,200 elements: 0.7–1.0 s before, 0.17–0.24 s
        with it, at load ~1.5).  Any inference meanwhile supersedes it; a failure says nothing
        (the next inference reports it).
        """
        if self.scene is None or not getattr(self.scene, "elements", ()):
            return
        request = InferRequest(self.scene, self.settings, scene_key=self.scene_key(), analyse_only=True)
        self.inference.submit(Purpose("prepare"), request)

    def _on_infer_failed(self, purpose: Purpose, message: str) -> None:
        if purpose.kind == "prepare":
            self.inferenceFinished.emit()
            return
        what = {"open": "Could not open", "reload": "Could not reload"}.get(purpose.kind)
        what = f"{what} {os.path.basename(purpose.path or '')}" if what else "Inference failed"
        self._restore_settings()
        self.message.emit(f"{what}: {message}")
        self.inferenceFinished.emit()

    def _on_infer_stopped(self, purpose: Purpose) -> None:
        if self._restore_settings():
            self.message.emit("Inference stopped: the settings are back to those of the rules shown.")
        self.inferenceFinished.emit()

    def _restore_settings(self) -> bool:
        """Show the settings of the rules again after a run that brought none; return whether needed."""
        if self.pending_settings is None:
            return False
        self.pending_settings = None
        self.settingsChanged.emit(self.settings)
        return True
