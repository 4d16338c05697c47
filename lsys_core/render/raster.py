"""Raster rendering of a :class:`~lsys_core.derive.model.Drawing` with skia-python (CPU).

:class:`Renderer` keeps one skia surface wrapped around a numpy array, and one
skia path and paint per terminal, so repeated redraws (the editor's canvas)
only pay for drawing.  :meth:`Renderer.draw` returns that array itself — no
copy — which a Qt canvas can wrap in a ``QImage`` (``Format_RGBA8888_Premultiplied``).

Full mode (not draft) paints the instances in order, each instance's fill then its
stroke, so overlaps are exact.  Most instances are drawn one by one, each with its own
matrix.  Runs of consecutive instances whose painted rectangles (stroke outlines and
joins included) pairwise neither overlap nor touch cover no pixel twice, so their
order does not matter: where such a run is long and compact (:data:`FULL_MIN_RUN`,
:data:`FULL_ROWS_PER_INSTANCE`), it is drawn as a few batched paths per terminal, at
about twice the speed.  The picture is the same except that skia anti-aliases a big
batched path by supersampling instead of analytically: edge pixels differ by a few
levels (at most ~30 of 255), never the shapes, colours or order.

Draft mode groups the instances by terminal and scale (quarter octaves), transforms
each terminal's outline to all instances of a group with numpy, and draws them as a
few big paths (:data:`DRAFT_CHUNK` instances each, built once and used for both
the fill and the stroke), without anti-aliasing, with curves flattened into lines
within :data:`DRAFT_TOLERANCE` pixels and with thin strokes as hairlines: much
faster, but overlaps between different terminals or scale groups no longer follow
the instance order (within a group, chunks are drawn in instance order).

skia is imported inside the functions that use it.
"""

from __future__ import annotations

import itertools
import math
import os
from dataclasses import dataclass, field

import numpy as np

from lsys_core.derive.model import Drawing
from lsys_core.errors import LsysError
from lsys_core.io import write_atomic
from lsys_core.render.paths import (
    _BUCKETS_PER_OCTAVE,
    _disjoint_runs,
    _flatten,
    _Geometry,
    _geometry,
    _groups,
    _Paints,
    _paints,
    _path_from_arrays,
    _path_from_xy,
    _skia_paint,
    parse_style,
)
from lsys_core.render.skia_import import load_skia
from lsys_core.render.units import CSS_DPI, length_px

__all__ = ["MAX_PNG_PIXELS", "Renderer", "encode_png", "fit_view", "parse_style", "render", "render_png"]

#: Colour of highlighted instances (RGBA).
HIGHLIGHT = (255, 111, 0, 255)
#: In draft mode, strokes thinner than this many pixels are drawn as hairlines.
DRAFT_HAIRLINE = 2.0
#: In draft mode, curves are replaced by lines at most this many pixels away from them.
DRAFT_TOLERANCE = 0.5
#: Instances per batched path (measured: skia fills ~1,000-instance paths without anti-aliasing
#: about twice as fast per instance as one path of 10,000; building them stays a small part).
DRAFT_CHUNK = 1024
#: Full mode draws runs of at least this many consecutive instances whose painted rectangles
#: are pairwise disjoint as batched anti-aliased paths (shorter runs are drawn one by one) ...
FULL_MIN_RUN = 16
#: ... when their centres lie within this many pixel rows per instance (measured on 10,000 leaves:
#: runs spread over ~33 rows per instance draw 1.3x slower batched, compact ones 1.7x faster).
FULL_ROWS_PER_INSTANCE = 4.0
#: Most terminals (path, style) whose skia objects a renderer keeps.
CACHE_SIZE = 4096
#: Largest image side accepted, in pixels.
MAX_SIDE = 16384
#: Most pixels of a PNG written by :func:`render_png` (larger sizes are scaled down, aspect kept).
MAX_PNG_PIXELS = 40_000_000


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
    from lsys_core.render.svg import MARGIN, drawing_bounds

    bounds = drawing_bounds(drawing)
    if bounds is None:
        return (0.0, 0.0, 1.0, 1.0)
    x0, y0, x1, y1 = bounds
    m = MARGIN * max(x1 - x0, y1 - y0) or 1.0
    return (x0 - m, y0 - m, x1 - x0 + 2 * m, y1 - y0 + 2 * m)


# ---------------------------------------------------------------------------
# The renderer


def _painted_box(path, stroke) -> tuple[float, float, float, float]:
    """Return the tight bounds ``x0, y0, x1, y1`` of a path's fill and ``stroke`` (joins included)."""
    import skia

    box = path.computeTightBounds()
    if stroke is not None:
        outline = skia.Path()
        if stroke.getFillPath(path, outline):
            box.join(outline.computeTightBounds())
    return box.left(), box.top(), box.right(), box.bottom()


