"""File → Open Example lists the bundled gallery and opens it."""

from __future__ import annotations

from app.resources import examples, icon_path


def test_examples_and_icon_are_found() -> None:
    names = {p.stem for p in examples()}
    assert {"helix", "branching-plant"} <= names
    assert icon_path() is not None


def test_open_example_menu_opens_a_file(window, qtbot) -> None:
    actions = window.examples_menu.actions()
    assert len(actions) == len(examples()) >= 6
    helix = next(a for a in actions if a.toolTip().endswith("helix.svg"))
    helix.trigger()
    qtbot.waitUntil(
        lambda: window.doc.drawing is not None and len(window.doc.drawing) == 120, timeout=120_000
    )
