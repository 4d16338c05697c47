"""The canvas: the derived drawing rendered by ``lsys_core.render.raster`` into a zero-copy QImage.

Rendering runs on a worker (:class:`~app.workers.LatestRunner`): a request snapshots the
drawing, the view (zoom, offset, device pixel ratio, size) and the quality; the worker draws
with skia into one of two :class:`~lsys_core.render.raster.Renderer` surfaces (double buffering: the
one on screen is never drawn into) and wraps the pixels as a QImage without copying; the UI
thread only calls ``QPainter.drawImage``.  While the user drags a slider, pans or zooms, drafts
are rendered (and the last frame is shown transformed to the new view until the next one
arrives); full anti-aliased quality follows as soon as the interaction stops.

Also: pan (drag, space-drag, middle button), zoom at the cursor (wheel), fit / 100 %, an
optional overlay of the input SVG, colouring by similarity group or by rule, and picking the
element under a click.  The frame itself is made in :mod:`app.frames`, the colouring in
:mod:`app.coloring`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np
from PySide6.QtCore import QPointF, QRectF, QSize, Qt, QTimer, Signal
from PySide6.QtGui import QColor, QPainter, QTransform
from PySide6.QtWidgets import QSizePolicy, QWidget

from . import core
from .canvas_navigation import CanvasNavigation
from .coloring import group_color, legend, recolor, rule_color
from .frames import Frame, RenderRequest, View, render_frame
from .workers import LatestRunner

__all__ = ["Canvas", "Frame", "RenderRequest", "View", "group_color", "legend", "recolor", "rule_color"]

SETTLE_MS = 120  # quiet time after pan/zoom before rendering at full quality


class Canvas(CanvasNavigation, QWidget):
    """The central view of the derived drawing.

    Signals
    -------
    elementClicked(index)
        Instance index under a click (-1: none).
    message(text)
        A rendering error for the user.
    """

    elementClicked = Signal(int)
    message = Signal(str)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setMouseTracking(False)
        self.setAttribute(Qt.WidgetAttribute.WA_OpaquePaintEvent)
        self.drawing: Any = None
        self.view = View()
        self.color_mode = "none"
        self.overlay_visible = False
        self._overlay: Any = None
        self._overlay_path: str | None = None
        self._overlay_rect: QRectF | None = None
        self._frame: Frame | None = None
        self._renderers: dict[int, Any] = {}
        self._fit_pending = True
        self._user_moved = False
        self._centers: np.ndarray | None = None
        self._drag_start: QPointF | None = None
        self._drag_view: View | None = None
        self._press_pos: QPointF | None = None
        self._space = False
        self._interacting = False
        self._interactive_source: Callable[[], bool] = lambda: False
        self.last_frame_seconds = 0.0
        self._highlight: np.ndarray | None = None
        self._highlight_rule: int | None = None
        self._highlight_terminal: int | None = None
        #: Draws over the frame and may take mouse presses first (the handles).
        self.overlay: Any = None
        self._overlay_drag = False
        self.runner = LatestRunner(
            render_frame,
            name="lsys-render",
            prepare=self._assign_surface,
            finish_running=lambda req: req.draft and self._draft_now(),  # drafts keep coming in a drag
            parent=self,
        )
        self.runner.resultReady.connect(self._on_frame)
        self.runner.failed.connect(self._on_render_failed)
        self._settle = QTimer(self)
        self._settle.setSingleShot(True)
        self._settle.setInterval(SETTLE_MS)
        self._settle.timeout.connect(self._end_interaction)

    # -- public API ------------------------------------------------------------------------------------
    def sizeHint(self) -> QSize:
        """Prefer a roomy canvas."""
        return QSize(800, 600)

    def set_interactive_source(self, fn: Callable[[], bool]) -> None:
        """Tell the canvas how to know a slider drag is in progress (renders drafts then)."""
        self._interactive_source = fn

    def set_drawing(self, drawing: Any) -> None:
        """Show a new drawing (fits the view the first time after a file was opened)."""
        self.drawing = drawing
        self._centers = None
        self._update_highlight()
        if self._fit_pending and drawing is not None and len(drawing):
            self._fit_pending = False
            self.fit(render=False)
        self.request_render()

    def set_highlight_rule(self, rule: Any) -> None:
        """Draw the instances emitted by rule index ``rule`` (-1: the axiom; a list: several) highlighted."""
        self._highlight_rule = rule
        self._highlight_terminal = None
        self._update_highlight()
        self.request_render()

    def set_highlight_terminal(self, symbol: int | None) -> None:
        """Draw the instances of terminal index ``symbol`` in the highlight colour (None: none)."""
        self._highlight_terminal = symbol
        self._highlight_rule = None
        self._update_highlight()
        self.request_render()

    def _update_highlight(self) -> None:
        d, r, t = self.drawing, self._highlight_rule, self._highlight_terminal
        if d is None or len(d) == 0 or (r is None and t is None):
            self._highlight = None
        else:
            rules = np.asarray(d.rule)
            if r is None:
                self._highlight = d.base_symbol() == t
            else:
                self._highlight = np.isin(rules, r) if isinstance(r, (list, tuple, set)) else rules == r

    def fit_on_next_drawing(self) -> None:
        """Fit the view to the next drawing shown (a new file)."""
        self._fit_pending = True

    def set_color_mode(self, mode: str) -> None:
        """Colour elements by ``"group"``, ``"rule"`` or not at all (``"none"``)."""
        self.color_mode = mode
        self.request_render()

    def set_overlay_svg(self, path: str | None) -> None:
        """Use the SVG file ``path`` as the comparison overlay (None: no overlay)."""
        self._overlay_path = path
        self._overlay, self._overlay_rect = None, None
        if self.overlay_visible:
            self._load_overlay()
            self.request_render()

    def set_overlay_visible(self, visible: bool) -> None:
        """Show or hide the translucent input overlay (the SVG is read the first time)."""
        self.overlay_visible = bool(visible)
        if self.overlay_visible and self._overlay is None:
            self._load_overlay()
        self.request_render()

    def _load_overlay(self) -> None:
        from PySide6.QtSvg import QSvgRenderer

        if self._overlay_path:
            renderer = QSvgRenderer(self._overlay_path)
            renderer.setAnimationEnabled(False)  # a static picture: no timer touching it while a worker draws
            if renderer.isValid():
                self._overlay = renderer
                self._overlay_rect = QRectF(renderer.viewBoxF())

    def is_idle(self) -> bool:
        """Whether the frame on screen is the final one for the current drawing and view."""
        if self.runner.busy:
            return False
        if self.drawing is None:
            return True
        f = self._frame
        dpr = float(self.devicePixelRatioF())
        size = (max(1, round(self.width() * dpr)), max(1, round(self.height() * dpr)))
        return (
            f is not None
            and not f.draft
            and f.drawing is self.drawing
            and f.color_mode == self.color_mode
            and f.view == self.view
            and f.size == size
            and f.overlay == (self.overlay_visible and self._overlay is not None)
        )

    def shutdown(self) -> None:
        """Stop the render worker."""
        self._settle.stop()
        self.runner.shutdown()

    def pick(self, pos: QPointF, radius: float = 12.0) -> int:
        """Return the instance nearest to the widget point ``pos`` within ``radius`` pixels, or -1."""
        d = self.drawing
        if d is None or len(d) == 0:
            return -1
        if self._centers is None:
            self._centers = core.instance_centers(d)
        x, y = self.view.to_doc(pos.x(), pos.y())
        dist = np.abs(self._centers - complex(x, y))
        i = int(np.argmin(dist))
        return (
            i if dist[i] * self.view.zoom <= max(radius, core.instance_radius(d, i) * self.view.zoom) else -1
        )

    # -- rendering -----------------------------------------------------------------------------------
    def _draft_now(self) -> bool:
        return self._interacting or self._interactive_source()

    def request_render(self, *, draft: bool | None = None) -> None:
        """Ask for a frame of the current drawing and view (a draft while interacting)."""
        if draft is None:
            draft = self._draft_now()
        if self.drawing is None or self.width() <= 0 or self.height() <= 0:
            self.runner.cancel()
            self.update()
            return
        dpr = float(self.devicePixelRatioF())
        w, h = max(1, round(self.width() * dpr)), max(1, round(self.height() * dpr))
        overlay = self._overlay if self.overlay_visible else None
        self.runner.submit(
            RenderRequest(
                self.drawing,
                self.color_mode,
                self.view,
                w,
                h,
                dpr,
                draft,
                self._highlight,
                overlay,
                self._overlay_rect,
            )
        )
        self.update()

    def _assign_surface(self, req: RenderRequest) -> RenderRequest:
        """Give a starting job the surface that is not on screen (double buffering)."""
        slot = 1 - self._frame.slot if self._frame is not None else 0
        renderer = self._renderers.get(slot)
        if renderer is None:
            renderer = self._renderers[slot] = core.make_renderer(req.width, req.height)
        elif renderer.size != (req.width, req.height):
            renderer.resize(req.width, req.height)
        return dataclasses.replace(req, renderer=renderer, slot=slot)

    def request_full_quality(self) -> None:
        """Render at full quality now (a gesture ended)."""
        self._settle.stop()
        self._interacting = False
        self.request_render(draft=False)

    def _interact(self) -> None:
        self._interacting = True
        self._settle.start()
        self.request_render(draft=True)

    def _end_interaction(self) -> None:
        self._interacting = False
        if self._interactive_source():
            return  # the gesture's end triggers the full-quality frame
        self.request_render(draft=False)

    def _on_frame(self, frame: Frame) -> None:
        self._frame = frame
        self.last_frame_seconds = frame.seconds
        self.update()
        if frame.draft and not self._interacting and not self._interactive_source():
            self.request_render(draft=False)  # the interaction is over: the final frame is full quality

    def _on_render_failed(self, message: str) -> None:
        self.message.emit(f"Rendering failed: {message}")

    # -- Qt events ------------------------------------------------------------------------------------
    def paintEvent(self, event) -> None:
        """Draw the last frame (transformed to the current view if it is older) and the selection."""
        painter = QPainter(self)
        painter.fillRect(self.rect(), QColor("#ffffff"))
        f = self._frame
        if f is not None:
            if f.view == self.view:
                painter.drawImage(QPointF(0, 0), f.image)
            else:
                s = self.view.zoom / f.view.zoom
                painter.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, False)
                painter.setTransform(
                    QTransform(s, 0, 0, s, self.view.ox - f.view.ox * s, self.view.oy - f.view.oy * s)
                )
                painter.drawImage(QPointF(0, 0), f.image)
        if self.overlay is not None:
            painter.resetTransform()
            self.overlay.paint(painter)
        painter.end()

    def resizeEvent(self, event) -> None:
        """Re-render for the new size (re-fitting if the user has not moved the view)."""
        super().resizeEvent(event)
        if not self._user_moved and self.drawing is not None:
            self.fit(render=False)
        self._interact()

    def event(self, event) -> bool:
        """Render again when the screen's device pixel ratio changes (HiDPI)."""
        if event.type() == event.Type.DevicePixelRatioChange:
            self.request_render()
        return super().event(event)

    def keyPressEvent(self, event) -> None:
        """Space held: drag pans."""
        if event.key() == Qt.Key.Key_Space and not event.isAutoRepeat():
            self._space = True
            self.setCursor(Qt.CursorShape.OpenHandCursor)
        else:
            super().keyPressEvent(event)

    def keyReleaseEvent(self, event) -> None:
        """Space released."""
        if event.key() == Qt.Key.Key_Space and not event.isAutoRepeat():
            self._space = False
            self.unsetCursor()
        else:
            super().keyReleaseEvent(event)

    def mousePressEvent(self, event) -> None:
        """Start a handle drag, a pan (any drag) or a click."""
        if (
            self.overlay is not None
            and event.button() == Qt.MouseButton.LeftButton
            and not self._space
            and self.overlay.press(event.position())
        ):
            self._overlay_drag = True
            return
        self._press_pos = event.position()
        self._drag_start = event.position()
        self._drag_view = self.view
        if self._space or event.button() == Qt.MouseButton.MiddleButton:
            self.setCursor(Qt.CursorShape.ClosedHandCursor)

    def mouseMoveEvent(self, event) -> None:
        """Drag a handle, or pan."""
        if self._overlay_drag:
            self.overlay.move(event.position())
            return
        if self._drag_start is None or self._drag_view is None:
            return
        delta = event.position() - self._drag_start
        if self._press_pos is not None and delta.manhattanLength() < 4:
            return
        self._press_pos = None
        v = self._drag_view
        self.view = View(v.zoom, v.ox + delta.x(), v.oy + delta.y())
        self._user_moved = True
        self._interact()

    def mouseReleaseEvent(self, event) -> None:
        """A release without movement is a click: pick the element under it."""
        if self._overlay_drag:
            self._overlay_drag = False
            self.overlay.release(event.position())
            return
        if self._press_pos is not None and event.button() == Qt.MouseButton.LeftButton and not self._space:
            self.elementClicked.emit(self.pick(event.position()))
        self._drag_start = self._drag_view = self._press_pos = None
        if not self._space:
            self.unsetCursor()
