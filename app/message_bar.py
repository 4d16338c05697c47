"""A dismissable message line shown above the canvas for errors and notes."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QHBoxLayout, QLabel, QToolButton, QWidget

__all__ = ["MessageBar"]


class MessageBar(QWidget):
    """A dismissable line above the canvas showing the latest error or note."""

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

    def show_message(self, text: str) -> None:
        """Show ``text`` (replacing the previous message)."""
        self.label.setText(text)
        self.show()

    def text(self) -> str:
        """Return the message shown (empty when hidden)."""
        return self.label.text() if self.isVisible() else ""
