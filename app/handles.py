"""Handles on the canvas: drag a repetition's step, turn and scale; +/− its count.

Click an instance: the rule that repeats it shows handles (computed by
``lsys_core.derive.handles``): the next repetition (drag: step distance and direction), a turn
knob on its heading, a scale knob beside it, for a ring its centre and a radius handle, and
+/− buttons for the count.  A drag is one gesture (one undo step, draft frames while it lasts);
the overlay only draws and reports, the window turns a drag into control values.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QObject, QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QPainter, QPen

from . import core

__all__ = ["HANDLE_PX", "HandleEditor", "HandleOverlay"]

HANDLE_PX = 7.0  # radius of a handle in logical pixels
KNOB_PX = 48.0  # length of the turn and scale knobs in logical pixels
_COLORS = {"move": "#ef6c00", "turn": "#1565c0", "scale": "#2e7d32", "radius": "#6a1b9a"}
_BUTTONS = {"plus": QPointF(22, -22), "minus": QPointF(-22, -22)}  # +/- beside the selection


class HandleOverlay(QObject):
    """The handles of the selected repetition, drawn over the canvas.

    Signals
    -------
    dragStarted(), dragFinished()
        A handle drag begins / ends (the window opens and closes an undo gesture).
    dragged(which, x, y)
        Handle ``which`` is at drawing point ``(x, y)``.
    countStep(step)
        The +/− button was clicked (``+1`` or ``-1``).
    """

    dragStarted = Signal()
    dragFinished = Signal()
    dragged = Signal(str, float, float)
    countStep = Signal(int)

    def __init__(self, canvas: Any) -> None:
        super().__init__(canvas)
        self.canvas = canvas
        self.index: int | None = None
        self.handles: Any = None
        self.grammar: Any = None
        self._drag: str | None = None
        self._frozen: Any = None  # the handles at the start of a drag: the drag maps through them

    # -- state ----------------------------------------------------------------------------------
    def select(self, index: int | None, grammar: Any, drawing: Any) -> None:
        """Show the handles of instance ``index`` (None: no selection)."""
        self.index = index if index is not None and index >= 0 else None
        self.refresh(grammar, drawing)

    def refresh(self, grammar: Any, drawing: Any) -> None:
        """Recompute the handles for the current selection (new rules or drawing)."""
        self.grammar = grammar
        h = None
        if (
            self.index is not None
            and grammar is not None
            and drawing is not None
            and self.index < len(drawing)
        ):
            knob = KNOB_PX / self.canvas.view.zoom
            h = core.find_handles(grammar, drawing, self.index, knob)
        self.handles = h
        self.canvas.update()

    @property
    def dragging(self) -> bool:
        """Whether a handle is being dragged."""
        return self._drag is not None

    def frozen(self) -> Any:
        """Return the handles a running drag maps through (the current ones otherwise)."""
        return self._frozen if self._frozen is not None else self.handles

    # -- hit testing and mouse ----------------------------------------------------------------------
    def _widget(self, z: complex) -> QPointF:
        x, y = self.canvas.view.to_widget(z.real, z.imag)
        return QPointF(x, y)

    def hit(self, pos: QPointF) -> str | None:
        """Return the handle or button under widget point ``pos`` (None: none)."""
        h = self.handles
        if h is None:
            return None
        base = self._widget(h.b0)
        if "count" in h.controls:
            for name, off in _BUTTONS.items():
                if (pos - (base + off)).manhattanLength() <= 2 * HANDLE_PX:
                    return name
        best, best_d = None, 2 * HANDLE_PX
        for name, z in h.points().items():
            d = (pos - self._widget(z)).manhattanLength()
            if d <= best_d:
                best, best_d = name, d
        return best

    def press(self, pos: QPointF) -> bool:
        """Start a drag (or click a button) if ``pos`` is on a handle; return whether it was."""
        which = self.hit(pos)
        if which is None:
            return False
        if which in _BUTTONS:
            self.countStep.emit(1 if which == "plus" else -1)
            return True
        self._drag = which
        self._frozen = self.handles
        self.dragStarted.emit()
        return True

    def move(self, pos: QPointF) -> None:
        """Report the dragged handle's new place."""
        if self._drag is not None:
            x, y = self.canvas.view.to_doc(pos.x(), pos.y())
            self.dragged.emit(self._drag, x, y)

    def release(self, pos: QPointF) -> None:
        """End the drag."""
        if self._drag is not None:
            self.move(pos)
            self._drag = None
            self._frozen = None
            self.dragFinished.emit()

    # -- painting ---------------------------------------------------------------------------------------
    def paint(self, painter: QPainter) -> None:
        """Draw the handles (widget coordinates)."""
        h = self.handles
        if h is None:
            return
        painter.save()
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        base, nxt = self._widget(h.b0), self._widget(h.b1)
        dash = QPen(QColor("#424242"), 1.2, Qt.PenStyle.DashLine)
        painter.setPen(dash)
        painter.drawLine(base, nxt)
        points = h.points()
        for name in ("turn", "scale"):
            if name in points:
                painter.drawLine(nxt, self._widget(points[name]))
        if h.center is not None:
            c = self._widget(h.center)
            painter.drawLine(c + QPointF(-6, 0), c + QPointF(6, 0))
            painter.drawLine(c + QPointF(0, -6), c + QPointF(0, 6))
            painter.drawLine(c, base)
        painter.setPen(QPen(QColor("#ffffff"), 1.5))
        painter.setBrush(QColor("#424242"))
        painter.drawEllipse(base, HANDLE_PX * 0.6, HANDLE_PX * 0.6)
        for name, z in points.items():
            p = self._widget(z)
            painter.setBrush(QColor(_COLORS[name]))
            if name == "scale":
                painter.drawRect(QRectF(p.x() - HANDLE_PX, p.y() - HANDLE_PX, 2 * HANDLE_PX, 2 * HANDLE_PX))
            else:
                painter.drawEllipse(p, HANDLE_PX, HANDLE_PX)
        if "count" in h.controls:
            painter.setBrush(QColor("#fafafa"))
            painter.setPen(QPen(QColor("#424242"), 1.2))
            for name, off in _BUTTONS.items():
                p = base + off
                painter.drawEllipse(p, HANDLE_PX + 2, HANDLE_PX + 2)
                painter.drawLine(p + QPointF(-4, 0), p + QPointF(4, 0))
                if name == "plus":
                    painter.drawLine(p + QPointF(0, -4), p + QPointF(0, 4))
        painter.restore()


