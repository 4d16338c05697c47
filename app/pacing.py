"""Pacing the rules text and the panels while a gesture (a slider or handle drag) runs.

Every pointer move of a drag makes new rules.  The canvas shows each of them as a draft frame
(derived and rendered on workers); the rules text and the panels follow the same rules on
the UI thread, which shares the GIL and the cores with those workers.  During a gesture they
therefore follow at most every :data:`GESTURE_FOLLOW_MS` (the newest rules then), and at once
when the gesture ends; outside gestures at once, as before.  Measured on a drag of a
10,000-element grid's handle: the text and panel updates of every move ran while the move's
derivation did and made it finish 3–8 ms later.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from PySide6.QtCore import QObject, QTimer

__all__ = ["GESTURE_FOLLOW_MS", "GesturePacing"]

#: During a gesture, the text and panels show the newest rules at most this often (ms).
GESTURE_FOLLOW_MS = 100


class GesturePacing(QObject):
    """Show new rules text and panels at once, or paced during a gesture.

    Parameters
    ----------
    doc : Document
        Its ``interactive`` says whether a gesture runs; its ``gestureFinished`` flushes.
    show_text : callable
        ``show_text(text)`` shows the rules text.
    show_panels : callable
        ``show_panels()`` starts updating the panels for the document's grammar.
    """

    def __init__(
        self,
        doc: Any,
        show_text: Callable[[str], None],
        show_panels: Callable[[], None],
        parent: QObject | None = None,
    ) -> None:
        super().__init__(parent)
        self._doc, self._show_text, self._show_panels = doc, show_text, show_panels
        self._text: str | None = None
        self._panels = False
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(GESTURE_FOLLOW_MS)
        self._timer.timeout.connect(self.flush)
        doc.gestureFinished.connect(self.flush)

    @property
    def pending(self) -> bool:
        """Whether text or panels wait to show newer rules."""
        return self._text is not None or self._panels

    def text_changed(self, text: str) -> None:
        """New rules text: shown now, or with the next paced update during a gesture."""
        if self._doc.interactive:
            self._text = text
            self._arm()
        else:
            self._text = None
            self._show_text(text)

    def grammar_changed(self) -> None:
        """New rules: the panels follow now, or with the next paced update during a gesture."""
        if self._doc.interactive:
            self._panels = True
            self._arm()
        else:
            self._panels = False
            self._show_panels()

    def flush(self) -> None:
        """Show what waits now."""
        self._timer.stop()
        text, self._text = self._text, None
        panels, self._panels = self._panels, False
        if text is not None:
            self._show_text(text)
        if panels:
            self._show_panels()

    def _arm(self) -> None:
        if not self._timer.isActive():  # a throttle, not a debounce: a long drag still updates
            self._timer.start()
