"""Syntax colours for ``.lsys`` text, applied a few lines per event-loop turn.

A new text is coloured from its first visible line, within :data:`HIGHLIGHT_BUDGET_MS` per turn,
so a grammar of thousands of lines never stalls the editor; only the head of a very long line
is coloured token by token (:data:`_TOKEN_COLOURS`).
"""

from __future__ import annotations

import time

from PySide6.QtCore import QRegularExpression, QTimer
from PySide6.QtGui import QColor, QFont, QSyntaxHighlighter, QTextCharFormat

__all__ = ["HIGHLIGHT_BUDGET_MS", "KEYWORDS", "LsysHighlighter"]

#: Longest time the highlighter colours lines in one event-loop turn after a new text.
HIGHLIGHT_BUDGET_MS = 8.0
#: Characters of a line whose tokens are coloured: a 2,900-character start line coloured token
#: by token took 25-30 ms to lay out at every change (3-8 ms with its tail plain).
_TOKEN_COLOURS = 600
KEYWORDS = ("lsys", "canvas", "viewbox", "size", "terminal", "style", "mirror", "axiom", "randomize")


def _fmt(color: str, *, bold: bool = False, italic: bool = False) -> QTextCharFormat:
    f = QTextCharFormat()
    f.setForeground(QColor(color))
    if bold:
        f.setFontWeight(QFont.Weight.Bold)
    f.setFontItalic(italic)
    return f


class LsysHighlighter(QSyntaxHighlighter):
    """Colour keywords, symbols, turtle commands, numbers, strings, conditions and comments."""

    RULES = (
        (r"\b(?:" + "|".join(KEYWORDS) + r")\b", _fmt("#7b1fa2", bold=True)),
        (r"\b[A-Z][A-Za-z0-9_]*\b", _fmt("#1565c0", bold=True)),
        (r"(?<![A-Za-z0-9_])(?:f|[+\-*])(?=\s*\()", _fmt("#2e7d32", bold=True)),
        (r"(?<![A-Za-z_])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", _fmt("#e65100")),
        (r"\bm\b\s*(?:>|==)\s*0|\bm\b", _fmt("#6a1b9a", italic=True)),
        (r"->|→|:", _fmt("#455a64", bold=True)),
        (r"\[|\]", _fmt("#ad1457", bold=True)),
    )
    STRING = (r'"[^"]*"?', _fmt("#00695c"))
    COMMENT = (r"#.*$", _fmt("#757575", italic=True))

    def __init__(self, document) -> None:
        super().__init__(document)
        self._rules = [(QRegularExpression(p), f) for p, f in self.RULES]
        self._string = QRegularExpression(self.STRING[0])
        self._comment = QRegularExpression(self.COMMENT[0])
        self._deferred = False
        self._start_block = self._next_block = 0
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(0)
        self._timer.timeout.connect(self._highlight_some)

    @property
    def pending(self) -> bool:
        """Whether lines are still waiting to be coloured."""
        return self._deferred or self._timer.isActive()

    def defer(self) -> None:
        """Colour nothing until :meth:`resume` (while a whole new text is set)."""
        self._timer.stop()
        self._deferred = True

    def resume(self, first: int = 0) -> None:
        """Colour the lines a few at a time from line ``first`` (the first visible), then the rest."""
        self._deferred = False
        self._start_block = max(0, first)
        self._next_block = 0  # lines done, counted from the start line round to the one before
        self._timer.start()  # in the next event-loop turns, not in the one that set the text

    def _highlight_some(self) -> None:
        doc = self.document()
        if doc is None:
            return
        t0 = time.perf_counter()
        count = doc.blockCount()
        while self._next_block < count:
            if (time.perf_counter() - t0) * 1e3 >= HIGHLIGHT_BUDGET_MS:
                self._timer.start()
                return
            block = doc.findBlockByNumber((self._start_block + self._next_block) % count)
            self._next_block += 1
            if block.isValid():
                self.rehighlightBlock(block)

    def highlightBlock(self, text: str) -> None:
        """Apply the formats to one line (strings and comments win over the rest)."""
        if self._deferred:
            return
        strings = []
        it = self._string.globalMatch(text)
        while it.hasNext():
            m = it.next()
            strings.append((m.capturedStart(), m.capturedLength()))
        plain = text
        for start, length in strings:  # path data holds hundreds of numbers: do not colour them
            plain = plain[:start] + " " * length + plain[start + length :]
        tokens = plain[:_TOKEN_COLOURS]  # a long line's tail stays plain: see _TOKEN_COLOURS
        for rx, fmt in self._rules:
            it = rx.globalMatch(tokens)
            while it.hasNext():
                m = it.next()
                self.setFormat(m.capturedStart(), m.capturedLength(), fmt)
        for start, length in strings:
            self.setFormat(start, length, self.STRING[1])
        it = self._comment.globalMatch(plain)
        while it.hasNext():
            m = it.next()
            self.setFormat(m.capturedStart(), len(text) - m.capturedStart(), self.COMMENT[1])
