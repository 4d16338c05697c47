"""Rendering one frame of the canvas off the UI thread: the view, the request and the frame.

A :class:`RenderRequest` snapshots everything a frame depends on (drawing, colour mode,
:class:`View`, size, device pixel ratio, quality); :func:`render_frame` runs on a worker,
draws with skia into the request's surface and wraps the pixels as a QImage without copying
(:class:`Frame`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from PySide6.QtCore import QRectF
from PySide6.QtGui import QImage, QPainter, QTransform

from .coloring import recolor

__all__ = ["BACKGROUND", "RENDER_FORMAT", "Frame", "RenderRequest", "View", "render_frame"]

BACKGROUND = (255, 255, 255, 255)
#: Pixel format of ``Renderer.draw``'s array: RGBA bytes, premultiplied alpha (as skia draws).
RENDER_FORMAT = QImage.Format.Format_RGBA8888_Premultiplied


@dataclass(frozen=True)
class View:
    """How document coordinates map to the widget: ``widget = doc * zoom + (ox, oy)`` (logical pixels)."""

    zoom: float = 1.0
    ox: float = 0.0
    oy: float = 0.0

    def to_widget(self, x: float, y: float) -> tuple[float, float]:
        """Map a document point to widget (logical pixel) coordinates."""
        return x * self.zoom + self.ox, y * self.zoom + self.oy

    def to_doc(self, x: float, y: float) -> tuple[float, float]:
        """Map a widget point to document coordinates."""
        return (x - self.ox) / self.zoom, (y - self.oy) / self.zoom

    def transform(self) -> QTransform:
        """Return the document → widget transform."""
        return QTransform(self.zoom, 0, 0, self.zoom, self.ox, self.oy)


@dataclass(frozen=True)
class RenderRequest:
    """One frame to render: immutable inputs, plus the surface to draw into (set when it starts)."""

    drawing: Any
    color_mode: str
    view: View
    width: int
    height: int
    dpr: float
    draft: bool
    highlight: Any = None  # bool mask of instances drawn in the highlight colour
    overlay: Any = None  # a QSvgRenderer of the input, painted translucently on top
    overlay_rect: QRectF | None = None
    renderer: Any = None
    slot: int = 0


@dataclass(frozen=True)
class Frame:
    """A rendered frame: the QImage, the array it wraps (kept alive with it), and its inputs."""

    image: QImage
    pixels: np.ndarray
    renderer: Any
    slot: int
    drawing: Any
    color_mode: str
    view: View
    size: tuple[int, int]
    dpr: float
    draft: bool
    overlay: bool
    seconds: float


def render_frame(req: RenderRequest, cancel, progress) -> Frame:
    """Render ``req`` on a worker: skia draws into the request's surface, wrapped zero-copy."""
    t0 = time.perf_counter()
    s = req.dpr
    z = req.view.zoom
    region = (-req.view.ox / z, -req.view.oy / z, req.width / (z * s), req.height / (z * s))
    shown = recolor(req.drawing, req.color_mode)  # a copy with other styles: off the UI thread
    pixels = req.renderer.draw(
        shown, region, not req.draft, req.draft, background=BACKGROUND, highlight=req.highlight
    )
    cancel.check()
    h, w = pixels.shape[:2]
    image = QImage(pixels.data, w, h, pixels.strides[0], RENDER_FORMAT)
    image.setDevicePixelRatio(s)
    if req.overlay is not None and req.overlay_rect is not None:
        painter = QPainter(image)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, not req.draft)
        painter.setTransform(req.view.transform())
        painter.setOpacity(0.35)
        req.overlay.render(painter, req.overlay_rect)
        painter.end()
    return Frame(
        image,
        pixels,
        req.renderer,
        req.slot,
        req.drawing,
        req.color_mode,
        req.view,
        (req.width, req.height),
        s,
        req.draft,
        req.overlay is not None,
        time.perf_counter() - t0,
    )
