"""The rules text and panels follow new rules in their own event-loop turns; input never edits old text."""

from __future__ import annotations

from PySide6.QtCore import QEvent, Qt
from PySide6.QtGui import QKeyEvent
from PySide6.QtWidgets import QApplication

from app import core

RULES = """lsys 1
terminal A "M 0 0 L 8 0 L 8 3 Z" style "fill:#2a6"
axiom: P(10)
P(m): m > 0 -> A f(12) +(5) P(m-1)
P(m): m == 0 -> A
"""


def test_new_rules_show_in_the_text_in_the_next_turn(open_rules, qtbot, wait_idle):
    window = open_rules(RULES)
    doc = window.doc
    grammar = core.set_params(doc.grammar, {"P.0.1.v": 13.0})
    assert doc.apply_grammar(grammar, "test")
    assert "f(13)" in doc.text and "f(12)" in window.rules_panel.text()  # not in the applying turn
    assert window.pacing.pending and not window.is_idle()
    wait_idle(window)
    assert window.rules_panel.text() == doc.text and not window.pacing.pending


def test_a_key_pressed_before_the_text_follows_edits_the_new_text(open_rules, wait_idle):
    """A key already queued when new rules arrive goes to the new text, not to the old one."""
    window = open_rules(RULES)
    doc = window.doc
    editor = window.rules_panel.editor
    editor.setFocus()
    doc.apply_grammar(core.set_params(doc.grammar, {"P.0.1.v": 13.0}), "test")
    cursor = editor.textCursor()
    cursor.movePosition(cursor.MoveOperation.End)
    editor.setTextCursor(cursor)
    for key, text in ((Qt.Key.Key_NumberSign, "#"), (Qt.Key.Key_X, "x")):
        QApplication.sendEvent(
            editor, QKeyEvent(QEvent.Type.KeyPress, key, Qt.KeyboardModifier.NoModifier, text)
        )
    assert "f(13)" in window.rules_panel.text() and window.rules_panel.text().rstrip().endswith("#x")
    wait_idle(window)
    assert "f(13)" in doc.text and doc.text.rstrip().endswith("#x")  # the typing kept the new rules
    assert doc.undo_stack.count() == 2


def test_the_text_waits_for_the_derivation_of_the_new_rules(open_rules, wait_idle, monkeypatch):
    """Outside gestures the text and panels follow once the new rules are derived (they then do
    not share the GIL with the derivation)."""
    import app.pacing

    monkeypatch.setattr(app.pacing, "FOLLOW_WAIT_MS", 600_000)  # only the derivation's end counts
    window = open_rules(RULES)
    doc = window.doc
    seen = []
    show = window.pacing._show_text
    window.pacing._show_text = lambda text: (seen.append(doc.rules.deriver.busy), show(text))
    doc.apply_grammar(core.set_params(doc.grammar, {"P.0.1.v": 13.0}), "test")
    wait_idle(window)
    assert seen == [False] and window.rules_panel.text() == doc.text
