"""The parameters panel builds only the rows it shows, and reuses them for the next grammar."""

from __future__ import annotations

import pytest
from PySide6.QtWidgets import QSlider

from app.params_panel import OPEN_ROWS, ROWS_PER_PAGE, ParamsPanel
from lsys_core.grammar import list_params, parse_grammar


def many(rules: int, shift: int = 0):
    lines = ["lsys 1", 'terminal A "M 0 0 L 4 0 L 4 4 Z"']
    lines.append("axiom: " + " ".join(f"[ f({i + shift}) P{i}(3) ]" for i in range(rules)))
    for i in range(rules):
        lines.append(f"P{i}(m): m > 0 -> A +({i % 7 + 1}) f(10) *(0.99) +(-{i % 7 + 1}) P{i}(m-1)")
        lines.append(f"P{i}(m): m == 0 -> A")
    return list_params(parse_grammar("\n".join(lines) + "\n"))


def test_a_grammar_of_hundreds_of_parameters_builds_a_few_dozen_rows(qtbot):
    panel = ParamsPanel()
    qtbot.addWidget(panel)
    params = many(120)
    assert len(params) >= 600
    panel.set_params(params)
    sliders = panel.findChildren(QSlider)
    assert len(sliders) <= OPEN_ROWS + ROWS_PER_PAGE
    assert set(panel.rows) <= {p.key for p in params} and len(panel.rows) >= 4
    axiom = next(s for s in panel._sections if s.header.text().startswith("axiom"))
    assert axiom.more.isVisibleTo(panel)  # the axiom's 240 numbers come a page at a time
    axiom.more.click()
    assert sum(k.startswith("axiom.") for k in panel.rows) == 2 * ROWS_PER_PAGE
    closed = next(s for s in panel._sections if not s.header.isChecked())
    closed.header.click()  # opening a section builds its rows, with the current values
    key = closed.params[0].key
    assert panel.rows[key].value() == pytest.approx(closed.params[0].value)


def test_rows_are_reused_for_the_next_grammar_and_edits_are_forwarded(qtbot):
    panel = ParamsPanel()
    qtbot.addWidget(panel)
    panel.set_params(many(30))
    first = set(map(id, panel.findChildren(QSlider)))
    panel.set_params(many(29, shift=5))  # another set of keys
    assert set(map(id, panel.findChildren(QSlider))) == first  # no new widgets
    edits = []
    panel.paramEdited.connect(lambda k, v: edits.append((k, v)))
    row = panel.rows["axiom.0.1.v"]
    row.spin.setValue(12.5)
    assert edits == [("axiom.0.1.v", 12.5)]


def test_sections_are_configured_a_few_per_turn_and_an_interrupted_run_is_redone(qtbot):
    from app.params_panel import SECTIONS_PER_STEP

    panel = ParamsPanel()
    qtbot.addWidget(panel)
    old, new = many(120), many(120, shift=5)
    steps = panel.param_steps(old)
    next(steps)  # the first turn configures one batch of sections only
    configured = [s for s in panel._sections if not s.isHidden()]
    assert len(configured) == SECTIONS_PER_STEP < 121
    panel.set_params(new)  # a newer grammar before the run ended: everything again, new values
    assert sum(not s.isHidden() for s in panel._sections) == 121
    first = next(iter(panel.rows))
    assert panel.rows[first].value() == pytest.approx(panel.current(new[0]).value)
    assert panel.current(new[0]).value == new[0].value