@dataclass
class _Terminal:
    geometry: _Geometry
    paints: _Paints
    path: object  # skia.Path in the local frame
    fill_aa: object | None
    fill_noaa: object | None
    stroke_aa: object | None  # at the style's width, in the local frame (full mode)
    stroke_noaa: object | None
    box: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)  # x0, y0, x1, y1 of what it paints
    flat: dict[int, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)  # draft outline by bucket

    def ops(self, antialias: bool, *, fill: bool = True) -> tuple[tuple[object, object], ...]:
        """Return the ``(path, paint)`` draws of one instance in full mode: fill (if ``fill``), stroke."""
        paints = (self.fill_aa, self.stroke_aa) if antialias else (self.fill_noaa, self.stroke_noaa)
        return tuple((self.path, p) for p in paints[0 if fill else 1 :] if p is not None)

    def flattened(self, bucket: int) -> tuple[np.ndarray, np.ndarray]:
        """Return the draft outline (points, verbs) for instances of scale bucket ``bucket``."""
        entry = self.flat.get(bucket)
        if entry is None:
            top = 2.0 ** ((bucket + 0.5) / _BUCKETS_PER_OCTAVE)  # the largest scale of the bucket
            entry = self.flat[bucket] = _flatten(self.geometry, top, DRAFT_TOLERANCE)
        return entry


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
        self.resize(width, height)  # sets the pixels, the skia surface and its canvas

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
            fills = strokes = (None, None)
            if paints.fill is not None:
                fills = (_skia_paint(paints.fill, True), _skia_paint(paints.fill, False))
            if paints.stroke is not None:
                strokes = tuple(_skia_paint(paints.stroke, aa, paints, paints.width) for aa in (True, False))
            entry = _Terminal(geometry, paints, skpath, *fills, *strokes, _painted_box(skpath, strokes[0]))
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
            Draw a draft: instances batched by terminal and scale into a few paths, curves
            flattened (fast; overlaps of different terminals in approximate order).  Full mode
            keeps the exact order (see the module notes).
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
        """Draw the visible instances in order: one by one, or in batches where that is the same.

        Runs of at least :data:`FULL_MIN_RUN` consecutive instances whose painted rectangles
        are pairwise disjoint cover no pixel twice (except anti-aliased edge pixels of touching
        instances), so drawing them terminal by terminal as batched paths gives the same picture
        (such shared edge pixels blend as in one shape, without a seam); the rest is drawn one
        by one, each instance with its own matrix.
        """
        idx = np.flatnonzero(visible)
        if idx.size == 0:
            return
        full = _FullPass(self._canvas, terms, symbol[idx], da[idx], db[idx], antialias)
        done = 0
        for lo, hi in full.compact_runs():
            full.one_by_one(range(done, lo))
            full.run(lo, hi)
            done = hi
        full.one_by_one(range(done, idx.size))

    def _draw_batched(self, terms, symbol, da, db, visible) -> None:
        """Draft: per terminal and scale bucket, chunks of instances drawn as one path each."""
        canvas = self._canvas
        canvas.resetMatrix()
        idx = np.flatnonzero(visible)
        if idx.size == 0:
            return
        scale = np.abs(da[idx])
        bucket = np.round(np.log2(np.maximum(scale, 1e-30)) * _BUCKETS_PER_OCTAVE).astype(np.int64)
        sym = symbol[idx]
        for group in _groups(sym, bucket):
            t, key = int(sym[group[0]]), int(bucket[group[0]])
            term = terms[t]
            paints = term.paints
            points, verbs = term.flattened(key)
            stroke = None
            if paints.stroke is not None:
                # One width per bucket: within a quarter octave of every instance's true width.
                width = paints.width * float(np.median(scale[group]))
                if width < DRAFT_HAIRLINE:
                    width = 0.0  # a hairline: far cheaper than stroking thin outlines
                stroke = _skia_paint(paints.stroke, False, paints, width)
            inst = idx[group]
            for lo in range(0, inst.size, DRAFT_CHUNK):
                part = inst[lo : lo + DRAFT_CHUNK]
                path = self._batch_path(points, verbs, da[part], db[part], paints.evenodd)
                if term.fill_noaa is not None:
                    canvas.drawPath(path, term.fill_noaa)
                if stroke is not None:
                    canvas.drawPath(path, stroke)

    @staticmethod
    def _batch_path(points: np.ndarray, verbs: np.ndarray, a: np.ndarray, b: np.ndarray, evenodd: bool):
        """Return one path of the outline ``points``/``verbs`` placed at every pose ``z -> a z + b``."""
        pts = a[:, None] * points[None, :] + b[:, None]  # complex (instances, points)
        xy = pts.view(np.float64).astype(np.float32).reshape(-1, 2)
        return _path_from_xy(xy, np.tile(verbs, a.size), evenodd)

    def _draw_highlight(self, terms, symbol, da, db, mask, antialias: bool) -> None:
        """Draw the selected instances on top in the highlight colour."""
        canvas = self._canvas
        canvas.resetMatrix()
        r, g, b, a = HIGHLIGHT
        for t, term in enumerate(terms):
            sel = np.flatnonzero(mask & (symbol == t))
            if sel.size == 0:
                continue
            geo = term.geometry
            path = self._batch_path(geo.points, geo.verbs, da[sel], db[sel], term.paints.evenodd)
            if term.paints.fill is not None:
                canvas.drawPath(path, _skia_paint((r, g, b, a // 2), antialias))
            outline = _skia_paint(
                (r, g, b, a), antialias, _Paints(None, None, 1.5, "round", "round", 4.0, False), 1.5
            )
            canvas.drawPath(path, outline)


class _FullPass:
    """One full-mode drawing of instances (already culled) into a canvas, in their order."""

    def __init__(self, canvas, terms: list[_Terminal], symbol, a, b, antialias: bool) -> None:
        self.canvas, self.terms, self.antialias = canvas, terms, antialias
        self.symbol, self.a, self.b = symbol, a, b
        mats = np.zeros((a.size, 9))
        mats[:, 0] = mats[:, 4] = a.real
        mats[:, 1] = -a.imag
        mats[:, 3] = a.imag
        mats[:, 2] = b.real
        mats[:, 5] = b.imag
        mats[:, 8] = 1.0
        self.mats = mats.tolist()
        self.symbols = symbol.tolist()
        self.ops = [t.ops(antialias) for t in terms]
        self.stroke_ops = [t.ops(antialias, fill=False) for t in terms]
        self._same_scale: np.ndarray | None = None

    def boxes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Return the device rectangles the instances paint, strokes included (see :func:`_disjoint_runs`)."""
        local = np.zeros((len(self.terms), 3), dtype=complex)
        for k, t in enumerate(self.terms):
            x0, y0, x1, y1 = t.box
            local[k] = (complex(x0 + x1, y0 + y1) / 2, (x1 - x0) / 2, (y1 - y0) / 2)
        c, w, h = local[self.symbol].T
        scale = np.abs(self.a)
        u = np.where(scale > 0, self.a / np.where(scale > 0, scale, 1.0), 1.0)
        return self.a * c + self.b, u, w.real * scale, h.real * scale

    def compact_runs(self) -> list[tuple[int, int]]:
        """Return the runs worth batching: disjoint instances within few pixel rows per instance.

        Batched paths spread over many rows fill slower than their instances one by one, so
        scenes too small to gain, or whose consecutive instances are far apart vertically
        (median step over twice :data:`FULL_ROWS_PER_INSTANCE` rows) are not searched at all.
        """
        y = self.b.imag
        if y.size < 8 * FULL_MIN_RUN or np.median(np.abs(np.diff(y))) > 2 * FULL_ROWS_PER_INSTANCE:
            return []
        boxes = self.boxes()
        y = boxes[0].imag
        runs = _disjoint_runs(*boxes, FULL_MIN_RUN)
        return [(lo, hi) for lo, hi in runs if np.ptp(y[lo:hi]) <= FULL_ROWS_PER_INSTANCE * (hi - lo)]

    def one_by_one(self, positions, *, strokes_only: bool = False) -> None:
        """Draw the instances at ``positions`` in that order, each with its own matrix."""
        import skia

        table = self.stroke_ops if strokes_only else self.ops
        mats, symbols = self.mats, self.symbols
        matrix = skia.Matrix()
        set_all, set_matrix, draw_path = matrix.setAll, self.canvas.setMatrix, self.canvas.drawPath
        for k in positions:
            set_all(*mats[k])
            set_matrix(matrix)
            for path, paint in table[symbols[k]]:
                draw_path(path, paint)
        self.canvas.resetMatrix()

    def run(self, lo: int, hi: int) -> None:
        """Draw instances ``lo:hi``, which cover no pixel twice, in any order: batched where possible.

        Per terminal, the fills go into batched paths; a stroke joins them when the instances
        share one scale (stroke widths scale with the instance), else strokes of equal scale
        are batched and the others drawn one by one, as are terminals used fewer than four times.
        """
        if self._same_scale is None:  # scales equal within 1e-6 share a key
            self._same_scale = np.round(np.log2(np.maximum(np.abs(self.a), 1e-300)) * 2**20).astype(np.int64)
        sym, same = self.symbol[lo:hi], self._same_scale[lo:hi]
        order = np.lexsort((same, sym)) + lo
        sym, same = self.symbol[order], self._same_scale[order]
        change = sym[1:] != sym[:-1]
        terminal_starts = [0, *(np.flatnonzero(change) + 1).tolist(), order.size]
        scale_starts = np.flatnonzero(np.r_[True, change | (same[1:] != same[:-1]), True]).tolist()
        loose, strokes = [], []  # drawn one by one: whole instances, strokes only
        k = 0
        for t0, t1 in itertools.pairwise(terminal_starts):
            parts = []
            while scale_starts[k] < t1:
                parts.append((scale_starts[k], scale_starts[k + 1]))
                k += 1
            if t1 - t0 < 4:
                loose.append(order[t0:t1])
                continue
            term = self.terms[int(sym[t0])]
            fill = term.fill_aa if self.antialias else term.fill_noaa
            if term.paints.stroke is None:
                self.batch(term, order[t0:t1], fill, None)
                continue
            if len(parts) > 1 and fill is not None:
                self.batch(term, order[t0:t1], fill, None)
                fill = None
            for s0, s1 in parts:
                if s1 - s0 < 4:
                    strokes.append(order[s0:s1])
                    continue
                paints = term.paints
                width = paints.width * abs(self.a[order[s0]])
                self.batch(
                    term, order[s0:s1], fill, _skia_paint(paints.stroke, self.antialias, paints, width)
                )
        if loose:
            self.one_by_one(np.concatenate(loose).tolist())
        if strokes:
            self.one_by_one(np.concatenate(strokes).tolist(), strokes_only=True)

    def batch(self, term: _Terminal, positions: np.ndarray, fill, stroke) -> None:
        """Draw the terminal at ``positions`` as batched device-space paths with the given paints."""
        geo = term.geometry
        for lo in range(0, positions.size, DRAFT_CHUNK):
            part = positions[lo : lo + DRAFT_CHUNK]
            path = Renderer._batch_path(
                geo.points, geo.verbs, self.a[part], self.b[part], term.paints.evenodd
            )
            for paint in (fill, stroke):
                if paint is not None:
                    self.canvas.drawPath(path, paint)


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


def _png_size(
    drawing: Drawing, width: int | None, height: int | None, dpi: float = CSS_DPI
) -> tuple[int, int]:
    """Choose the PNG size: as given, else the document's size in its units at ``dpi``, aspect kept.

    Without ``width`` and ``height`` the size is the drawing's ``width``/``height`` converted
    from their units (``cm``, ``in``, ``pt``, … at 96 CSS px per inch) to pixels at ``dpi``;
    a missing or relative (``%``) size falls back to the viewBox size in user units.
    """
    _, _, vw, vh = default_view(drawing)
    aspect = vw / vh if vw > 0 and vh > 0 else 1.0
    if width is not None and height is not None:
        w, h = int(width), int(height)
    elif height is not None:
        h = int(height)
        w = max(1, round(h * aspect))
    elif width is not None:
        w = int(width)
        h = max(1, round(w / aspect))
    else:
        size = drawing.size
        given_w = length_px(size[0]) if size else None
        given_h = length_px(size[1]) if size else None
        if given_w is not None:
            fw, fh = given_w, given_h if given_h is not None else given_w / aspect
        elif given_h is not None:
            fw, fh = given_h * aspect, given_h
        else:
            fw, fh = vw, vh
        scale = dpi / CSS_DPI
        w, h = max(1, round(fw * scale)), max(1, round(fh * scale))
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
    dpi: float = CSS_DPI,
) -> bytes:
    """Render a drawing and return the bytes of a PNG file.

    Without ``width`` and ``height`` the drawing's ``width``/``height`` in their units
    at ``dpi`` dots per inch (96: one pixel per CSS pixel), or its viewBox size, is used;
    with one of them the other follows the aspect ratio.  Sides are capped at
    :data:`MAX_SIDE` and the image at :data:`MAX_PNG_PIXELS` pixels (scaled down, aspect
    ratio kept), so an absurd canvas size cannot exhaust memory.

    Raises
    ------
    LsysError
        When the image cannot be encoded, or skia cannot be loaded (naming the missing
        system library).
    """
    skia = load_skia()
    if not (math.isfinite(dpi) and dpi > 0):
        raise LsysError(f"the resolution must be a positive number of dots per inch, got {dpi}")
    w, h = _png_size(drawing, width, height, dpi)
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
    dpi: float = CSS_DPI,
) -> None:
    """Render a drawing and write it as a PNG file atomically (see :func:`encode_png`)."""
    try:
        data = encode_png(drawing, width, height, background=background, dpi=dpi)
    except LsysError as exc:
        raise LsysError(f"cannot write {path}: {exc}") from exc
    write_atomic(path, data)
