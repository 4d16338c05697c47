"""Crash recovery: autosave the open document and offer it back after a crash.

Every running editor owns one recovery file (``recovery-<id>.json`` in the application data
folder) and holds a :class:`QLockFile` beside it for as long as it runs.  While the document
has unsaved edits it is written there (atomically) every few seconds; a clean exit or a save
removes it.  At start-up, a recovery file whose lock is free (its editor has died) is a crash
leftover, which the editor offers to restore.
"""

from __future__ import annotations

import contextlib
import json
import os
import time
import uuid
from pathlib import Path
from typing import Any

from PySide6.QtCore import QLockFile, QObject, QStandardPaths, QTimer

from lsys_core.errors import LsysError

from . import core

__all__ = ["AUTOSAVE_MS", "Recovery", "find_orphans", "recovery_dir"]

AUTOSAVE_MS = 5000
_VERSION = 1


def recovery_dir() -> Path:
    """Return the folder of recovery files (created if missing)."""
    base = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
    path = Path(base or Path.home() / ".lsys-editor") / "recovery"
    path.mkdir(parents=True, exist_ok=True)
    return path


def find_orphans(directory: Path | None = None) -> list[tuple[Path, dict[str, Any]]]:
    """Return recovery files left by editors that did not exit cleanly, newest first.

    Each file is returned with its content; unreadable files are skipped.  A file belongs to
    a running editor while that editor holds its lock.
    """
    directory = directory or recovery_dir()
    found = []
    for path in directory.glob("recovery-*.json"):
        lock = QLockFile(str(path.with_suffix(".lock")))
        lock.setStaleLockTime(0)
        if not lock.tryLock(0):
            continue  # another editor is running and owns it
        lock.unlock()
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if isinstance(data, dict) and data.get("version") == _VERSION and isinstance(data.get("state"), dict):
            found.append((path, data))
    found.sort(key=lambda item: item[1].get("saved_at", 0), reverse=True)
    return found


def discard_orphan(path: Path) -> None:
    """Delete a crash leftover once it was restored or declined."""
    for p in (path, path.with_suffix(".lock")):
        with contextlib.suppress(OSError):
            p.unlink()


class Recovery(QObject):
    """Autosave ``doc`` while it has unsaved edits; remove the file on a clean exit.

    Parameters
    ----------
    doc : Document
        The document to save (its :meth:`~app.document.Document.snapshot`).
    directory : Path, optional
        Where recovery files go (default :func:`recovery_dir`).
    interval_ms : int
        Autosave period.
    """

    def __init__(
        self, doc, directory: Path | None = None, interval_ms: int = AUTOSAVE_MS, parent=None
    ) -> None:
        super().__init__(parent)
        self.doc = doc
        self.directory = directory or recovery_dir()
        name = f"recovery-{os.getpid()}-{uuid.uuid4().hex[:8]}"
        self.path = self.directory / f"{name}.json"
        self._lock = QLockFile(str(self.path.with_suffix(".lock")))
        self._lock.tryLock(0)
        self._dirty = False
        self.last_error: str | None = None
        doc.undo_stack.indexChanged.connect(self._mark_dirty)
        doc.undo_stack.cleanChanged.connect(self._on_clean_changed)
        self.timer = QTimer(self)
        self.timer.setInterval(interval_ms)
        self.timer.timeout.connect(self.save_now)
        self.timer.start()

    def _mark_dirty(self, _index: int = 0) -> None:
        self._dirty = True

    def _on_clean_changed(self, clean: bool) -> None:
        if clean:
            self._remove_file()
            self._dirty = False

    def save_now(self) -> bool:
        """Write the recovery file if the document changed since the last autosave.

        Returns
        -------
        bool
            Whether a file was written.
        """
        if not self._dirty or not self.doc.modified:
            return False
        payload = {"version": _VERSION, "saved_at": time.time(), "state": self.doc.snapshot()}
        try:
            core.write_atomic(str(self.path), json.dumps(payload, indent=1).encode("utf-8"))
        except LsysError as exc:  # a full disk must not interrupt editing; report once
            if self.last_error != str(exc):
                self.doc.message.emit(f"Autosave failed: {exc}")
            self.last_error = str(exc)
            return False
        self._dirty = False
        self.last_error = None
        return True

    def _remove_file(self) -> None:
        with contextlib.suppress(OSError):
            self.path.unlink()

    def close(self) -> None:
        """Stop autosaving and remove the recovery file (a clean exit)."""
        self.timer.stop()
        self._remove_file()
        self._lock.unlock()
