"""Handles on the canvas: select an instance, drag its repetition's step, turn, scale; +/− count."""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
from PySide6.QtGui import QMouseEvent
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication

HELIX = """lsys 1
terminal A "M 0 0 L 8 0 L 8 3 Z" style "fill:#2a6"
axiom: +(20) f(300) +(-20) P(40)
P(m): m > 0 -> A +(-80) f(-24) *(0.99) +(91) P(m-1)
P(m): m == 0 -> A
"""


@pytest.fixture
def helix(open_rules):
    window = open_rules(HELIX)
    window.canvas.elementClicked.emit(5)
    assert window.handles.handles is not None
    return window


def _widget_point(window, z: complex) -> QPoint:
    x, y = window.canvas.view.to_widget(z.real, z.imag)
    return QPoint(round(x), round(y))


def _move_pressed(canvas, p: QPoint) -> None:
    """Move the mouse, its left button held, to ``p`` on ``canvas``."""
    event = QMouseEvent(
        QEvent.Type.MouseMove,
        QPointF(p),
        QPointF(canvas.mapToGlobal(p)),
        Qt.MouseButton.NoButton,
        Qt.MouseButton.LeftButton,
        Qt.KeyboardModifier.NoModifier,
    )
    QApplication.sendEvent(canvas, event)


def _drag(window, start: QPoint, path: list[QPoint]) -> None:
    """Press on ``start``, move the pressed mouse along ``path``, release at its end."""
    canvas = window.canvas
    QTest.mousePress(canvas, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, start)
    for p in path:
        _move_pressed(canvas, p)
    QTest.mouseRelease(canvas, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, path[-1])


def test_selecting_an_instance_shows_the_handles_of_its_repetition(helix):
    h = helix.handles.handles
    d = helix.doc.drawing
    assert h.rule == "P" and h.b0 == pytest.approx(d.b[5]) and h.b1 == pytest.approx(d.b[6])
    assert set(h.points()) == {"move", "turn", "scale"}
    assert helix.handles.hit(QPointF(_widget_point(helix, h.b1))) == "move"


