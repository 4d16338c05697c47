"""A rule card: one rule of the rules view in a designer's words, with its controls.

The card shows the rule's kind ("ring of 8", "row of 12, 46 apart"), thumbnails of the terminals
it draws, the rules it uses, and, when open, one :class:`~app.params_panel.ParamRow` per semantic
control, a page of :data:`~app.params_panel.ROWS_PER_PAGE` at a time.  Rows are reused from one
grammar to the next; the card forwards edits as ``(rule, control, value)``.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QImage, QPixmap
from PySide6.QtWidgets import QFrame, QHBoxLayout, QLabel, QPushButton, QToolButton, QVBoxLayout, QWidget

from lsys_core.grammar import Param

from . import core
from .params_panel import ROWS_PER_PAGE, ParamRow

__all__ = ["THUMB", "RuleCard", "thumbnail"]

#: Side of a terminal's thumbnail on a card, in logical pixels.
THUMB = 36
_SEP = "\x1f"


def thumbnail(terminal: Any, size: int, dpr: float = 1.0) -> QPixmap:
    """Return a pixmap of ``terminal``'s shape fitted in ``size`` logical pixels."""
    px = max(8, round(size * dpr))
    pixels = core.terminal_image(terminal, px)
    image = QImage(pixels.data, px, px, pixels.strides[0], QImage.Format.Format_RGBA8888).copy()
    pixmap = QPixmap.fromImage(image)
    pixmap.setDevicePixelRatio(dpr)
    return pixmap


