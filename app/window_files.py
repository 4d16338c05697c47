"""The main window's file side: open, save, export, drag and drop, and the unsaved-changes prompt.

:class:`WindowFiles` is mixed into :class:`~app.main_window.MainWindow`; it calls the document's
file methods and ``lsys_core`` exports, and turns every failure into a message.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from PySide6.QtWidgets import QFileDialog, QMessageBox

from lsys_core.errors import LsysError

from . import core

__all__ = ["FILE_FILTER", "WindowFiles"]

FILE_FILTER = "SVG or L-system (*.svg *.lsys);;SVG files (*.svg);;L-system rules (*.lsys);;All files (*)"


class WindowFiles:
    """Files of the main window (mixed into :class:`~app.main_window.MainWindow`)."""

    doc: Any
    recent: Any
    canvas: Any
    message_bar: Any

    def open_path(self, path: str) -> None:
        """Open an SVG (inferring its rules) or an .lsys file; errors become messages."""
        if not self.maybe_save():
            return
        path = str(path)
        if not os.path.isfile(path):
            self.show_message(f"Cannot open {path}: no such file")
            return
        if path.lower().endswith(".lsys"):
            try:
                self.doc.open_lsys(path)
            except LsysError as exc:
                self.show_message(f"Could not open {os.path.basename(path)}: {exc}")
                return
            self.recent.add(path)
            self.canvas.fit_on_next_drawing()
            self.message_bar.hide()
        else:
            self.statusBar().showMessage(f"Opening {os.path.basename(path)}…")
            self.doc.open_svg(path)

    def open_dialog(self) -> None:
        """Ask for a file and open it."""
        path, _ = QFileDialog.getOpenFileName(self, "Open", self._last_dir(), FILE_FILTER)
        if path:
            self.open_path(path)

    def save(self) -> bool:
        """Save the rules to the current .lsys file (asks for a name if there is none)."""
        if not self.doc.path:
            return self.save_as()
        return self._save_to(self.doc.path)

    def save_as(self) -> bool:
        """Ask for a file name and save the rules there."""
        suggestion = self.doc.path or (
            str(Path(self.doc.scene_path).with_suffix(".lsys"))
            if self.doc.scene_path
            else os.path.join(self._last_dir(), "untitled.lsys")
        )
        path, _ = QFileDialog.getSaveFileName(self, "Save rules", suggestion, "L-system rules (*.lsys)")
        return bool(path) and self._save_to(path)

    def _save_to(self, path: str) -> bool:
        try:
            self.doc.save(path)
        except LsysError as exc:
            self.show_message(f"Could not save: {exc}")
            return False
        self.recent.add(path)
        self.statusBar().showMessage(f"Saved {path}", 5000)
        return True

    def export_svg(self, path: str) -> bool:
        """Write the current drawing as SVG; errors become messages."""
        return self._export(core.export_svg, path)

    def export_png(self, path: str) -> bool:
        """Render the current drawing into a PNG file; errors become messages."""
        return self._export(core.export_png, path)

    def _export(self, fn, path: str) -> bool:
        if self.doc.drawing is None:
            self.show_message("Nothing to export yet.")
            return False
        try:
            fn(self.doc.drawing, path)
        except LsysError as exc:
            self.show_message(f"Could not export: {exc}")
            return False
        self.statusBar().showMessage(f"Exported {path}", 5000)
        return True

    def export_svg_dialog(self) -> None:
        """Ask for a file name and export SVG."""
        path, _ = QFileDialog.getSaveFileName(
            self, "Export SVG", self._export_name(".svg"), "SVG files (*.svg)"
        )
        if path:
            self.export_svg(path)

    def export_png_dialog(self) -> None:
        """Ask for a file name and export PNG."""
        path, _ = QFileDialog.getSaveFileName(
            self, "Export PNG", self._export_name(".png"), "PNG images (*.png)"
        )
        if path:
            self.export_png(path)

    def _export_name(self, suffix: str) -> str:
        base = self.doc.path or self.doc.scene_path
        if base:
            return str(Path(base).with_name(Path(base).stem + "-derived" + suffix))
        return os.path.join(self._last_dir(), "derived" + suffix)

    def _last_dir(self) -> str:
        recent = self.recent.files()
        return os.path.dirname(recent[0]) if recent else os.getcwd()

    def dragEnterEvent(self, event) -> None:
        """Accept dragged .svg and .lsys files."""
        if any(
            u.isLocalFile() and u.toLocalFile().lower().endswith((".svg", ".lsys"))
            for u in event.mimeData().urls()
        ):
            event.acceptProposedAction()

    def dropEvent(self, event) -> None:
        """Open the first dropped .svg or .lsys file."""
        for url in event.mimeData().urls():
            path = url.toLocalFile()
            if url.isLocalFile() and path.lower().endswith((".svg", ".lsys")):
                event.acceptProposedAction()
                self.open_path(path)
                return

    def ask_save_changes(self) -> QMessageBox.StandardButton:
        """Ask whether to save unsaved changes (Save, Discard or Cancel)."""
        B = QMessageBox.StandardButton
        return QMessageBox.question(
            self,
            "Unsaved changes",
            f"Save the changes to {self.doc.display_name()}?",
            B.Save | B.Discard | B.Cancel,
            B.Save,
        )

    def maybe_save(self) -> bool:
        """Offer to save unsaved changes; return False if the user cancelled."""
        if not self.doc.modified:
            return True
        answer = self.ask_save_changes()
        if answer == QMessageBox.StandardButton.Save:
            return self.save()
        return answer == QMessageBox.StandardButton.Discard
