"""The rules panel: the grammar as ``.lsys`` text with highlighting, line numbers and error markers.

The editor forwards every keystroke to the document (which records it on the undo stack and
re-derives after a short pause) and shows the document's text, its parse error (a wavy
underline at ``line:column``, a marker in the line-number gutter and the message below), and
the rule a clicked element came from.  Undo/redo keys go to the document's undo stack, not to
the text widget's own history.
"""

from __future__ import annotations

import difflib
import re
from typing import Any

from PySide6.QtCore import QRect, QSize, Qt, Signal
from PySide6.QtGui import (
    QColor,
    QFontDatabase,
    QKeySequence,
    QPainter,
    QTextCharFormat,
    QTextCursor,
    QTextFormat,
    QTextOption,
)
from PySide6.QtWidgets import QLabel, QPlainTextEdit, QTextEdit, QVBoxLayout, QWidget

from .highlighter import LsysHighlighter

__all__ = ["RulesEditor", "RulesPanel"]

#: Changed lines coloured at once when the text is replaced (more wait for later turns).
_SYNC_LINES = 40
#: Longest text whose changed lines are found line by line (:func:`_line_edits`).
_DIFF_LINES = 4000


def _line_edits(a: list[str], b: list[str]) -> list[tuple[int, int, int, int]]:
    """Return the ``(i1, i2, j1, j2)`` spans where lines ``a[i1:i2]`` become ``b[j1:j2]``.

    Above :data:`_DIFF_LINES` lines (the matcher can grow quadratically) the one span between the
    common first and last lines is returned.
    """
    if max(len(a), len(b)) <= _DIFF_LINES:
        matcher = difflib.SequenceMatcher(None, a, b, autojunk=False)
        return [(i1, i2, j1, j2) for tag, i1, i2, j1, j2 in matcher.get_opcodes() if tag != "equal"]
    n = min(len(a), len(b))
    p = next((i for i in range(n) if a[i] != b[i]), n)
    q = next((k for k in range(n - p) if a[-1 - k] != b[-1 - k]), n - p)
    return [(p, len(a) - q, p, len(b) - q)]


class _LineNumbers(QWidget):
    """The gutter of a :class:`RulesEditor`."""

    def __init__(self, editor: RulesEditor) -> None:
        super().__init__(editor)
        self.editor = editor

    def sizeHint(self) -> QSize:
        """Return the gutter width for the current line count."""
        return QSize(self.editor.gutter_width(), 0)

    def paintEvent(self, event) -> None:
        """Paint the line numbers (and the error marker)."""
        self.editor.paint_gutter(event)