class RuleCard(QFrame):
    """One rule: a header that folds, thumbnails, and its controls when open.

    Signals
    -------
    controlEdited(rule, label, value)
        A control row of this card was moved to ``value``.
    clicked(rule)
        The card was clicked.
    dragStarted(), dragFinished()
        A control's slider drag began or ended.
    """

    controlEdited = Signal(str, str, float)
    clicked = Signal(str)
    dragStarted = Signal()
    dragFinished = Signal()

    def __init__(self, parent: QWidget) -> None:
        super().__init__(parent)
        self.card: Any = None
        self._selected = False
        self.setObjectName("card")
        self.setFrameShape(QFrame.Shape.StyledPanel)
        self.fold = QToolButton(self)
        self.fold.setCheckable(True)
        self.fold.setAutoRaise(True)
        self.fold.toggled.connect(lambda _on: self._refresh())
        self.name = QLabel(self)
        self.name.setTextFormat(Qt.TextFormat.PlainText)
        bold = self.name.font()
        bold.setBold(True)
        self.name.setFont(bold)
        self.title = QLabel(self)
        self.title.setTextFormat(Qt.TextFormat.PlainText)
        self.title.setWordWrap(True)
        head = QHBoxLayout()
        head.setContentsMargins(0, 0, 0, 0)
        head.addWidget(self.fold)
        head.addWidget(self.name)
        head.addWidget(self.title, 1)
        self.thumbs = QHBoxLayout()
        self.thumbs.setContentsMargins(22, 0, 0, 0)
        self.thumbs.setSpacing(4)
        self.thumb_labels: list[QLabel] = []
        self.uses = QLabel(self)
        self.uses.setStyleSheet("color: palette(mid);")
        self.thumbs.addWidget(self.uses)
        self.thumbs.addStretch(1)
        self.body = QWidget(self)
        self.rows_layout = QVBoxLayout(self.body)
        self.rows_layout.setContentsMargins(22, 0, 0, 0)
        self.rows_layout.setSpacing(2)
        self.limit = ROWS_PER_PAGE  # controls shown while open; "Show more" adds a page
        self.more = QPushButton(self.body)
        self.more.setFlat(True)
        self.more.clicked.connect(self._show_more)
        self.rows_layout.addWidget(self.more)
        self.lines: list[tuple[QWidget, QLabel, ParamRow]] = []
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.setSpacing(2)
        layout.addLayout(head)
        layout.addLayout(self.thumbs)
        layout.addWidget(self.body)

    def configure(self, card: Any, open_: bool, terminals: dict[str, Any]) -> None:
        """Show ``card``; ``open_`` unfolds its controls."""
        self.card = card
        self.limit = ROWS_PER_PAGE
        name = "Start (axiom)" if card.owner == "axiom" else card.owner
        summary = card.summary.split(": ", 1)[-1] if card.owner == "axiom" else card.summary
        self.name.setText(name)
        self.title.setText("— " + summary)
        self.fold.blockSignals(True)
        self.fold.setChecked(open_)
        self.fold.blockSignals(False)
        self._show_thumbs([terminals[t] for t in card.terminals if t in terminals])
        self.uses.setText(("uses " + ", ".join(card.calls)) if card.calls else "")
        self.uses.setVisible(bool(card.calls))
        self._refresh()

    def _show_thumbs(self, terms: list[Any]) -> None:
        dpr = float(self.devicePixelRatioF())
        for i, t in enumerate(terms):
            if i == len(self.thumb_labels):
                label = QLabel(self)
                label.setFixedSize(THUMB, THUMB)
                label.setStyleSheet("background: white; border: 1px solid palette(mid);")
                self.thumbs.insertWidget(i, label)
                self.thumb_labels.append(label)
            label = self.thumb_labels[i]
            label.setPixmap(thumbnail(t, THUMB - 2, dpr))
            label.setToolTip(f"terminal {t.name}")
            label.show()
        for label in self.thumb_labels[len(terms) :]:
            label.hide()

    def update_values(self, card: Any) -> None:
        """Show the values of ``card`` (same controls as shown) without rebuilding."""
        self.card = card
        self.title.setText("— " + card.summary.split(": ", 1)[-1])
        for (line, _label, row), ctl in zip(self.lines, card.controls, strict=False):
            if not line.isHidden() and not row.slider.isSliderDown() and not row.spin.hasFocus():
                row.set_value(ctl.value)

    def _show_more(self) -> None:
        self.limit += ROWS_PER_PAGE
        self._refresh()

    def _refresh(self) -> None:
        open_ = self.fold.isChecked() and self.card is not None
        controls = self.card.controls[: self.limit] if open_ else ()
        self.fold.setArrowType(Qt.ArrowType.DownArrow if open_ else Qt.ArrowType.RightArrow)
        self.fold.setEnabled(bool(self.card is not None and self.card.controls))
        for i, ctl in enumerate(controls):
            param = Param(self.card.owner + _SEP + ctl.label, ctl.label, ctl.value, ctl.kind)
            if i == len(self.lines):
                line = QWidget(self.body)
                label = QLabel(line)
                label.setMinimumWidth(110)
                row = ParamRow(param, line)
                row.valueEdited.connect(self._on_row_edited)
                row.dragStarted.connect(self.dragStarted)
                row.dragFinished.connect(self.dragFinished)
                lay = QHBoxLayout(line)
                lay.setContentsMargins(0, 0, 0, 0)
                lay.addWidget(label)
                lay.addWidget(row, 1)
                self.rows_layout.insertWidget(len(self.lines), line)
                self.lines.append((line, label, row))
            line, label, row = self.lines[i]
            row.configure(param)
            label.setText(ctl.label + (f" ({ctl.unit})" if ctl.unit else ""))
            label.setToolTip("writes " + ", ".join(w.key for w in ctl.writes))
            line.show()
        for line, _label, _row in self.lines[len(controls) :]:
            line.hide()
        rest = len(self.card.controls) - len(controls) if open_ else 0
        self.more.setVisible(rest > 0)
        self.more.setText(f"Show {min(rest, ROWS_PER_PAGE)} more of {rest}…")
        self.body.setVisible(bool(controls))

    def set_selected(self, selected: bool) -> None:
        """Frame the card when its rule is selected."""
        if selected == self._selected:
            return  # a style sheet change re-polishes the card and its children: only on change
        self._selected = selected
        self.setStyleSheet("QFrame#card { border: 2px solid #f9a825; }" if selected else "")

    def mousePressEvent(self, event) -> None:
        """A click selects the rule."""
        if self.card is not None:
            self.clicked.emit(self.card.owner)
        super().mousePressEvent(event)

    def _on_row_edited(self, key: str, value: float) -> None:
        owner, label = key.split(_SEP, 1)
        self.controlEdited.emit(owner, label, value)
