"""The structure panel: hierarchy with selection sync, colour legend, terminal palette and colours."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtGui import QColor
from PySide6.QtWidgets import QColorDialog

from app.resources import examples


@pytest.fixture
def facade(window, wait_idle):
    path = next(p for p in examples() if p.name == "facade.svg").with_suffix(".lsys")
    window.open_path(str(path))
    wait_idle(window)
    return window


def _items(panel, name):
    return panel._items[name]


def test_the_tree_goes_from_the_start_through_the_rules_to_the_shapes(facade):
    panel = facade.structure_panel
    top = panel.tree.topLevelItem(0)
    assert top.text(0) == "Start (axiom)" and top.text(2) == "72"
    assert _items(panel, "P2")[0].parent() is _items(panel, "Z")[0]
    assert (
        _items(panel, "P2")[0].text(1).startswith("row of 5 × P1") and _items(panel, "P2")[0].text(2) == "70"
    )
    leaves = [_items(panel, "X1")[0].child(i) for i in range(_items(panel, "X1")[0].childCount())]
    assert {leaf.text(0) for leaf in leaves} == {"C", "D"} and all(
        not leaf.icon(0).isNull() for leaf in leaves
    )


def test_selecting_a_rule_selects_its_instances_and_a_click_selects_the_rule(facade):
    panel, canvas = facade.structure_panel, facade.canvas
    _items(panel, "P1")[0].setSelected(True)
    assert canvas._highlight is not None and int(canvas._highlight.sum()) == 70  # P1's rows of X1 pairs
    assert facade.rules_view._selected == "P1"
    d = facade.doc.drawing
    door = int(np.flatnonzero(d.symbol == [t.name for t in d.terminals].index("B"))[0])
    canvas.elementClicked.emit(door)
    assert panel.selected_rule() == "Z" and canvas._highlight.sum() == 72


def test_legend_follows_the_colour_mode(facade):
    panel = facade.structure_panel
    facade.act_colors["rule"].trigger()
    assert panel.legend.count() == len(facade.doc.grammar.rules) + 1 and panel.legend.isVisibleTo(panel)
    assert panel.legend.item(0).text() == "Start (axiom)"
    facade.act_colors["group"].trigger()
    assert [panel.legend.item(i).text() for i in range(panel.legend.count())] == [
        f"terminal {t.name}" for t in facade.doc.grammar.terminals
    ]
    facade.act_colors["none"].trigger()
    assert not panel.legend.isVisibleTo(panel) and panel.legend_note.isVisibleTo(panel)


def test_palette_selects_instances_and_edits_colours_one_step_each(facade, monkeypatch, wait_idle):
    panel, doc = facade.structure_panel, facade.doc
    item = next(
        panel.palette.item(i) for i in range(panel.palette.count()) if panel.palette.item(i).text() == "C"
    )
    assert not item.icon().isNull()
    item.setSelected(True)
    symbol = [t.name for t in doc.grammar.terminals].index("C")
    assert np.array_equal(facade.canvas._highlight, doc.drawing.symbol == symbol)
    monkeypatch.setattr(QColorDialog, "getColor", staticmethod(lambda *a, **k: QColor("#ff0000")))
    panel.fill_button.click()
    wait_idle(facade)
    assert "fill:#ff0000" in doc.grammar.terminal("C").style and doc.undo_stack.count() == 1
    panel.opacity.setValue(0.5)
    wait_idle(facade)
    assert "opacity:0.5" in doc.grammar.terminal("C").style and doc.undo_stack.count() == 2
    doc.undo_stack.undo()
    doc.undo_stack.undo()
    wait_idle(facade)
    assert "ff0000" not in doc.text


def test_replace_from_the_palette_opens_replace_symbol_for_that_terminal(facade, monkeypatch):
    from app import dialogs

    seen = []

    def fake_exec(self):
        seen.append(self.target.currentData())
        seen.append(self.source.count() > 0 and not self.source.itemIcon(0).isNull())
        return 0

    monkeypatch.setattr(dialogs.ReplaceDialog, "exec", fake_exec)
    panel = facade.structure_panel
    next(
        panel.palette.item(i) for i in range(panel.palette.count()) if panel.palette.item(i).text() == "D"
    ).setSelected(True)
    panel.replace_button.click()
    assert seen == [("terminal", "D"), True]


def test_a_hidden_panel_catches_up_when_it_shows(facade, wait_idle):
    panel = facade.structure_panel
    facade.structure_dock.hide()
    facade.doc.edit_text(facade.doc.text.replace("P2", "Q2"))
    wait_idle(facade)
    assert "Q2" in {r.name for r in facade.doc.grammar.rules}
    assert "Q2" not in panel._items  # not rebuilt while nobody sees it
    facade.structure_dock.show()
    assert "Q2" in panel._items and "P2" not in panel._items
    assert panel.tree.topLevelItem(0).text(2) == "72"


def test_a_new_tree_is_built_a_few_items_per_turn_and_an_interrupted_one_again(open_rules, many_rules):
    from app.structure_panel import ITEMS_PER_STEP

    window = open_rules(many_rules(80))
    panel = window.structure_panel
    assert panel.isVisible()
    grammar, cards, drawing = window.doc.grammar, panel._cards, window.doc.drawing
    top = panel.tree.topLevelItem(0)
    assert top.childCount() == 80 and set(panel._items) == {c.owner for c in cards}
    panel._tree_key = ()  # as if the rules had a new structure
    steps = panel.content_steps(grammar, cards, drawing)
    next(steps)  # a part of the tree, in a turn of its own
    assert 0 < panel.tree.topLevelItem(0).childCount() < 80
    steps.close()  # newer rules came
    assert panel._tree_key == () and not panel._updating
    turns = sum(1 for _ in panel.content_steps(grammar, cards, drawing))
    assert turns >= 2 * 80 // ITEMS_PER_STEP  # 80 rules and their shapes, in several turns
    top = panel.tree.topLevelItem(0)
    assert top.text(0) == "Start (axiom)" and top.childCount() == 80
    assert sorted(top.child(i).text(0) for i in range(80)) == sorted(f"P{i}" for i in range(80))
    assert all(top.child(i).child(0).text(0) == "A" for i in range(80))
    assert panel._tree_key and set(panel._items) == {c.owner for c in cards}
