"""The main window's actions, menus, toolbar and keyboard shortcuts.

Shortcuts come from ``QKeySequence.StandardKey`` wherever the platform has a standard (open,
save, undo, redo, zoom, help), so each platform gets its own keys; Redo answers to every key
the platform binds to it plus Ctrl+Shift+Z and, outside macOS, Ctrl+Y.  No key sequence is bound
twice (Qt would report it as ambiguous and run neither action): :func:`ambiguous_shortcuts`
checks it, and *Help → Keyboard Shortcuts* lists them all.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable
from typing import Any

from PySide6.QtGui import QAction, QActionGroup, QKeySequence
from PySide6.QtWidgets import (
    QDialog,
    QDialogButtonBox,
    QMainWindow,
    QMessageBox,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from .resources import examples

__all__ = [
    "ShortcutsDialog",
    "ambiguous_shortcuts",
    "create_actions",
    "create_menus",
    "redo_keys",
    "shortcut_rows",
    "undo_keys",
]

K = QKeySequence.StandardKey


def _unique(keys: Iterable[QKeySequence]) -> list[QKeySequence]:
    out: list[QKeySequence] = []
    for k in keys:
        if not k.isEmpty() and k not in out:
            out.append(k)
    return out


def undo_keys() -> list[QKeySequence]:
    """Return the platform's keys for Undo."""
    return _unique([*QKeySequence.keyBindings(K.Undo), QKeySequence("Ctrl+Z")])


def redo_keys() -> list[QKeySequence]:
    """Return the keys for Redo: the platform's, Ctrl+Shift+Z, and Ctrl+Y outside macOS."""
    extra = [QKeySequence("Ctrl+Shift+Z")] + ([] if sys.platform == "darwin" else [QKeySequence("Ctrl+Y")])
    return _unique([*QKeySequence.keyBindings(K.Redo), *extra])


def _keys(shortcut: Any) -> list[QKeySequence]:
    if shortcut is None:
        return []
    if isinstance(shortcut, QKeySequence.StandardKey):
        return _unique(QKeySequence.keyBindings(shortcut))
    return [QKeySequence(shortcut)]


def _action(win: QMainWindow, text: str, slot: Callable, shortcut: Any = None, tip: str = "") -> QAction:
    action = QAction(text, win)
    action.setShortcuts(_keys(shortcut))
    if tip:
        action.setStatusTip(tip)
    action.triggered.connect(slot)
    return action


def create_actions(win: Any) -> None:
    """Create the window's actions as ``win.act_*`` attributes."""
    doc, canvas = win.doc, win.canvas
    win.act_open = _action(win, "&Open…", win.open_dialog, K.Open, "Open an SVG or .lsys file")
    win.act_save = _action(win, "&Save", win.save, K.Save, "Save the rules as .lsys")
    win.act_save_as = _action(win, "Save &As…", win.save_as, K.SaveAs)
    win.act_export_svg = _action(win, "Export S&VG…", win.export_svg_dialog, "Ctrl+E")
    win.act_export_png = _action(win, "Export &PNG…", win.export_png_dialog, "Ctrl+Shift+E")
    win.act_quit = _action(win, "&Quit", win.close, K.Quit)
    win.act_undo = doc.undo_stack.createUndoAction(win, "&Undo")
    win.act_undo.setShortcuts(undo_keys())
    win.act_redo = doc.undo_stack.createRedoAction(win, "&Redo")
    win.act_redo.setShortcuts(redo_keys())
    win.act_symmetrize = _action(
        win, "S&ymmetrize", doc.symmetrize, "Ctrl+Shift+Y", "Infer again with relaxed tolerance"
    )
    win.act_randomize = _action(win, "&Randomize…", win.randomize_dialog, "Ctrl+R")
    win.act_unrandomize = _action(win, "Clear Randomization", lambda: doc.set_randomize(None))
    win.act_replace = _action(win, "Re&place Symbol…", win.replace_dialog, "Ctrl+Shift+R")
    win.act_clean = _action(
        win,
        "&Clean Numbers",
        doc.clean_numbers,
        "Ctrl+Shift+C",
        "Simplest values within tolerance: 0° for 0.44°",
    )
    win.act_grow = _action(win, "&Grow", lambda: win.change_count(+1), "Ctrl+]", "Increase the axiom's m")
    win.act_shrink = _action(win, "S&hrink", lambda: win.change_count(-1), "Ctrl+[", "Decrease the axiom's m")
    win.act_fit = _action(win, "&Fit", canvas.fit, "Ctrl+0")
    win.act_100 = _action(win, "&100 %", canvas.zoom_100, "Ctrl+1")
    win.act_zoom_in = _action(win, "Zoom &In", lambda: canvas.zoom_by(1.25), K.ZoomIn)
    win.act_zoom_out = _action(win, "Zoom &Out", lambda: canvas.zoom_by(0.8), K.ZoomOut)
    win.act_overlay = _action(win, "Show &Input Overlay", canvas.set_overlay_visible, "Ctrl+I")
    win.act_overlay.setCheckable(True)
    win.color_group = QActionGroup(win)
    win.act_colors = {}
    for mode, text in (
        ("none", "Original Colours"),
        ("group", "Colour by Similarity Group"),
        ("rule", "Colour by Rule"),
    ):
        act = QAction(text, win, checkable=True)
        act.setData(mode)
        act.triggered.connect(lambda _checked=False, m=mode: win.set_color_mode(m))
        win.color_group.addAction(act)
        win.act_colors[mode] = act
    win.act_colors["none"].setChecked(True)
    win.act_shortcuts = _action(
        win, "&Keyboard Shortcuts", lambda: ShortcutsDialog(win).exec(), K.HelpContents
    )
    win.act_about = _action(win, "&About lsys-editor", lambda: _about(win))


