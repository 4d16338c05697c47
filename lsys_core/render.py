"""Raster rendering of a :class:`~lsys_core.model.Drawing` with skia-python (CPU).

:class:`Renderer` keeps one skia surface wrapped around a numpy array, and one
skia path and paint per terminal, so repeated redraws (the editor's canvas)
only pay for drawing.  :meth:`Renderer.draw` returns that array itself — no
copy — which a Qt canvas can wrap in a ``QImage`` (``Format_RGBA8888_Premultiplied``).

Full mode draws every instance with its own transform and anti-aliasing, in
order.  Draft mode transforms each terminal's control points to all its
instances with numpy and draws them as one path per terminal (and stroke-width
bucket), without anti-aliasing and with thin strokes as hairlines: much faster,
but overlaps between terminals no longer follow the instance order.

skia is imported inside the functions that use it.
"""

from __future__ import annotations

import math
import os
import struct
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .errors import LsysError
from .io import write_atomic
from .model import Drawing

__all__ = ["MAX_PNG_PIXELS", "Renderer", "encode_png", "fit_view", "parse_style", "render", "render_png"]

#: Colour of highlighted instances (RGBA).
HIGHLIGHT = (255, 111, 0, 255)
#: In draft mode, strokes thinner than this many pixels are drawn as hairlines.
DRAFT_HAIRLINE = 2.0
#: Most terminals (path, style) whose skia objects a renderer keeps.
CACHE_SIZE = 4096
#: Largest image side accepted, in pixels.
MAX_SIDE = 16384
#: Most pixels of a PNG written by :func:`render_png` (larger sizes are scaled down, aspect kept).
MAX_PNG_PIXELS = 40_000_000

_VERB_MOVE, _VERB_LINE, _VERB_CUBIC, _VERB_CLOSE = 0, 1, 4, 5


def parse_style(style: str) -> dict[str, str]:
    """Split CSS declarations ``"a:b;c:d"`` into a dict with lower-case keys."""
    out: dict[str, str] = {}
    for part in style.split(";"):
        key, sep, value = part.partition(":")
        if sep:
            out[key.strip().lower()] = value.strip()
    return out


def _number(text: str | None, default: float) -> float:
    if text is None:
        return default
    t = text.strip().lower().removesuffix("px")
    try:
        if t.endswith("%"):
            v = float(t[:-1]) / 100.0
        else:
            v = float(t)
    except ValueError:
        return default
    return v if math.isfinite(v) else default


@lru_cache(maxsize=256)
def _rgba(color: str, opacity: float) -> tuple[int, int, int, int] | None:
    """Parse a CSS colour into RGBA bytes with ``opacity`` applied; None for ``none``."""
    c = color.strip()
    if not c or c.lower() in ("none", "transparent"):
        return None
    from svgelements import Color

    col = Color(c)
    if col.value is None:
        return None
    alpha = col.alpha * max(0.0, min(1.0, opacity))
    return (col.red, col.green, col.blue, round(alpha))


@dataclass
class _Paints:
    """What a style draws: fill and stroke colours and stroke geometry."""

    fill: tuple[int, int, int, int] | None
    stroke: tuple[int, int, int, int] | None
    width: float
    cap: str
    join: str
    miter: float
    evenodd: bool


@lru_cache(maxsize=1024)
def _paints(style: str) -> _Paints:
    """Interpret a terminal's style as SVG would (fill black and no stroke by default)."""
    decl = parse_style(style)
    opacity = max(0.0, min(1.0, _number(decl.get("opacity"), 1.0)))
    fill = _rgba(decl.get("fill", "black"), opacity * _number(decl.get("fill-opacity"), 1.0))
    stroke = _rgba(decl.get("stroke", "none"), opacity * _number(decl.get("stroke-opacity"), 1.0))
    width = max(0.0, _number(decl.get("stroke-width"), 1.0))
    if width == 0.0:
        stroke = None
    return _Paints(
        fill=fill if fill is None or fill[3] > 0 else None,
        stroke=stroke if stroke is None or stroke[3] > 0 else None,
        width=width,
        cap=decl.get("stroke-linecap", "butt").lower(),
        join=decl.get("stroke-linejoin", "miter").lower(),
        miter=max(1.0, _number(decl.get("stroke-miterlimit"), 4.0)),
        evenodd=decl.get("fill-rule", "nonzero").lower() == "evenodd",
    )