class RulesEditor(QPlainTextEdit):
    """A plain-text editor with line numbers, an error underline and rule highlighting.

    Signals
    -------
    undoRequested(), redoRequested()
        The user pressed the undo/redo keys (the document's stack handles them).
    """

    undoRequested = Signal()
    redoRequested = Signal()

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setUndoRedoEnabled(False)
        self.setLineWrapMode(QPlainTextEdit.LineWrapMode.WidgetWidth)
        self.setWordWrapMode(QTextOption.WrapMode.WrapAtWordBoundaryOrAnywhere)
        font = QFontDatabase.systemFont(QFontDatabase.SystemFont.FixedFont)
        self.setFont(font)
        self.setTabStopDistance(4 * self.fontMetrics().horizontalAdvance(" "))
        self.highlighter = LsysHighlighter(self.document())
        self._gutter = _LineNumbers(self)
        self._error: tuple[int, int, str] | None = None
        self._rule_lines: list[int] = []
        self._undo_keys: list[QKeySequence] = []
        self._redo_keys: list[QKeySequence] = []
        self.blockCountChanged.connect(self._update_gutter_width)
        self.updateRequest.connect(self._update_gutter)
        self._update_gutter_width()

    # -- gutter ---------------------------------------------------------------------------------
    def gutter_width(self) -> int:
        """Return the width of the line-number gutter in pixels."""
        digits = len(str(max(1, self.blockCount())))
        return 12 + self.fontMetrics().horizontalAdvance("9") * max(2, digits)

    def _update_gutter_width(self, _count: int = 0) -> None:
        self.setViewportMargins(self.gutter_width(), 0, 0, 0)

    def _update_gutter(self, rect: QRect, dy: int) -> None:
        if dy:
            self._gutter.scroll(0, dy)
        else:
            self._gutter.update(0, rect.y(), self._gutter.width(), rect.height())

    def resizeEvent(self, event) -> None:
        """Keep the gutter beside the text."""
        super().resizeEvent(event)
        cr = self.contentsRect()
        self._gutter.setGeometry(QRect(cr.left(), cr.top(), self.gutter_width(), cr.height()))

    def paint_gutter(self, event) -> None:
        """Paint line numbers; the error line gets a red number on a tinted background."""
        painter = QPainter(self._gutter)
        painter.fillRect(event.rect(), self.palette().alternateBase())
        block = self.firstVisibleBlock()
        number = block.blockNumber()
        top = round(self.blockBoundingGeometry(block).translated(self.contentOffset()).top())
        bottom = top + round(self.blockBoundingRect(block).height())
        width = self._gutter.width() - 4
        height = self.fontMetrics().height()
        while block.isValid() and top <= event.rect().bottom():
            if block.isVisible() and bottom >= event.rect().top():
                is_error = self._error is not None and self._error[0] == number + 1
                if is_error:
                    painter.fillRect(0, top, self._gutter.width(), height, QColor("#ffcdd2"))
                    painter.setPen(QColor("#c62828"))
                else:
                    painter.setPen(self.palette().placeholderText().color())
                painter.drawText(0, top, width, height, Qt.AlignmentFlag.AlignRight, str(number + 1))
            block = block.next()
            top = bottom
            bottom = top + round(self.blockBoundingRect(block).height())
            number += 1
        painter.end()

    # -- markers --------------------------------------------------------------------------------
    def set_error(self, line: int | None, column: int | None = None, message: str = "") -> None:
        """Mark a parse error at 1-based ``line``/``column`` (None clears the marker)."""
        self._error = None if line is None else (int(line), int(column or 1), message)
        self.setToolTip(message if line is not None else "")
        self._refresh_selections()
        self._gutter.update()

    def set_rule_lines(self, lines: list[int]) -> None:
        """Highlight whole lines (0-based), e.g. the productions of a clicked element's rule."""
        self._rule_lines = list(lines)
        self._refresh_selections()
        if lines:
            block = self.document().findBlockByNumber(lines[0])
            if block.isValid():
                cursor = QTextCursor(block)
                self.setTextCursor(cursor)
                self.ensureCursorVisible()

    def _refresh_selections(self) -> None:
        selections = []
        for line in self._rule_lines:
            block = self.document().findBlockByNumber(line)
            if not block.isValid():
                continue
            sel = QTextEdit.ExtraSelection()
            sel.format.setBackground(QColor("#fff59d"))
            sel.format.setProperty(QTextFormat.Property.FullWidthSelection, True)
            cursor = QTextCursor(block)
            cursor.movePosition(QTextCursor.MoveOperation.EndOfBlock, QTextCursor.MoveMode.KeepAnchor)
            sel.cursor = cursor
            selections.append(sel)
        if self._error is not None:
            line, column, _ = self._error
            block = self.document().findBlockByNumber(line - 1)
            if not block.isValid():
                block = self.document().lastBlock()
            cursor = QTextCursor(block)
            start = min(max(column - 1, 0), max(block.length() - 1, 0))
            cursor.setPosition(block.position() + start)
            token_end = re.match(r"\S*", block.text()[start:])
            length = max(1, len(token_end.group(0)) if token_end else 1)
            if start >= block.length() - 1:  # error at the end of the line: mark the last character
                cursor.setPosition(block.position() + max(start - 1, 0))
                length = 1
            cursor.setPosition(cursor.position() + length, QTextCursor.MoveMode.KeepAnchor)
            sel = QTextEdit.ExtraSelection()
            sel.format.setUnderlineStyle(QTextCharFormat.UnderlineStyle.WaveUnderline)
            sel.format.setUnderlineColor(QColor("#d32f2f"))
            sel.format.setToolTip(self._error[2])
            sel.cursor = cursor
            selections.append(sel)
        self.setExtraSelections(selections)

    # -- text and keys -----------------------------------------------------------------------------
    def replace_text(self, text: str) -> None:
        """Show ``text``, keeping the cursor position and scroll offset where possible.

        Only the lines that differ are replaced, so the others keep their layout and colours: a
        new number re-lays out one line.  (Replacing the whole text made the next paint lay out
        and colour every visible line again: 25–29 ms at 120 rules.)  When many lines change,
        colouring is deferred to later event-loop turns.
        """
        old = self.toPlainText()
        if text == old:
            return
        a, b = old.split("\n"), text.split("\n")
        edits = _line_edits(a, b)
        many = sum(j2 - j1 for _i1, _i2, j1, j2 in edits) > _SYNC_LINES
        if many:
            self.highlighter.defer()
        doc = self.document()
        end = doc.characterCount() - 1
        cursor = QTextCursor(doc)  # one edit each: an edit block would colour every line between
        for i1, i2, j1, j2 in reversed(edits):
            new = b[j1:j2]
            if i1 < i2 and new:  # lines replaced: the line breaks around them stay
                last = doc.findBlockByNumber(i2 - 1)
                start, stop = doc.findBlockByNumber(i1).position(), last.position() + last.length() - 1
                insert = "\n".join(new)
            elif i2 < len(a):  # lines removed or inserted before line i2
                start, stop = doc.findBlockByNumber(i1).position(), doc.findBlockByNumber(i2).position()
                insert = "".join(line + "\n" for line in new)
            elif i1 == 0:  # everything removed
                start, stop, insert = 0, end, ""
            else:  # lines removed from or added at the end, with the line break before them
                start = doc.findBlockByNumber(i1).position() - 1 if i1 < len(a) else end
                stop, insert = end, "".join("\n" + line for line in new)
            cursor.setPosition(start)
            cursor.setPosition(stop, QTextCursor.MoveMode.KeepAnchor)
            cursor.insertText(insert)
        if many:
            self.highlighter.resume(self.firstVisibleBlock().blockNumber())
        self._refresh_selections()

    def set_history_keys(self, undo: list[QKeySequence], redo: list[QKeySequence]) -> None:
        """Use these keys for undo and redo (the window's; default: the platform's standard keys)."""
        self._undo_keys, self._redo_keys = list(undo), list(redo)

    def _history_key(self, event) -> str | None:
        """Return ``"undo"``/``"redo"`` if ``event`` is one of their keys, else None."""
        pressed = QKeySequence(event.keyCombination())
        if pressed in self._undo_keys or event.matches(QKeySequence.StandardKey.Undo):
            return "undo"
        if pressed in self._redo_keys or event.matches(QKeySequence.StandardKey.Redo):
            return "redo"
        return None

    def event(self, event) -> bool:
        """Leave undo/redo shortcuts to the window (the document's undo stack)."""
        if event.type() == event.Type.ShortcutOverride and self._history_key(event) is not None:
            event.accept()
            return True
        return super().event(event)

    def keyPressEvent(self, event) -> None:
        """Route undo/redo keys to the document; everything else edits the text."""
        key = self._history_key(event)
        if key == "undo":
            self.undoRequested.emit()
        elif key == "redo":
            self.redoRequested.emit()
        else:
            super().keyPressEvent(event)


