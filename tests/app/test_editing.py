"""Editing an .lsys document in the main window: rules text, parameters, undo, randomize, canvas."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QMimeData, QPoint, QPointF, Qt, QUrl
from PySide6.QtGui import QDropEvent, QKeySequence, QTextCursor
from PySide6.QtWidgets import QMessageBox

from app import core
from lsys_core.grammar.model import Randomize


def _open(window, path, wait_idle):
    window.open_path(str(path))
    wait_idle(window)
    assert window.doc.drawing is not None


def _replace_in_editor(window, old: str, new: str) -> None:
    """Edit the rules like a user: select ``old`` in the editor and type ``new`` over it."""
    editor = window.rules_panel.editor
    start = editor.toPlainText().index(old)
    cursor = editor.textCursor()
    cursor.setPosition(start)
    cursor.setPosition(start + len(old), QTextCursor.MoveMode.KeepAnchor)
    editor.setTextCursor(cursor)
    editor.insertPlainText(new)


def test_open_lsys_fills_rules_and_params(window, helix_lsys, wait_idle):
    _open(window, helix_lsys, wait_idle)
    assert "P(m): m > 0 -> A f(24)" in window.rules_panel.text()
    rows = window.params_panel.rows
    assert set(rows) == {"axiom.0.0.m", "P.0.1.v", "P.0.2.v", "P.0.3.v"}
    assert rows["P.0.1.v"].value() == pytest.approx(24)
    assert len(window.doc.drawing) == 120
    assert "120 elements" in window._status_labels["elements"].text()
    assert window.canvas._frame is not None and not window.canvas._frame.draft
    assert not window.inference_panel.weights_box.isEnabled()  # no input SVG: nothing to infer


def test_editing_rule_text_rederives_and_keeps_last_drawing_while_invalid(
    window, helix_lsys, qtbot, wait_idle
):
    _open(window, helix_lsys, wait_idle)
    doc = window.doc
    _replace_in_editor(window, "P(119)", "P(49)")
    qtbot.waitUntil(lambda: len(doc.drawing) == 50, timeout=120_000)
    good = doc.drawing

    _replace_in_editor(window, "f(24)", "f(24")  # unbalanced: a syntax error on line 4
    qtbot.waitUntil(lambda: doc.error is not None, timeout=120_000)
    assert doc.error.line == 4
    assert window.rules_panel.error_label.isVisible()
    assert "line 4" in window.rules_panel.error_label.text()
    assert window.rules_panel.editor._error[0] == 4
    assert not window.params_panel.isEnabled()
    wait_idle(window)
    assert doc.drawing is good  # the last valid drawing stays
    assert window.canvas._frame.drawing is window.canvas.drawing

    _replace_in_editor(window, "f(24", "f(30)")
    qtbot.waitUntil(lambda: doc.error is None and doc.drawing is not good, timeout=120_000)
    assert not window.rules_panel.error_label.isVisible()
    wait_idle(window)  # the panels follow the drawing in later event-loop turns
    assert window.params_panel.rows["P.0.1.v"].value() == pytest.approx(30)


def test_param_slider_drag_rederives_without_inference_as_one_undo_step(window, helix_lsys, qtbot, wait_idle):
    _open(window, helix_lsys, wait_idle)
    doc = window.doc
    started = []
    doc.inferenceStarted.connect(lambda: started.append(1))
    row = window.params_panel.rows["P.0.3.v"]  # the +(11) turn
    before = doc.drawing
    drafts = []
    window.canvas.runner.resultReady.connect(lambda f: drafts.append(f.draft))
    row.slider.setSliderDown(True)  # press
    for pos in range(row.slider.value() + 10, row.slider.value() + 60, 10):
        row.slider.setValue(pos)
        qtbot.waitUntil(lambda: not doc.rules.deriver.busy, timeout=120_000)
        qtbot.wait(5)
    assert doc.interactive
    row.slider.setSliderDown(False)  # release
    wait_idle(window)
    assert not doc.interactive
    assert started == []  # a parameter change never re-runs inference
    assert doc.drawing is not before and len(doc.drawing) == len(before)
    assert not np.allclose(doc.drawing.b, before.b)
    params = {p.key: p.value for p in core.list_params(doc.grammar)}
    assert params["P.0.3.v"] == pytest.approx(row.value()) and row.value() > 11
    assert "+(11)" not in doc.text
    assert doc.undo_stack.count() == 1  # one step for the whole drag
    assert True in drafts and drafts[-1] is False  # drafts while dragging, full quality after release
    assert not window.canvas._frame.draft
    doc.undo_stack.undo()
    wait_idle(window)
    assert "+(11)" in doc.text and row.value() == pytest.approx(11)
    np.testing.assert_allclose(doc.drawing.b, before.b)


def test_spin_box_sets_exact_value(window, helix_lsys, qtbot, wait_idle):
    _open(window, helix_lsys, wait_idle)
    window.params_panel.rows["axiom.0.0.m"].spin.setValue(9)
    qtbot.waitUntil(lambda: len(window.doc.drawing) == 10, timeout=120_000)
    assert "axiom: P(9)" in window.rules_panel.text()


def test_undo_redo_of_text_params_and_actions(window, helix_lsys, qtbot, wait_idle):
    _open(window, helix_lsys, wait_idle)
    doc = window.doc
    original = doc.text
    _replace_in_editor(window, "f(24)", "f(20)")
    qtbot.waitUntil(lambda: "f(20)" in doc.text, timeout=120_000)
    window.change_count(-1)  # Shrink: m 119 -> 107
    wait_idle(window)
    assert "P(107)" in doc.text and len(doc.drawing) == 108
    doc.set_randomize(Randomize(angle=5, seed=3))
    wait_idle(window)
    assert doc.undo_stack.count() == 3
    assert window.act_undo.isEnabled()
    # Ctrl+Z in the rules editor goes to the document's undo stack
    window.rules_panel.editor.setFocus()
    window.rules_panel.editor.undoRequested.emit()
    wait_idle(window)
    assert doc.randomize is None
    doc.undo_stack.undo()
    doc.undo_stack.undo()
    wait_idle(window)
    assert doc.text == original and window.rules_panel.text() == original
    assert len(doc.drawing) == 120 and not doc.modified
    doc.undo_stack.redo()
    doc.undo_stack.redo()
    wait_idle(window)
    assert "P(107)" in doc.text and "f(20)" in doc.text and len(doc.drawing) == 108


def test_typing_merges_into_one_undo_step(window, helix_lsys, qtbot, wait_idle):
    _open(window, helix_lsys, wait_idle)
    editor = window.rules_panel.editor
    editor.setFocus()
    cursor = editor.textCursor()
    cursor.movePosition(QTextCursor.MoveOperation.End)
    editor.setTextCursor(cursor)
    qtbot.keyClicks(editor, "# a note")
    assert window.doc.text.endswith("# a note")
    assert window.doc.undo_stack.count() == 1
    qtbot.keySequence(editor, QKeySequence(QKeySequence.StandardKey.Undo))
    assert "# a note" not in window.doc.text
    qtbot.waitUntil(lambda: window.rules_panel.text() == window.doc.text)  # in the next event-loop turn


def test_randomize_is_seeded(window, helix_lsys, wait_idle):
    _open(window, helix_lsys, wait_idle)
    doc = window.doc
    plain = doc.drawing
    doc.set_randomize(Randomize(angle=10, distance=0.1, scale=0.05, seed=7))
    wait_idle(window)
    first = doc.drawing
    assert not np.allclose(first.b, plain.b)
    doc.set_randomize(None)
    wait_idle(window)
    np.testing.assert_allclose(doc.drawing.b, plain.b)
    doc.set_randomize(Randomize(angle=10, distance=0.1, scale=0.05, seed=7))
    wait_idle(window)
    np.testing.assert_allclose(doc.drawing.b, first.b)  # same seed, same drawing
    doc.set_randomize(Randomize(angle=10, distance=0.1, scale=0.05, seed=8))
    wait_idle(window)
    assert not np.allclose(doc.drawing.b, first.b)


def test_randomize_dialog_reroll_applies_a_new_seed(window, helix_lsys, wait_idle):
    from app.dialogs import RandomizeDialog

    _open(window, helix_lsys, wait_idle)
    dialog = RandomizeDialog(None, window)
    dialog.applied.connect(window.doc.preview_randomize)
    dialog.reroll()
    first = window.doc.rules.preview_randomize
    dialog.reroll()
    shown = window.doc.rules.preview_randomize
    assert shown.seed != first.seed and shown.angle == pytest.approx(dialog.angle.value())
    assert window.doc.randomize is None and window.doc.undo_stack.count() == 0  # a preview only
    dialog.close()


def test_replace_nonterminal_by_terminal(window, tmp_path, wait_idle):
    pytest.importorskip("lsys_core.grammar.edit")
    from app.dialogs import ReplaceDialog

    path = tmp_path / "rows.lsys"
    path.write_text(
        'lsys 1\nterminal A "M 0 0 L 4 0 L 4 4 Z"\nterminal W "M 0 0 L 10 0 L 10 10 L 0 10 Z"\n'
        "axiom: Q(3)\nP(m): m > 0 -> A f(5) P(m-1)\nP(m): m == 0 -> A\n"
        "Q(m): m > 0 -> P(4) +(90) f(10) -(90) Q(m-1)\nQ(m): m == 0 -> P(4)\n",
        encoding="utf-8",
    )
    _open(window, path, wait_idle)
    assert len(window.doc.drawing) == 4 * 5
    dialog = ReplaceDialog(window.doc.grammar, (), None, window)
    dialog.target.setCurrentIndex(dialog.target.findText("P (non-terminal)"))
    dialog.source.setCurrentIndex(dialog.source.findText("terminal W"))
    choice = dialog.choice()
    assert (choice.kind, choice.target, choice.terminal) == ("nonterminal", "P", "W")
    window.replace_symbol(choice)
    wait_idle(window)
    assert len(window.doc.drawing) == 4  # each row of five A became one W
    window.doc.undo_stack.undo()
    wait_idle(window)
    assert len(window.doc.drawing) == 20


def test_replace_terminal_shape(window, helix_lsys, wait_idle):
    pytest.importorskip("lsys_core.grammar.edit")
    from app.dialogs import ReplaceChoice

    _open(window, helix_lsys, wait_idle)
    before = window.doc.grammar.terminal("A")
    window.replace_symbol(ReplaceChoice("terminal", "A", path="M 0 0 L 3 0 L 3 3 Z", style="fill:#f00"))
    wait_idle(window)
    term = window.doc.grammar.terminal("A")
    assert term.style == "fill:#f00" and term.path != before.path
    assert len(window.doc.drawing) == 120 and window.doc.undo_stack.count() == 1
    window.doc.undo_stack.undo()
    wait_idle(window)
    assert window.doc.grammar.terminal("A") == before


def test_click_on_element_highlights_its_rule(window, helix_lsys, qtbot, wait_idle):
    _open(window, helix_lsys, wait_idle)
    canvas = window.canvas
    centers = core.instance_centers(window.doc.drawing)
    c = centers[40]
    x, y = canvas.view.to_widget(c.real, c.imag)
    qtbot.mouseClick(canvas, Qt.MouseButton.LeftButton, pos=QPoint(round(x), round(y)))
    lines = window.rules_panel.editor._rule_lines
    text = window.rules_panel.text().splitlines()
    assert lines and all(text[i].startswith("P(m)") for i in lines)
    assert canvas._highlight is not None and canvas._highlight.sum() == 120  # every A comes from rule P
    wait_idle(window)
    qtbot.mouseClick(canvas, Qt.MouseButton.LeftButton, pos=QPoint(2, 2))  # empty corner
    assert window.rules_panel.editor._rule_lines == []


def test_zoom_pan_fit_and_100_percent(window, helix_lsys, qtbot, wait_idle):
    _open(window, helix_lsys, wait_idle)
    canvas = window.canvas
    fitted = canvas.view
    window.act_100.trigger()
    assert canvas.view.zoom == pytest.approx(1.0)
    canvas.zoom_at(2.0, QPointF(100, 100))
    doc_pt = canvas.view.to_doc(100, 100)
    canvas.zoom_at(1.5, QPointF(100, 100))
    assert canvas.view.to_doc(100, 100) == pytest.approx(doc_pt)  # the point under the cursor stays
    ox = canvas.view.ox
    qtbot.mousePress(canvas, Qt.MouseButton.LeftButton, pos=QPoint(200, 200))
    qtbot.mouseMove(canvas, QPoint(260, 230))
    qtbot.mouseRelease(canvas, Qt.MouseButton.LeftButton, pos=QPoint(260, 230))
    assert canvas.view.ox == pytest.approx(ox + 60)
    window.act_fit.trigger()
    assert canvas.view == fitted
    wait_idle(window)
    assert canvas._frame.view == canvas.view and not canvas._frame.draft


def test_color_modes_and_overlay(window, helix_lsys, wait_idle):
    from app.coloring import recolor

    _open(window, helix_lsys, wait_idle)
    window.doc.edit_text(window.doc.text.replace("axiom: P(119)", "axiom: A f(30) P(119)"))
    wait_idle(window)
    drawing = window.doc.drawing
    by_rule = recolor(drawing, "rule")
    styles, style = by_rule.instance_styles()
    assert len(styles) == 2  # terminal A drawn by the axiom and by rule P: two colours
    assert len(set(styles)) == 2 and np.array_equal(style == style[drawing.rule == 0][0], drawing.rule == 0)
    assert by_rule.terminals == drawing.terminals  # the shapes stay, only the instances' paint changes
    styles, style = recolor(drawing, "group").instance_styles()
    assert len(styles) == 1 and "stroke:#1f77b4" in styles[0] and "fill:none" in styles[0]
    window.act_colors["rule"].trigger()
    wait_idle(window)
    frame = window.canvas._frame
    assert frame.drawing is window.doc.drawing and frame.color_mode == "rule"


def test_save_and_reopen(window, helix_lsys, tmp_path, wait_idle):
    _open(window, helix_lsys, wait_idle)
    _replace_in_editor(window, "P(119)", "P(20)")
    assert window.doc.modified and window.isWindowModified()
    out = tmp_path / "saved.lsys"
    assert window._save_to(str(out))
    assert out.read_text(encoding="utf-8") == window.doc.text
    assert not window.doc.modified and window.doc.path == str(out)
    assert window.recent.files()[0] == str(out)


def test_close_with_unsaved_changes_asks(window, helix_lsys, monkeypatch, wait_idle):
    _open(window, helix_lsys, wait_idle)
    _replace_in_editor(window, "P(119)", "P(20)")
    monkeypatch.setattr(window, "ask_save_changes", lambda: QMessageBox.StandardButton.Cancel)
    assert not window.close()
    assert window.isVisible()
    monkeypatch.setattr(window, "ask_save_changes", lambda: QMessageBox.StandardButton.Discard)
    assert window.close()


def test_drop_opens_file_and_recent_menu_lists_it(window, helix_lsys, qtbot, wait_idle):
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(helix_lsys))])
    event = QDropEvent(
        QPointF(10, 10),
        Qt.DropAction.CopyAction,
        mime,
        Qt.MouseButton.NoButton,
        Qt.KeyboardModifier.NoModifier,
    )
    window.dropEvent(event)
    wait_idle(window)
    assert window.doc.path == str(helix_lsys) and len(window.doc.drawing) == 120
    window.recent.fill_menu()
    assert any(str(helix_lsys) == a.toolTip() for a in window.recent_menu.actions())


def test_layout_is_kept_in_settings(make_window):
    first = make_window(restore_layout=True)
    first.inference_dock.hide()
    first.close()
    second = make_window(restore_layout=True)
    assert not second.inference_dock.isVisible()


def test_param_rows_follow_values_outside_their_range(qtbot):
    from app.params_panel import ParamsPanel, slider_range
    from lsys_core.grammar import Param

    panel = ParamsPanel()
    qtbot.addWidget(panel)
    panel.set_params([Param("P.0.1.v", "P: f #1", 24.0, "distance")])
    row = panel.rows["P.0.1.v"]
    assert (row.lo, row.hi) == slider_range("distance", 24.0) == (0.0, 48.0)
    panel.set_params([Param("P.0.1.v", "P: f #1", 300.0, "distance")])
    assert panel.rows["P.0.1.v"] is row and row.hi >= 300 and row.value() == pytest.approx(300)
    assert row.slider.value() < row.slider.maximum()
    edits = []
    panel.paramEdited.connect(lambda k, v: edits.append((k, v)))
    row.slider.setValue(row.slider.maximum())
    assert edits == [("P.0.1.v", pytest.approx(row.hi))]
    assert slider_range("scale", 0.99)[0] > 0  # a scale must stay positive


def test_replace_dialog_offers_input_shapes_and_svg_files(qtbot, corpus):
    from app import core
    from app.dialogs import ReplaceDialog
    from lsys_core.grammar import Terminal, parse_grammar

    grammar = parse_grammar(
        'lsys 1\nterminal A "M 0 0 L 4 0 L 4 4 Z"\naxiom: P(3)\nP(m): m > 0 -> A f(5) P(m-1)\nP(m): m == 0 -> A\n'
    )
    shapes = (Terminal("G0", "M 0 0 L 1 1", "stroke:#000"),)
    dialog = ReplaceDialog(grammar, shapes, core.shape_from_svg)
    qtbot.addWidget(dialog)
    assert dialog.target.currentData() == ("terminal", "A")
    assert [dialog.source.itemText(i) for i in range(dialog.source.count())] == ["input element group 1"]
    assert dialog.add_shape_from(str(corpus("sequence5.svg")))
    choice = dialog.choice()
    assert choice.kind == "terminal" and choice.target == "A" and choice.path.startswith("M")
    dialog.target.setCurrentIndex(dialog.target.findText("P (non-terminal)"))
    assert [dialog.source.itemText(i) for i in range(dialog.source.count())] == ["terminal A"]
    assert not dialog.load_button.isEnabled()
    assert not dialog.add_shape_from("/nonexistent/shape.svg")
    assert "shape.svg" in dialog.error.text()


def test_a_message_lies_over_the_canvas_without_resizing_it(window, helix_lsys, wait_idle, qtbot):
    _open(window, helix_lsys, wait_idle)
    canvas, bar = window.canvas, window.message_bar
    size, frame = canvas.size(), canvas._frame
    window.show_message("A note long enough to need a line of its own, at least on a narrow canvas.")
    assert bar.isVisible() and bar.text().startswith("A note")
    assert bar.parentWidget() is canvas and bar.geometry().top() == 0
    assert bar.width() == canvas.width() and bar.height() >= bar.sizeHint().height() // 2
    qtbot.wait(50)
    assert canvas.size() == size and canvas._frame is frame and window.is_idle()  # nothing drawn again
    window.resize(window.width() - 200, window.height())
    qtbot.waitUntil(lambda: canvas.width() < size.width(), timeout=5_000)
    assert bar.width() == canvas.width()  # it follows the canvas
    bar.hide()
    assert not bar.text()