def _skia_paint(rgba, antialias: bool, stroke: _Paints | None = None, width: float = 1.0):
    import skia

    paint = skia.Paint()
    paint.setAntiAlias(antialias)
    r, g, b, a = rgba
    paint.setARGB(a, r, g, b)
    if stroke is None:
        paint.setStyle(skia.Paint.kFill_Style)
        return paint
    paint.setStyle(skia.Paint.kStroke_Style)
    paint.setStrokeWidth(width)
    paint.setStrokeCap(
        {"round": skia.Paint.kRound_Cap, "square": skia.Paint.kSquare_Cap}.get(
            stroke.cap, skia.Paint.kButt_Cap
        )
    )
    paint.setStrokeJoin(
        {"round": skia.Paint.kRound_Join, "bevel": skia.Paint.kBevel_Join}.get(
            stroke.join, skia.Paint.kMiter_Join
        )
    )
    paint.setStrokeMiter(stroke.miter)
    return paint


# ---------------------------------------------------------------------------
# Building skia paths from arrays


@dataclass
class _Geometry:
    """A terminal's outline as skia path ingredients in its local frame."""

    points: np.ndarray  # complex, (m,)
    verbs: np.ndarray  # uint8, (v,)
    radius: float  # max |p| of the control points (for culling)


def _geometry(d: str) -> _Geometry:
    """Turn path data into skia points and verbs (lines where control points sit at thirds)."""
    from .svg.pathdata import _collinear_thirds, cubics_from_d

    try:
        cubics, subpaths, closed = cubics_from_d(d) if d.strip() else (np.zeros((0, 4), complex), None, ())
    except LsysError:
        cubics, subpaths, closed = np.zeros((0, 4), complex), None, ()
    k = len(cubics)
    if k == 0:
        return _Geometry(np.zeros(0, complex), np.zeros(0, np.uint8), 0.0)
    if not np.isfinite(cubics).all():
        return _Geometry(np.zeros(0, complex), np.zeros(0, np.uint8), 0.0)
    scale = float(np.abs(cubics).max()) or 1.0
    is_line = _collinear_thirds(cubics, 1e-9 * scale)
    first = np.ones(k, dtype=bool)
    first[1:] = (subpaths[1:] != subpaths[:-1]) | (cubics[1:, 0] != cubics[:-1, 3])
    last = np.ones(k, dtype=bool)
    last[:-1] = first[1:]
    flags = np.asarray(closed, dtype=bool)
    seg_closed = last & (flags[subpaths] if flags.size else False)
    # Per segment: optional move, then line (1 point) or cubic (3 points), then optional close.
    pts_mask = np.zeros((k, 4), dtype=bool)
    pts_mask[:, 0] = first
    pts_mask[:, 1] = ~is_line
    pts_mask[:, 2] = ~is_line
    pts_mask[:, 3] = True
    points = cubics[pts_mask]
    v = np.where(is_line, _VERB_LINE, _VERB_CUBIC)
    parts = np.stack([np.where(first, _VERB_MOVE, -1), v, np.where(seg_closed, _VERB_CLOSE, -1)], axis=1)
    verbs = parts[parts >= 0].astype(np.uint8)
    return _Geometry(points, verbs, float(np.abs(points).max()))


@lru_cache(maxsize=1)
def _serialization_works() -> bool:
    """Check once that skia reads paths in the layout :func:`_path_from_arrays` writes."""
    import skia

    pts = np.array([[1, 2], [3, 4], [5, 6], [7, 8], [9, 10]], dtype=np.float32)
    verbs = np.array([_VERB_MOVE, _VERB_LINE, _VERB_CUBIC, _VERB_CLOSE], dtype=np.uint8)
    path = skia.Path()
    try:
        if path.readFromMemory(_serialize(pts, verbs, evenodd=True)) == 0:
            return False
    except Exception:  # an incompatible skia: use the slow but safe builder
        return False
    ref = skia.Path()
    ref.moveTo(1, 2)
    ref.lineTo(3, 4)
    ref.cubicTo(5, 6, 7, 8, 9, 10)
    ref.close()
    ref.setFillType(skia.PathFillType.kEvenOdd)
    return path == ref