class RulesPanel(QWidget):
    """The dock content: the rules editor and a line for the current error.

    Signals
    -------
    textEdited(text)
        The user changed the text.
    """

    textEdited = Signal(str)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.editor = RulesEditor(self)
        self.error_label = QLabel(self)
        self.error_label.setWordWrap(True)
        self.error_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.error_label.setStyleSheet("color: #c62828;")
        self.error_label.hide()
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.editor, 1)
        layout.addWidget(self.error_label)
        self._updating = False
        self._text = ""
        self.editor.textChanged.connect(self._on_text_changed)

    def text(self) -> str:
        """Return the text shown."""
        return self.editor.toPlainText()

    def set_text(self, text: str) -> None:
        """Show the document's text (does not emit :attr:`textEdited`)."""
        self._text = text
        self._updating = True
        try:
            self.editor.replace_text(text)
        finally:
            self._updating = False

    def set_error(self, error: Any) -> None:
        """Show a grammar error (with ``line``/``column`` if it has them), or clear it with None."""
        if error is None:
            self.editor.set_error(None)
            self.error_label.hide()
            return
        line = getattr(error, "line", None)
        column = getattr(error, "column", None)
        message = getattr(error, "message", None) or str(error)
        self.editor.set_error(line if line is not None else None, column, message)
        where = f"line {line}, column {column}: " if line is not None else ""
        self.error_label.setText(where + message)
        self.error_label.show()

    def highlight_rule(self, name: str | None) -> None:
        """Highlight the lines defining rule ``name`` (``"axiom"`` for the axiom; None clears)."""
        if not name:
            self.editor.set_rule_lines([])
            return
        pattern = re.compile(r"^\s*axiom\b" if name == "axiom" else rf"^\s*{re.escape(name)}\s*(?:\(|:|->|→)")
        lines = [i for i, line in enumerate(self.text().splitlines()) if pattern.match(line)]
        self.editor.set_rule_lines(lines)

    def _on_text_changed(self) -> None:
        if self._updating:
            return
        text = self.editor.toPlainText()
        if text != self._text:
            self._text = text
            self.textEdited.emit(text)