def create_menus(win: Any, docks: Iterable[Any]) -> None:
    """Fill the menu bar (File, Edit, View, Help) and the toolbar with ``win``'s actions."""
    bar = win.menuBar()
    file_menu = bar.addMenu("&File")
    file_menu.addAction(win.act_open)
    win.recent_menu = file_menu.addMenu("Open &Recent")
    win.recent.attach(win.recent_menu)
    win.examples_menu = file_menu.addMenu("Open E&xample")
    for path in examples():
        act = win.examples_menu.addAction(path.stem.replace("-", " ").capitalize())
        act.setToolTip(str(path))
        act.triggered.connect(lambda _=False, p=str(path): win.open_path(p))
    win.examples_menu.setEnabled(bool(win.examples_menu.actions()))
    for group in ((win.act_save, win.act_save_as), (win.act_export_svg, win.act_export_png), (win.act_quit,)):
        file_menu.addSeparator()
        for act in group:
            file_menu.addAction(act)
    edit = bar.addMenu("&Edit")
    for act in (win.act_undo, win.act_redo):
        edit.addAction(act)
    edit.addSeparator()
    for act in (
        win.act_symmetrize,
        win.act_randomize,
        win.act_unrandomize,
        win.act_replace,
        win.act_clean,
        win.act_grow,
        win.act_shrink,
    ):
        edit.addAction(act)
    view = bar.addMenu("&View")
    for act in (win.act_fit, win.act_100, win.act_zoom_in, win.act_zoom_out):
        view.addAction(act)
    view.addSeparator()
    view.addAction(win.act_overlay)
    for act in win.act_colors.values():
        view.addAction(act)
    view.addSeparator()
    for dock in docks:
        view.addAction(dock.toggleViewAction())
    help_menu = bar.addMenu("&Help")
    help_menu.addAction(win.act_shortcuts)
    help_menu.addAction(win.act_about)
    tools = win.addToolBar("Main")
    tools.setObjectName("toolbar-main")
    for act in (
        win.act_open,
        win.act_save,
        win.act_undo,
        win.act_redo,
        win.act_symmetrize,
        win.act_randomize,
        win.act_replace,
        win.act_shrink,
        win.act_grow,
        win.act_fit,
    ):
        tools.addAction(act)


def _plain(text: str) -> str:
    """Return a menu text without its mnemonic ``&`` and ellipsis."""
    return text.replace("&&", "\0").replace("&", "").replace("\0", "&").rstrip("…")


def shortcut_rows(win: QWidget) -> list[tuple[str, str]]:
    """Return ``(action, keys)`` for every action of ``win`` with a shortcut, in menu order."""
    rows = []
    for act in _all_actions(win):
        keys = [k.toString(QKeySequence.SequenceFormat.NativeText) for k in act.shortcuts()]
        if keys:
            rows.append((_plain(act.text()), ", ".join(keys)))
    return rows


def _all_actions(win: QWidget) -> list[QAction]:
    seen: list[QAction] = []
    for act in win.findChildren(QAction):
        if act not in seen:
            seen.append(act)
    return seen


def ambiguous_shortcuts(win: QWidget) -> dict[str, list[str]]:
    """Return every key sequence bound to more than one action of ``win`` (none: an empty dict)."""
    owners: dict[str, list[str]] = {}
    for act in _all_actions(win):
        for key in act.shortcuts():
            owners.setdefault(key.toString(QKeySequence.SequenceFormat.PortableText), []).append(
                _plain(act.text())
            )
    return {k: v for k, v in owners.items() if len(v) > 1}


class ShortcutsDialog(QDialog):
    """*Help → Keyboard Shortcuts*: every action with a shortcut and its keys on this platform."""

    def __init__(self, win: QWidget) -> None:
        super().__init__(win)
        self.setWindowTitle("Keyboard Shortcuts")
        rows = shortcut_rows(win)
        rows.append(("Pan the canvas", "Space + drag, middle button drag"))
        rows.append(("Zoom at the cursor", "Mouse wheel"))
        self.table = QTableWidget(len(rows), 2, self)
        self.table.setHorizontalHeaderLabels(["Action", "Keys"])
        self.table.verticalHeader().hide()
        self.table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        for i, (name, keys) in enumerate(rows):
            self.table.setItem(i, 0, QTableWidgetItem(name))
            self.table.setItem(i, 1, QTableWidgetItem(keys))
        self.table.resizeColumnsToContents()
        self.table.horizontalHeader().setStretchLastSection(True)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close, self)
        buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addWidget(self.table)
        layout.addWidget(buttons)
        self.resize(460, 560)


def _about(win: QWidget) -> None:
    from lsys_core import __version__

    QMessageBox.about(
        win,
        "About lsys-editor",
        f"<b>lsys-editor {__version__}</b><p>Turns vector art into an editable parametric L-system "
        "(Šťava et al., <i>Inverse Procedural Modeling by Automatic Generation of L-systems</i>, "
        "Eurographics 2010), and back.</p>",
    )
