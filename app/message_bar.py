"""A dismissable message line shown over the top of the canvas for errors and notes."""

from __future__ import annotations

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtWidgets import QHBoxLayout, QLabel, QToolButton, QWidget

__all__ = ["MessageBar"]


class MessageBar(QWidget):
    """A dismissable line over the top of its parent (the canvas) showing the latest error or note.

    It lies over the canvas rather than above it in the layout: a message that came and went
    resized the canvas, which re-fitted the drawing and rendered it twice (a draft, then full
    quality after the settle delay: 110–140 ms more for the first weight change after opening a
    file, whose "same rules" note was the first message).
    """

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.label = QLabel(self)
        self.label.setWordWrap(True)
        self.label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        close = QToolButton(self)
        close.setText("✕")
        close.setAutoRaise(True)
        close.clicked.connect(self.hide)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(8, 4, 4, 4)
        layout.addWidget(self.label, 1)
        layout.addWidget(close)
        self.setAutoFillBackground(True)
        self.setStyleSheet("MessageBar { background: #fdecea; } QLabel { color: #611a15; }")
        self.hide()
        if parent is not None:
            parent.installEventFilter(self)

    def show_message(self, text: str) -> None:
        """Show ``text`` (replacing the previous message)."""
        self.label.setText(text)
        self._place()
        self.show()
        self.raise_()

    def text(self) -> str:
        """Return the message shown (empty when hidden)."""
        return self.label.text() if self.isVisible() else ""

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        """Follow the parent's width."""
        if watched is self.parentWidget() and event.type() == QEvent.Type.Resize and not self.isHidden():
            self._place()
        return False

    def _place(self) -> None:
        parent = self.parentWidget()
        if parent is None:
            return
        width = parent.width()
        height = self.heightForWidth(width) if self.hasHeightForWidth() else -1
        self.setGeometry(0, 0, width, height if height > 0 else self.sizeHint().height())