def _serialize(points_xy: np.ndarray, verbs: np.ndarray, evenodd: bool) -> bytes:
    """Write skia's path serialisation (version 5): header, counts, float32 points, verbs, padding."""
    pts = np.ascontiguousarray(points_xy, dtype=np.float32)
    header = struct.pack("<iiii", 5 | ((1 if evenodd else 0) << 8), len(pts), 0, len(verbs))
    pad = (-len(verbs)) % 4
    return header + pts.tobytes() + np.ascontiguousarray(verbs, dtype=np.uint8).tobytes() + b"\0" * pad


def _path_from_arrays(points: np.ndarray, verbs: np.ndarray, evenodd: bool):
    """Build a skia path from complex ``points`` and skia ``verbs`` (bulk when possible)."""
    import skia

    xy = np.stack([points.real, points.imag], axis=-1).reshape(-1, 2)
    if _serialization_works():
        path = skia.Path()
        if path.readFromMemory(_serialize(xy, verbs, evenodd)):
            return path
    fill = skia.PathFillType.kEvenOdd if evenodd else skia.PathFillType.kWinding
    pts = [skia.Point(float(x), float(y)) for x, y in xy.tolist()]
    return skia.Path.Make(pts, verbs.tolist(), [], fill)


# ---------------------------------------------------------------------------
# Views


def fit_view(view: tuple[float, float, float, float], width: int, height: int) -> tuple[float, float, float]:
    """Return ``(scale, tx, ty)`` mapping ``view`` (x, y, w, h) centred into a width×height image."""
    x, y, w, h = (float(v) for v in view)
    w = w if w > 0 and math.isfinite(w) else 1.0
    h = h if h > 0 and math.isfinite(h) else 1.0
    s = min(width / w, height / h)
    tx = (width - s * w) / 2.0 - s * x
    ty = (height - s * h) / 2.0 - s * y
    return s, tx, ty


def default_view(drawing: Drawing) -> tuple[float, float, float, float]:
    """Return the drawing's viewBox, or its bounds with a small margin, or a unit square."""
    if drawing.viewbox is not None:
        return drawing.viewbox
    from .svg.export import MARGIN, drawing_bounds

    bounds = drawing_bounds(drawing)
    if bounds is None:
        return (0.0, 0.0, 1.0, 1.0)
    x0, y0, x1, y1 = bounds
    m = MARGIN * max(x1 - x0, y1 - y0) or 1.0
    return (x0 - m, y0 - m, x1 - x0 + 2 * m, y1 - y0 + 2 * m)


# ---------------------------------------------------------------------------
# The renderer


@dataclass
class _Terminal:
    geometry: _Geometry
    paints: _Paints
    path: object  # skia.Path in the local frame
    fill_aa: object | None
    fill_noaa: object | None