def test_dragging_the_next_repetition_changes_the_step_in_one_undo_step(helix, wait_idle):
    doc = helix.doc
    before = doc.text
    h = helix.handles.handles
    start = _widget_point(helix, h.b1)
    path = [start + QPoint(dx, dx // 2) for dx in (4, 9, 15, 20)]
    _drag(helix, start, path)
    wait_idle(helix)
    assert doc.undo_stack.count() == 1 and doc.undo_stack.undoText().startswith("Drag the step of P")
    x, y = helix.canvas.view.to_doc(path[-1].x(), path[-1].y())
    d = doc.drawing  # the step from 5 to 6, in 5's frame, goes where it was dropped (within a pixel:
    pixel = 1.0 / helix.canvas.view.zoom  # the values are snapped to what the screen can tell)
    assert abs((d.b[6] - d.b[5]) - (complex(x, y) - h.b0) * d.a[5] / h.a0) <= pixel
    turn = doc.drawing.a[6] / doc.drawing.a[5]
    assert math.degrees(cmath.phase(turn)) == pytest.approx(11.0)  # the turn per step stays
    assert "+(-80) f(-24)" not in doc.text
    doc.undo_stack.undo()
    wait_idle(helix)
    assert doc.text == before


def test_the_turn_knob_sets_the_turn_per_step(helix, wait_idle):
    doc = helix.doc
    h = helix.handles.handles
    start = _widget_point(helix, h.points()["turn"])
    b1 = _widget_point(helix, h.b1)
    target = b1 + QPoint(0, 48)  # straight down on screen: +90° in SVG coordinates
    _drag(helix, start, [target])
    wait_idle(helix)
    d = doc.drawing  # the turn from 5 to 6 now points 6 at the knob, seen from 5's frame
    turn = math.degrees(cmath.phase(d.a[6] / d.a[5]))
    expected = math.remainder(90.0 - math.degrees(cmath.phase(h.a0)), 360.0)
    assert turn == pytest.approx(expected, abs=2.0)
    assert doc.undo_stack.count() == 1


def test_plus_and_minus_change_the_count_by_one(helix, qtbot, wait_idle):
    doc = helix.doc
    base = _widget_point(helix, helix.handles.handles.b0)
    n = len(doc.drawing)
    QTest.mouseClick(
        helix.canvas, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, base + QPoint(22, -22)
    )
    wait_idle(helix)
    assert len(doc.drawing) == n + 1 and "P(41)" in doc.text and doc.undo_stack.count() == 1
    base = _widget_point(helix, helix.handles.handles.b0)
    QTest.mouseClick(
        helix.canvas, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, base + QPoint(-22, -22)
    )
    wait_idle(helix)
    assert len(doc.drawing) == n and doc.undo_stack.count() == 2


def test_a_drag_shows_drafts_of_the_new_step_and_the_text_follows_paced(helix, qtbot, wait_idle):
    """While the pointer moves, the canvas shows draft frames of the moved instances at their new
    places; the rules text and panels follow at most every GESTURE_FOLLOW_MS and at once on the
    release, which renders at full quality; the whole drag is one undo step."""
    from app.pacing import GESTURE_FOLLOW_MS

    doc, canvas = helix.doc, helix.canvas
    before = doc.text
    h = helix.handles.handles
    start = _widget_point(helix, h.b1)
    QTest.mousePress(canvas, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, start)
    helix.pacing._timer.setInterval(60_000)  # no paced update during this test: only the release's
    for dx in (6, 12, 18):
        p = start + QPoint(dx, 0)
        _move_pressed(canvas, p)
        qtbot.waitUntil(
            lambda: not doc.busy and canvas._frame is not None and canvas._frame.drawing is doc.drawing,
            timeout=10_000,
        )
        frame = canvas._frame
        assert frame.draft  # drag speed
        x, y = canvas.view.to_doc(p.x(), p.y())
        pixel = 1.0 / canvas.view.zoom
        d = frame.drawing  # the step from 5 to 6 (in 5's frame) goes where the pointer is
        assert abs((d.b[6] - d.b[5]) - (complex(x, y) - h.b0) * d.a[5] / h.a0) <= pixel
        assert doc.text != before and helix.rules_panel.text() == before  # the text waits (paced)
        assert helix.pacing.pending and not helix.is_idle()
    QTest.mouseRelease(canvas, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, p)
    wait_idle(helix)
    assert not canvas._frame.draft and canvas._frame.drawing is doc.drawing  # full quality on release
    assert helix.rules_panel.text() == doc.text != before and not helix.pacing.pending
    assert doc.undo_stack.count() == 1
    assert GESTURE_FOLLOW_MS > 0


def test_moves_faster_than_frames_still_show_frames(helix, qtbot, wait_idle):
    """A move that comes while the previous one is still derived does not cancel it: its
    drawing is shown, then the newest one (a fast drag keeps showing frames)."""
    doc, canvas = helix.doc, helix.canvas
    drawings = []
    doc.rules.deriver.resultReady.connect(drawings.append)
    h = helix.handles.handles
    start = _widget_point(helix, h.b1)
    QTest.mousePress(canvas, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, start)
    for dx in (6, 12):  # back to back: the first derivation is still running at the second move
        p = start + QPoint(dx, 0)
        _move_pressed(canvas, p)
    assert doc.rules.deriver.running
    qtbot.waitUntil(lambda: not doc.rules.deriver.busy, timeout=60_000)
    QTest.mouseRelease(canvas, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, p)
    wait_idle(helix)
    assert len(drawings) == 2 and drawings[-1] is doc.drawing
    assert not np.allclose(drawings[0].b, drawings[1].b)
    assert doc.undo_stack.count() == 1