class HandleEditor(QObject):
    """Turns handle drags into document edits: one gesture per drag, one step per +/− click.

    Parameters
    ----------
    doc : Document
        The document edited (``set_params``, ``begin_gesture``, ``end_gesture``).
    overlay : HandleOverlay
    control : callable
        ``control(rule, label)`` returns the current semantic control (the rules view's).
    """

    def __init__(self, doc: Any, overlay: HandleOverlay, control: Any) -> None:
        super().__init__(overlay)
        self.doc, self.overlay, self._control = doc, overlay, control
        overlay.dragStarted.connect(doc.begin_gesture)
        overlay.dragFinished.connect(doc.end_gesture)
        overlay.dragged.connect(self._on_dragged)
        overlay.countStep.connect(self._on_count)
        doc.drawingChanged.connect(lambda d: overlay.refresh(doc.grammar, d))

    def _values(self, rule: str, values: dict[str, float]) -> dict[str, float]:
        out: dict[str, float] = {}
        for label, v in values.items():
            control = self._control(rule, label)
            if control is not None:
                out.update(control.values(v))
        return out

    def _on_dragged(self, which: str, x: float, y: float) -> None:
        h = self.overlay.frozen()
        if h is None:
            return
        pixel = 1.0 / self.overlay.canvas.view.zoom  # one logical screen pixel in drawing units
        values = self._values(h.rule, core.handle_values(h, which, complex(x, y), pixel))
        if values:
            what = {"move": "step", "turn": "turn per step", "scale": "scale per step", "radius": "radius"}[
                which
            ]
            self.doc.set_params(values, f"Drag the {what} of {h.rule}", f"handle:{h.rule}:{which}")

    def _on_count(self, step: int) -> None:
        h = self.overlay.handles
        control = self._control(h.rule, "count") if h is not None else None
        if control is None:
            return
        new = max(1.0, control.value + step)
        if new != control.value:
            self.doc.set_params(control.values(new), f"Count of {h.rule} {'+' if step > 0 else '−'}1")
