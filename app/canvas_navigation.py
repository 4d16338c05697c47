"""Moving the canvas's view: fit, 100 %, zoom at a point, pan, and the mouse wheel.

:class:`CanvasNavigation` is mixed into :class:`~app.canvas.Canvas`; each move sets a new
:class:`~app.frames.View` and asks for a frame (a draft while the user keeps moving).
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QPointF

from . import core
from .frames import View

__all__ = ["MAX_ZOOM", "MIN_ZOOM", "CanvasNavigation"]

MIN_ZOOM, MAX_ZOOM = 1e-4, 1e4


class CanvasNavigation:
    """View moves of the canvas (mixed into :class:`~app.canvas.Canvas`)."""

    view: View
    drawing: Any
    _user_moved: bool

    def fit(self, render: bool = True) -> None:
        """Fit the drawing (or its canvas viewbox) into the widget."""
        bounds = self._bounds()
        if bounds is None:
            return
        x0, y0, x1, y1 = bounds
        w, h = max(self.width(), 1), max(self.height(), 1)
        bw, bh = max(x1 - x0, 1e-9), max(y1 - y0, 1e-9)
        zoom = min(max(min((w - 40) / bw, (h - 40) / bh), MIN_ZOOM), MAX_ZOOM)
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
        self.view = View(zoom, w / 2 - cx * zoom, h / 2 - cy * zoom)
        self._user_moved = False
        if render:
            self.request_render()

    def zoom_100(self) -> None:
        """Show the drawing at 100 % (one SVG unit per logical pixel), keeping the centre."""
        self.zoom_at(1.0 / self.view.zoom, QPointF(self.width() / 2, self.height() / 2))

    def zoom_by(self, factor: float) -> None:
        """Zoom around the widget centre."""
        self.zoom_at(factor, QPointF(self.width() / 2, self.height() / 2))

    def zoom_at(self, factor: float, pos: QPointF) -> None:
        """Zoom by ``factor`` keeping the document point under ``pos`` fixed."""
        v = self.view
        zoom = min(max(v.zoom * factor, MIN_ZOOM), MAX_ZOOM)
        f = zoom / v.zoom
        self.view = View(zoom, pos.x() - (pos.x() - v.ox) * f, pos.y() - (pos.y() - v.oy) * f)
        self._user_moved = True
        self._interact()

    def pan_by(self, dx: float, dy: float) -> None:
        """Move the view by ``(dx, dy)`` logical pixels."""
        self.view = View(self.view.zoom, self.view.ox + dx, self.view.oy + dy)
        self._user_moved = True
        self._interact()

    def wheelEvent(self, event) -> None:
        """Zoom at the cursor."""
        steps = event.angleDelta().y() / 120.0
        if steps:
            self.zoom_at(1.2**steps, event.position())
        event.accept()

    def _bounds(self) -> tuple[float, float, float, float] | None:
        d = self.drawing
        if d is None:
            return None
        bounds = core.drawing_bounds(d) if len(d) else None
        if bounds is None and d.viewbox is not None:
            x, y, w, h = d.viewbox
            return x, y, x + w, y + h
        return bounds