class Renderer:
    """Draw drawings into one reusable RGBA surface of a fixed size.

    Parameters
    ----------
    width, height : int
        Image size in pixels.

    Notes
    -----
    The pixels are premultiplied RGBA (``QImage.Format_RGBA8888_Premultiplied``);
    :func:`render` returns straight (unpremultiplied) RGBA.
    """

    def __init__(self, width: int, height: int) -> None:
        self._cache: dict[tuple[str, str], _Terminal] = {}
        self._surface = None
        self.resize(width, height)

    @property
    def size(self) -> tuple[int, int]:
        """The image size ``(width, height)``."""
        return self._pixels.shape[1], self._pixels.shape[0]

    @property
    def pixels(self) -> np.ndarray:
        """The ``(height, width, 4)`` uint8 premultiplied RGBA array the surface draws into."""
        return self._pixels

    def resize(self, width: int, height: int) -> None:
        """Use a new surface of the given size (the terminal cache is kept)."""
        import skia

        width, height = int(width), int(height)
        if not (0 < width <= MAX_SIDE and 0 < height <= MAX_SIDE):
            raise LsysError(f"image size {width}x{height} is out of range (1..{MAX_SIDE} pixels a side)")
        self._pixels = np.zeros((height, width, 4), dtype=np.uint8)
        self._surface = skia.Surface(
            self._pixels, colorType=skia.kRGBA_8888_ColorType, alphaType=skia.kPremul_AlphaType
        )
        self._canvas = self._surface.getCanvas()

    def _terminal(self, path: str, style: str) -> _Terminal:
        key = (path, style)
        entry = self._cache.get(key)
        if entry is None:
            if len(self._cache) >= CACHE_SIZE:
                self._cache.clear()  # edits create new terminals: keep the cache bounded
            geometry = _geometry(path)
            paints = _paints(style)
            skpath = _path_from_arrays(geometry.points, geometry.verbs, paints.evenodd)
            fills = (None, None)
            if paints.fill is not None:
                fills = (_skia_paint(paints.fill, True), _skia_paint(paints.fill, False))
            entry = _Terminal(geometry, paints, skpath, *fills)
            self._cache[key] = entry
        return entry

    def draw(
        self,
        drawing: Drawing,
        view: tuple[float, float, float, float] | None = None,
        antialias: bool = True,
        draft: bool = False,
        *,
        background: tuple[int, int, int, int] = (255, 255, 255, 0),
        highlight: np.ndarray | None = None,
    ) -> np.ndarray:
        """Draw ``drawing`` and return the surface's pixel array (not a copy).

        Parameters
        ----------
        drawing : Drawing
        view : (x, y, w, h), optional
            Region of drawing coordinates fitted into the image, aspect ratio kept
            (default: the drawing's viewBox or bounds).
        antialias : bool
            Anti-alias edges (ignored in draft mode, which never does).
        draft : bool
            Batch each terminal's instances into one path (fast, approximate order).
        background : (r, g, b, a)
            Colour the image is cleared to.
        highlight : ndarray of int or bool, optional
            Instances (indices or mask) drawn again on top in :data:`HIGHLIGHT` colour.

        Returns
        -------
        ndarray of uint8, shape (height, width, 4)
            Premultiplied RGBA; overwritten by the next call.
        """
        import skia

        width, height = self.size
        canvas = self._canvas
        r, g, b, a = (int(v) for v in background)
        canvas.resetMatrix()
        canvas.clear(skia.ColorSetARGB(a, r, g, b))
        n = len(drawing)
        if n == 0:
            return self._pixels
        s, tx, ty = fit_view(view if view is not None else default_view(drawing), width, height)
        symbol = np.asarray(drawing.symbol, dtype=np.intp).reshape(n)
        pa = np.asarray(drawing.a, dtype=complex).reshape(n)
        pb = np.asarray(drawing.b, dtype=complex).reshape(n)
        # Device frame of every instance: view ∘ pose (non-finite ones are culled below).
        with np.errstate(invalid="ignore", over="ignore"):
            da = s * pa
            db = s * pb + complex(tx, ty)
        terms = [self._terminal(t.path, t.style) for t in drawing.terminals]
        visible = self._visible(terms, symbol, da, db, width, height)
        if draft:
            self._draw_batched(terms, symbol, da, db, visible)
        else:
            self._draw_each(terms, symbol, da, db, visible, antialias)
        if highlight is not None:
            mask = np.zeros(n, dtype=bool)
            hl = np.asarray(highlight).reshape(-1)
            if hl.dtype == bool:
                mask[: min(n, hl.size)] = hl[:n]
            else:
                hl = hl.astype(np.intp)
                mask[hl[(hl >= 0) & (hl < n)]] = True
            self._draw_highlight(terms, symbol, da, db, visible & mask, antialias and not draft)
        canvas.resetMatrix()
        return self._pixels

    @staticmethod
    def _visible(terms, symbol, da, db, width, height) -> np.ndarray:
        """Return a mask of instances whose bounding disc meets the image."""
        radius = np.array(
            [t.geometry.radius + (t.paints.width / 2 if t.paints.stroke else 0.0) for t in terms] + [0.0]
        )
        empty = np.array([t.geometry.verbs.size == 0 for t in terms] + [True])
        sym = np.where((symbol >= 0) & (symbol < len(terms)), symbol, len(terms))  # bad index: not drawn
        with np.errstate(invalid="ignore", over="ignore"):
            rr = radius[sym] * np.abs(da) + 1.0
            x, y = db.real, db.imag
            ok = (x + rr >= 0) & (x - rr <= width) & (y + rr >= 0) & (y - rr <= height)
        return ok & ~empty[sym] & np.isfinite(rr) & np.isfinite(db)

    def _draw_each(self, terms, symbol, da, db, visible, antialias: bool) -> None:
        """Draw every visible instance with its own matrix, in order."""
        import skia

        canvas = self._canvas
        idx = np.flatnonzero(visible)
        if idx.size == 0:
            return
        mats = np.stack([da.real, -da.imag, db.real, da.imag, da.real, db.imag], axis=1)[idx]
        matrix = skia.Matrix()
        stroke_cache: dict[tuple[int, float], object] = {}
        for t, m in zip(symbol[idx].tolist(), mats.tolist(), strict=True):
            term = terms[t]
            matrix.setAll(m[0], m[1], m[2], m[3], m[4], m[5], 0.0, 0.0, 1.0)
            canvas.setMatrix(matrix)
            if term.fill_aa is not None:
                canvas.drawPath(term.path, term.fill_aa if antialias else term.fill_noaa)
            if term.paints.stroke is not None:
                key = (t, antialias)
                paint = stroke_cache.get(key)
                if paint is None:
                    paint = _skia_paint(term.paints.stroke, antialias, term.paints, term.paints.width)
                    stroke_cache[key] = paint
                canvas.drawPath(term.path, paint)

    def _draw_batched(self, terms, symbol, da, db, visible) -> None:
        """Draft: one path per terminal (and stroke-width bucket) with all its instances."""
        canvas = self._canvas
        canvas.resetMatrix()
        for t, term in enumerate(terms):
            sel = np.flatnonzero(visible & (symbol == t))
            if sel.size == 0:
                continue
            geo, paints = term.geometry, term.paints
            if paints.fill is not None:
                path = self._batch_path(geo, da[sel], db[sel], paints.evenodd)
                canvas.drawPath(path, term.fill_noaa)
            if paints.stroke is not None:
                # Group instances by scale so stroke widths stay close to the true ones.
                scale = np.abs(da[sel])
                bucket = np.round(np.log2(np.maximum(scale, 1e-30)) * 4).astype(np.int64)
                for key in np.unique(bucket).tolist():
                    part = sel[bucket == key]
                    width = paints.width * float(np.median(np.abs(da[part])))
                    if width < DRAFT_HAIRLINE:
                        width = 0.0  # a hairline: far cheaper than stroking thin outlines
                    path = self._batch_path(geo, da[part], db[part], False)
                    canvas.drawPath(path, _skia_paint(paints.stroke, False, paints, width))

    @staticmethod
    def _batch_path(geo: _Geometry, a: np.ndarray, b: np.ndarray, evenodd: bool):
        pts = (a[:, None] * geo.points[None, :] + b[:, None]).reshape(-1)
        verbs = np.tile(geo.verbs, a.size)
        return _path_from_arrays(pts, verbs, evenodd)

    def _draw_highlight(self, terms, symbol, da, db, mask, antialias: bool) -> None:
        """Draw the selected instances on top in the highlight colour."""
        canvas = self._canvas
        canvas.resetMatrix()
        r, g, b, a = HIGHLIGHT
        for t, term in enumerate(terms):
            sel = np.flatnonzero(mask & (symbol == t))
            if sel.size == 0:
                continue
            path = self._batch_path(term.geometry, da[sel], db[sel], term.paints.evenodd)
            if term.paints.fill is not None:
                canvas.drawPath(path, _skia_paint((r, g, b, a // 2), antialias))
            outline = _skia_paint(
                (r, g, b, a), antialias, _Paints(None, None, 1.5, "round", "round", 4.0, False), 1.5
            )
            canvas.drawPath(path, outline)


def _unpremultiply(pixels: np.ndarray) -> np.ndarray:
    """Convert premultiplied RGBA to straight RGBA in place and return it."""
    alpha = pixels[..., 3]
    partial = (alpha > 0) & (alpha < 255)
    if partial.any():
        a = alpha[partial].astype(np.float64)[:, None]
        rgb = pixels[..., :3][partial].astype(np.float64)
        pixels[..., :3][partial] = np.clip(np.round(rgb * 255.0 / a), 0, 255).astype(np.uint8)
    return pixels


def render(
    drawing: Drawing,
    width: int,
    height: int,
    *,
    view: tuple[float, float, float, float] | None = None,
    antialias: bool = True,
    background: tuple[int, int, int, int] = (255, 255, 255, 0),
    highlight: np.ndarray | None = None,
    draft: bool = False,
) -> np.ndarray:
    """Render a drawing to a new ``(height, width, 4)`` uint8 array of straight RGBA.

    Parameters
    ----------
    drawing : Drawing
    width, height : int
        Image size in pixels.
    view : (x, y, w, h), optional
        Region of drawing coordinates to fit into the image, aspect ratio kept
        (default: the drawing's viewBox, else its bounds).
    antialias : bool
        Anti-alias edges.
    background : (r, g, b, a)
        Background colour (default transparent white).
    highlight : ndarray of int or bool, optional
        Instances to emphasise (see :meth:`Renderer.draw`).
    draft : bool
        Use the fast batched draft mode.
    """
    renderer = Renderer(width, height)
    pixels = renderer.draw(drawing, view, antialias, draft, background=background, highlight=highlight)
    return _unpremultiply(pixels)


def _png_size(drawing: Drawing, width: int | None, height: int | None) -> tuple[int, int]:
    """Choose the PNG size: as given, else from the drawing's canvas with its aspect ratio."""
    _, _, vw, vh = default_view(drawing)
    aspect = vw / vh if vw > 0 and vh > 0 else 1.0
    if width is None and height is None:
        size = drawing.size
        w = _number(size[0], vw) if size else vw
        h = _number(size[1], vh) if size else vh
        if not (w > 0 and h > 0) or (size and ("%" in size[0] or "%" in size[1])):
            w, h = vw, vh
        w, h = max(1, round(w)), max(1, round(h))
    elif width is None:
        h = int(height)
        w = max(1, round(h * aspect))
    elif height is None:
        w = int(width)
        h = max(1, round(w / aspect))
    else:
        w, h = int(width), int(height)
    w, h = min(w, MAX_SIDE), min(h, MAX_SIDE)
    if w * h > MAX_PNG_PIXELS:
        shrink = math.sqrt(MAX_PNG_PIXELS / (w * h))
        w, h = max(1, int(w * shrink)), max(1, int(h * shrink))
    return w, h


def encode_png(
    drawing: Drawing,
    width: int | None = None,
    height: int | None = None,
    *,
    background: tuple[int, int, int, int] = (255, 255, 255, 0),
) -> bytes:
    """Render a drawing and return the bytes of a PNG file.

    Without ``width`` and ``height`` the drawing's ``width``/``height`` (in px) or
    viewBox size is used; with one of them the other follows the aspect ratio.  Sides
    are capped at :data:`MAX_SIDE` and the image at :data:`MAX_PNG_PIXELS` pixels
    (scaled down, aspect ratio kept), so an absurd canvas size cannot exhaust memory.

    Raises
    ------
    LsysError
        When the image cannot be encoded.
    """
    import skia

    w, h = _png_size(drawing, width, height)
    renderer = Renderer(w, h)
    renderer.draw(drawing, None, True, False, background=background)
    image = renderer._surface.makeImageSnapshot()
    data = image.encodeToData(skia.EncodedImageFormat.kPNG, 100)
    if data is None:
        raise LsysError("PNG encoding failed")
    return bytes(data)


def render_png(
    drawing: Drawing,
    path: str | os.PathLike,
    width: int | None = None,
    height: int | None = None,
    *,
    background: tuple[int, int, int, int] = (255, 255, 255, 0),
) -> None:
    """Render a drawing and write it as a PNG file atomically (see :func:`encode_png`)."""
    try:
        data = encode_png(drawing, width, height, background=background)
    except LsysError as exc:
        raise LsysError(f"cannot write {path}: {exc}") from exc
    write_atomic(path, data)
