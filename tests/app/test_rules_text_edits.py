"""The rules text replaces only the lines that changed, so the others keep layout and colours."""

from __future__ import annotations

import random

import pytest

from app import highlighter, rules_panel
from app.rules_panel import RulesEditor


def revisions(editor: RulesEditor) -> list[int]:
    doc = editor.document()
    return [doc.findBlockByNumber(i).revision() for i in range(doc.blockCount())]


def test_a_changed_number_touches_only_its_line(qtbot):
    editor = RulesEditor()
    qtbot.addWidget(editor)
    lines = ["lsys 1", 'terminal A "M 0 0 L 4 0 Z"', "axiom: P(3)"]
    lines += [f"P{i}(m): m > 0 -> A f({i}) P{i}(m-1)" for i in range(50)]
    editor.replace_text("\n".join(lines))
    before = revisions(editor)
    lines[20] = lines[20].replace("f(17)", "f(17.5)")
    editor.replace_text("\n".join(lines))
    after = revisions(editor)
    assert editor.toPlainText() == "\n".join(lines)
    changed = [i for i, (a, b) in enumerate(zip(before, after, strict=True)) if a != b]
    assert changed == [20]


@pytest.mark.parametrize("diff_lines", [rules_panel._DIFF_LINES, 0])
def test_any_sequence_of_texts_is_shown_exactly(qtbot, monkeypatch, diff_lines):
    monkeypatch.setattr(rules_panel, "_DIFF_LINES", diff_lines)  # 0: one span, as for long texts
    editor = RulesEditor()
    qtbot.addWidget(editor)
    rnd = random.Random(7)
    words = ["a", "bb", "", "ccc x", "é", "\U0001f600 z", "P(m) -> A"]
    text = ""
    for _ in range(400):
        lines = (
            [rnd.choice(words) for _ in range(rnd.randint(0, 9))] if rnd.random() < 0.2 else text.split("\n")
        )
        for _ in range(rnd.randint(0, 3)):
            op = rnd.random()
            if op < 0.3 and lines:
                del lines[rnd.randrange(len(lines))]
            elif op < 0.6:
                lines.insert(rnd.randint(0, len(lines)), rnd.choice(words))
            elif lines:
                lines[rnd.randrange(len(lines))] = rnd.choice(words)
        text = "\n".join(lines)
        editor.replace_text(text)
        assert editor.toPlainText() == text


def test_a_long_line_is_coloured_at_its_head_and_its_tail_stays_plain(qtbot):
    editor = RulesEditor()
    qtbot.addWidget(editor)
    axiom = "axiom: " + " ".join(f"[ f({i}) P{i}(3) ]" for i in range(200))
    editor.replace_text(f"lsys 1\n{axiom}\n")
    qtbot.waitUntil(lambda: not editor.highlighter.pending, timeout=10_000)
    ranges = editor.document().findBlockByNumber(1).layout().formats()
    assert ranges, "the head of the line is coloured"
    assert max(r.start + r.length for r in ranges) <= highlighter._TOKEN_COLOURS < len(axiom)


def test_changes_at_both_ends_colour_only_the_changed_lines(qtbot, monkeypatch):
    coloured: list[str] = []
    real = highlighter.LsysHighlighter.highlightBlock
    monkeypatch.setattr(
        highlighter.LsysHighlighter,
        "highlightBlock",
        lambda self, text: coloured.append(text) or real(self, text),
    )
    editor = RulesEditor()
    qtbot.addWidget(editor)
    lines = ["lsys 1", "axiom: P0(3)"] + [f"P{i}(m): m > 0 -> A f({i}) P{i}(m-1)" for i in range(30)]
    editor.replace_text("\n".join(lines))
    qtbot.waitUntil(lambda: not editor.highlighter.pending, timeout=10_000)
    assert len(coloured) >= len(lines)  # the first text: every line
    coloured.clear()
    lines[1], lines[-1] = "axiom: P1(4)", "P29(m): m > 0 -> A f(2.9) P29(m-1)"
    editor.replace_text("\n".join(lines))
    assert editor.toPlainText() == "\n".join(lines)
    assert {lines[1], lines[-1]} <= set(coloured) <= {lines[1], lines[2], lines[-1]}  # not the 28 between
