"""The rules of the open document: text → grammar → drawing, kept consistent in the background.

The rules *text* is the source of truth.  It is parsed into a *grammar* (at once, or after a
short pause while the user types), and the grammar is derived into a *drawing* on a worker
thread (:class:`~app.workers.LatestRunner`: the newest request wins).  While the text does not
parse, the last valid grammar and drawing stay.  No undo here: the document pushes commands,
and the commands call :meth:`RulesModel.apply_text`.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QObject, QTimer, Signal

from lsys_core.errors import GrammarError, LsysError

from . import core
from .jobs import DeriveRequest, run_derive
from .workers import LatestRunner

__all__ = ["PARSE_DELAY_MS", "RulesModel"]

PARSE_DELAY_MS = 150


class RulesModel(QObject):
    """Rules text, its grammar and its drawing.

    Signals
    -------
    textChanged(text), grammarChanged(grammar), drawingChanged(drawing)
        A new text / valid grammar / derivation.
    grammarError(error)
        The text does not parse (a ``GrammarError``), or ``None`` when it parses again.
    message(text)
        A derivation failed.
    """

    textChanged = Signal(str)
    grammarChanged = Signal(object)
    grammarError = Signal(object)
    drawingChanged = Signal(object)
    message = Signal(str)

    def __init__(self, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.text = ""
        self.grammar: Any = None
        self.drawing: Any = None
        self.error: LsysError | None = None
        #: A randomization shown instead of the grammar's own (a dialog's preview), or None.
        self.preview_randomize: Any = None
        self._parse_timer = QTimer(self)
        self._parse_timer.setSingleShot(True)
        self._parse_timer.setInterval(PARSE_DELAY_MS)
        self._parse_timer.timeout.connect(self._parse_now)
        self.deriver = LatestRunner(run_derive, name="lsys-derive", parent=self)
        self.deriver.resultReady.connect(self._set_drawing)
        self.deriver.failed.connect(lambda m: self.message.emit(f"Derivation failed: {m}"))

    @property
    def busy(self) -> bool:
        """Whether parsing or derivation is waiting or running."""
        return self.deriver.busy or self._parse_timer.isActive()

    def clear(self) -> None:
        """Forget the grammar and drawing (a new document is coming; the text stays until then)."""
        self._parse_timer.stop()
        self.deriver.cancel()
        self.grammar = None
        self.drawing = None
        self.preview_randomize = None

    def apply_text(
        self, text: str, *, grammar: Any = None, drawing: Any = None, typing: bool = False
    ) -> None:
        """Show ``text``; parse it now (or after a pause when ``typing``) unless ``grammar`` is given.

        ``drawing`` is the derivation of ``grammar`` if known; otherwise it is derived.
        """
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

    def flush(self) -> None:
        """Parse text typed in the last moments now (before an edit starts from the grammar)."""
        if self._parse_timer.isActive():
            self._parse_timer.stop()
            self._parse_now()

    def request_derive(self) -> None:
        """Derive the current grammar again in the background."""
        if self.grammar is not None:
            self.deriver.submit(DeriveRequest(self.grammar, self.preview_randomize))

    def set_preview_randomize(self, randomize: Any) -> None:
        """Derive with ``randomize`` instead of the grammar's own (None: the grammar's again)."""
        if randomize != self.preview_randomize:
            self.preview_randomize = randomize
            self.request_derive()

    def shutdown(self) -> None:
        """Stop parsing and derivation and wait for the worker thread."""
        self._parse_timer.stop()
        self.deriver.shutdown()

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
        if drawing is not None and self.preview_randomize is None:
            self.deriver.cancel()
            self._set_drawing(drawing)
        else:
            self.request_derive()  # before the panels update, so the worker starts at once
        if had_error:
            self.grammarError.emit(None)
        if changed:
            self.grammarChanged.emit(grammar)

    def _set_drawing(self, drawing: Any) -> None:
        self.drawing = drawing
        self.drawingChanged.emit(drawing)
