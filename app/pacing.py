"""When the rules text and the panels follow new rules: in their own event-loop turns, paced in gestures.

New rules reach the canvas through workers (derived and rendered off the UI thread); the rules
text and the panels follow the same rules on the UI thread, which shares the GIL and the cores
with those workers.  So they never run in the turn that applies the rules, and they wait for
the derivation of the new rules (at most :data:`FOLLOW_WAIT_MS`): then the text follows in one
turn and the panels in the turns after it (see ``MainWindow._update_panels``).  Applying rules
with 833 parameters (their derivation holds the GIL for 50–100 ms of Python), the text
update in the applying turn made that turn the longest UI stall (6–10 ms of CPU, 10–50 ms of
wall time), and every panel step waited for the GIL several times.

During a gesture (a slider or handle drag) every pointer move makes new rules: the text and
panels then follow at most every :data:`GESTURE_FOLLOW_MS` (the newest rules then), and at once
when the gesture ends.  Measured on a drag of a 10,000-element grid's handle: the text and
panel updates of every move ran while the move's derivation did and made it finish 3–8 ms
later.

The text shown is always the document's newest, and any input to the text editor (a key, a
click, a drop) first shows the text that waits: an edit never starts from older text.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from PySide6.QtCore import QEvent, QObject, QTimer

__all__ = ["FOLLOW_WAIT_MS", "GESTURE_FOLLOW_MS", "GesturePacing"]

#: During a gesture, the text and panels show the newest rules at most this often (ms).
GESTURE_FOLLOW_MS = 100
#: Outside gestures, the text and panels wait for the derivation of the new rules, at most this
#: long (ms): they then run without sharing the GIL with it.
FOLLOW_WAIT_MS = 150


_INPUT = frozenset(
    {
        QEvent.Type.KeyPress,
        QEvent.Type.ShortcutOverride,
        QEvent.Type.InputMethod,
        QEvent.Type.MouseButtonPress,
        QEvent.Type.MouseButtonDblClick,
        QEvent.Type.Drop,
    }
)


class GesturePacing(QObject):
    """Show new rules text and panels in the next event-loop turns, paced during a gesture.

    Parameters
    ----------
    doc : Document
        Its ``text`` is shown, its ``interactive`` says whether a gesture runs, and its
        ``gestureFinished`` shows what waits at once.
    show_text : callable
        ``show_text(text)`` shows the rules text.
    show_panels : callable
        ``show_panels()`` starts updating the panels for the document's grammar.
    editor : QWidget, optional
        The widget that shows the text: input to it first shows the text that waits.
    """

    def __init__(
        self,
        doc: Any,
        show_text: Callable[[str], None],
        show_panels: Callable[[], None],
        parent: QObject | None = None,
        editor: Any = None,
    ) -> None:
        super().__init__(parent)
        if editor is not None:  # keys reach a text edit, mouse and drops its viewport
            for widget in (editor, getattr(editor, "viewport", lambda: None)()):
                if widget is not None:
                    widget.installEventFilter(self)
        self._doc, self._show_text, self._show_panels = doc, show_text, show_panels
        self._text = False
        self._panels = False
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.timeout.connect(self._due)
        self._deadline = 0.0
        self._deriver = doc.rules.deriver
        self._deriver.busyChanged.connect(self._derived)
        doc.gestureFinished.connect(self.flush)

    @property
    def pending(self) -> bool:
        """Whether text or panels wait to show newer rules."""
        return self._text or self._panels

    def text_changed(self, _text: str = "") -> None:
        """New rules text: shown in the next turn (paced during a gesture)."""
        self._text = True
        self._arm()

    def grammar_changed(self) -> None:
        """New rules: the panels follow after the text (paced during a gesture)."""
        self._panels = True
        self._arm()

    def flush(self) -> None:
        """Show what waits now (the panels then update in turns of their own)."""
        self._timer.stop()
        text, self._text = self._text, False
        panels, self._panels = self._panels, False
        if text:
            self._show_text(self._doc.text)
        if panels:
            self._show_panels()

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        """Show the waiting text before the editor handles input."""
        if self._text and event.type() in _INPUT:
            self._text = False
            self._show_text(self._doc.text)
        return False

    def _arm(self) -> None:
        if self._doc.interactive:
            if not self._timer.isActive():  # a throttle, not a debounce: a long drag still updates
                self._timer.start(GESTURE_FOLLOW_MS)
            return
        if not self._timer.isActive():
            self._deadline = time.monotonic() + FOLLOW_WAIT_MS / 1000
        self._timer.start(0)

    def _due(self) -> None:
        """The timer fired: show what waits, unless (outside a gesture) the derivation still runs."""
        left = self._deadline - time.monotonic()
        if not self._doc.interactive and self._deriver.busy and left > 0:
            self._timer.start(max(1, round(left * 1000)))  # or sooner: when the derivation ends
            return
        self.flush()

    def _derived(self) -> None:
        if self.pending and not self._deriver.busy and not self._doc.interactive:
            self.flush()
