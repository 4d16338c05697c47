"""Keyboard shortcuts: platform standard keys, none bound twice, listed in Help."""

from __future__ import annotations

import sys

from PySide6.QtCore import Qt
from PySide6.QtGui import QKeySequence

from app.actions import ShortcutsDialog, ambiguous_shortcuts, shortcut_rows


def test_no_key_sequence_is_bound_to_two_actions(window):
    assert ambiguous_shortcuts(window) == {}
    bound = [k for _, keys in shortcut_rows(window) for k in keys.split(", ")]
    assert len(bound) == len(set(bound)) and len(bound) >= 15


def test_redo_answers_to_ctrl_shift_z_and_ctrl_y(window):
    keys = window.act_redo.shortcuts()
    assert QKeySequence("Ctrl+Shift+Z") in keys
    assert (QKeySequence("Ctrl+Y") in keys) == (sys.platform != "darwin")
    assert all(
        k in window.act_undo.shortcuts() for k in QKeySequence.keyBindings(QKeySequence.StandardKey.Undo)
    )
    assert window.act_open.shortcuts() == QKeySequence.keyBindings(QKeySequence.StandardKey.Open)


def test_undo_and_redo_keys_reach_the_document_from_canvas_and_rules_editor(
    window, helix_lsys, qtbot, wait_idle
):
    window.open_path(str(helix_lsys))
    wait_idle(window)
    doc = window.doc
    window.change_count(-1)
    changed = doc.text
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow, timeout=10_000)
    for widget in (window.canvas, window.rules_panel.editor):
        widget.setFocus()
        for redo in ("Ctrl+Shift+Z", "Ctrl+Y"):
            qtbot.keyClick(widget, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
            assert doc.text != changed, widget
            seq = QKeySequence(redo)[0]
            qtbot.keyClick(widget, seq.key(), seq.keyboardModifiers())
            assert doc.text == changed, (widget, redo)
    assert doc.undo_stack.count() == 1


def test_help_lists_the_shortcuts(window, qtbot):
    dialog = ShortcutsDialog(window)
    qtbot.addWidget(dialog)
    cells = {
        dialog.table.item(r, 0).text(): dialog.table.item(r, 1).text() for r in range(dialog.table.rowCount())
    }
    assert "Ctrl+Shift+Z" in cells["Redo"] and "Symmetrize" in cells and "Keyboard Shortcuts" in cells
    assert window.act_shortcuts in window.menuBar().actions()[-1].menu().actions()
