"""The recent-files list, kept in QSettings, and its menu."""

from __future__ import annotations

import os

from PySide6.QtCore import QObject, QSettings, Signal
from PySide6.QtWidgets import QMenu

__all__ = ["MAX_RECENT", "RecentFiles"]

MAX_RECENT = 10
_KEY = "recentFiles"


class RecentFiles(QObject):
    """The files opened or saved last, newest first.

    Signals
    -------
    openRequested(path)
        The user picked a file in the menu.
    """

    openRequested = Signal(str)

    def __init__(self, settings: QSettings, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.settings = settings
        self._menu: QMenu | None = None

    def files(self) -> list[str]:
        """Return the recent files, newest first."""
        value = self.settings.value(_KEY, [])
        if isinstance(value, str):
            value = [value]
        return [str(v) for v in (value or [])]

    def add(self, path: str) -> None:
        """Put ``path`` first in the list."""
        path = os.path.abspath(path)
        files = [path] + [f for f in self.files() if f != path]
        self.settings.setValue(_KEY, files[:MAX_RECENT])

    def clear(self) -> None:
        """Forget every file."""
        self.settings.setValue(_KEY, [])

    def attach(self, menu: QMenu) -> None:
        """Fill ``menu`` with the list each time it opens."""
        self._menu = menu
        menu.aboutToShow.connect(self.fill_menu)

    def fill_menu(self) -> None:
        """Rebuild the attached menu from the list."""
        menu = self._menu
        if menu is None:
            return
        menu.clear()
        files = self.files()
        for i, path in enumerate(files):
            act = menu.addAction(f"&{i + 1} {os.path.basename(path)}")
            act.setToolTip(path)
            act.triggered.connect(lambda _checked=False, p=path: self.openRequested.emit(p))
        if not files:
            menu.addAction("(none)").setEnabled(False)
        else:
            menu.addSeparator()
            menu.addAction("Clear", self.clear)
