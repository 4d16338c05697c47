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
the instance order (within a group, chunks are drawn in instance order).  Small opaque
instances are not drawn as paths but stamped as sprites, over the paths (:mod:`.sprites`:
10,000 leaves of ~6 pixels in 2–3 ms instead of 7–9 ms), and highlighted instances are drawn
last, highlighted in the same pass.

Content kept as is (text, images) and instances painted by gradients are drawn at their
places in the paint order in full mode (:mod:`lsys_core.render.kept`, :mod:`.served`); in
draft mode, what comes before every instance is drawn under them and the rest on top.

skia is imported inside the functions that use it.
"""

from __future__ import annotations

import math
import os

import numpy as np

from lsys_core.derive.model import Drawing
from lsys_core.errors import LsysError
from lsys_core.io import write_atomic
from lsys_core.render.kept import Kept
from lsys_core.render.passes import (
    DRAFT_CHUNK,
    DRAFT_HAIRLINE,
    DRAFT_TOLERANCE,
    FULL_MIN_RUN,
    FULL_ROWS_PER_INSTANCE,
    HIGHLIGHT,
    _FullPass,
    _painted_box,
    _Terminal,
    batch_path,
    draw_draft,
    draw_highlight,
    highlight_mask,
)
from lsys_core.render.paths import (
    _geometry,
    _paints,
    _path_from_arrays,
    _skia_paint,
    parse_style,
)
from lsys_core.render.sizing import default_view, fit_view, png_size
from lsys_core.render.skia_import import load_skia
from lsys_core.render.sprites import Sprites
from lsys_core.render.units import CSS_DPI

__all__ = [
    "DRAFT_CHUNK",
    "DRAFT_TOLERANCE",
    "FULL_MIN_RUN",
    "FULL_ROWS_PER_INSTANCE",
    "HIGHLIGHT",
    "MAX_PNG_PIXELS",
    "Renderer",
    "default_view",
    "encode_png",
    "fit_view",
    "parse_style",
    "render",
    "render_png",
]

#: Most terminals (path, style) whose skia objects a renderer keeps.
CACHE_SIZE = 4096
#: Largest image side accepted, in pixels.
MAX_SIDE = 16384
#: Most pixels of a PNG written by :func:`render_png` (larger sizes are scaled down, aspect kept).
MAX_PNG_PIXELS = 40_000_000


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
        self._sprites = Sprites()
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
        kept = Kept(drawing, self._terminal)
        if n == 0 and not kept:
            return self._pixels
        s, tx, ty = fit_view(view if view is not None else default_view(drawing), width, height)
        if n == 0:
            kept.draw(canvas, None, (s, tx, ty))
            return self._pixels
        symbol, terms = self._pairs(drawing)
        sscale = drawing.stroke_scale()
        pa = np.asarray(drawing.a, dtype=complex).reshape(n)
        pb = np.asarray(drawing.b, dtype=complex).reshape(n)
        # Device frame of every instance: view ∘ pose (non-finite ones are culled below).
        with np.errstate(invalid="ignore", over="ignore"):
            da = s * pa
            db = s * pb + complex(tx, ty)
        visible = self._visible(terms, symbol, da, db, sscale, width, height)
        visible[kept.served] = False  # gradient-painted: drawn by kept, at their places
        mask = None if highlight is None else highlight_mask(highlight, n)
        if draft:  # kept content placed before every instance goes under them, the rest on top
            kept.draw(canvas, np.flatnonzero(kept.orders == 0).tolist(), (s, tx, ty))
            stamp = self._sprites.plan(
                terms, symbol, da, db, sscale, np.flatnonzero(visible), mask, DRAFT_HAIRLINE
            )
            self._draw_batched(
                terms, symbol, da, db, sscale, visible & ~stamp.mask if stamp else visible, mask
            )
            if stamp is not None:  # small instances, over the paths
                stamp.apply(self._pixels)
            kept.draw(canvas, np.flatnonzero(kept.orders > 0).tolist(), (s, tx, ty))
        else:
            self._draw_each(terms, symbol, da, db, sscale, visible, antialias, kept, (s, tx, ty))
            if mask is not None:
                self._draw_highlight(terms, symbol, da, db, visible & mask, antialias)
        canvas.resetMatrix()
        return self._pixels

    def _pairs(self, drawing: Drawing) -> tuple[np.ndarray, list[_Terminal]]:
        """Return each instance's index into the distinct (terminal, style) pairs, and their skia objects.

        An instance with a terminal index out of range gets the index ``len(pairs)`` (not drawn).
        """
        n = len(drawing)
        symbol = np.asarray(drawing.symbol, dtype=np.intp).reshape(n)
        styles, style = drawing.instance_styles()
        bad = (symbol < 0) | (symbol >= len(drawing.terminals)) | (style < 0) | (style >= len(styles))
        key = np.where(bad, -1, symbol * max(len(styles), 1) + style)
        uniq, pair = np.unique(key, return_inverse=True)
        pair = pair.reshape(-1)
        terms = []
        for k in uniq.tolist():
            if k >= 0:
                t, s = divmod(k, max(len(styles), 1))
                terms.append(self._terminal(drawing.terminals[t].path, styles[s]))
        if uniq.size and uniq[0] < 0:
            pair = np.where(pair == 0, len(terms), pair - 1)
        return pair, terms

    @staticmethod
    def _visible(terms, symbol, da, db, sscale, width, height) -> np.ndarray:
        """Return a mask of instances whose bounding disc meets the image."""
        radius = np.array([t.geometry.radius for t in terms] + [0.0])
        half = np.array([t.paints.width / 2 if t.paints.stroke else 0.0 for t in terms] + [0.0])
        empty = np.array([t.geometry.verbs.size == 0 for t in terms] + [True])
        sym = np.where((symbol >= 0) & (symbol < len(terms)), symbol, len(terms))  # bad index: not drawn
        with np.errstate(invalid="ignore", over="ignore"):
            rr = (radius[sym] + half[sym] * sscale) * np.abs(da) + 1.0
            x, y = db.real, db.imag
            ok = (x + rr >= 0) & (x - rr <= width) & (y + rr >= 0) & (y - rr <= height)
        return ok & ~empty[sym] & np.isfinite(rr) & np.isfinite(db)

    def _draw_each(self, terms, symbol, da, db, sscale, visible, antialias: bool, kept, view) -> None:
        """Draw the visible instances in order: one by one, or in batches where that is the same.

        Runs of at least :data:`FULL_MIN_RUN` consecutive instances whose painted rectangles
        are pairwise disjoint cover no pixel twice (except anti-aliased edge pixels of touching
        instances), so drawing them terminal by terminal as batched paths gives the same picture
        (such shared edge pixels blend as in one shape, without a seam); the rest is drawn one
        by one, each instance with its own matrix.  Kept content (text, images) is drawn at
        its place among them (:class:`~lsys_core.render.kept.Kept`).
        """
        idx = np.flatnonzero(visible)
        full = _FullPass(self._canvas, terms, symbol[idx], da[idx], db[idx], antialias, sscale[idx])
        runs = full.compact_runs() if idx.size else []
        for kind, lo, hi, items in kept.steps(idx, runs):
            if kind == "each":
                full.one_by_one(range(lo, hi))
            elif kind == "run":
                full.run(lo, hi)
            else:
                kept.draw(self._canvas, items, view)

    def _draw_batched(self, terms, symbol, da, db, sscale, visible, highlight=None) -> None:
        """Draft: per terminal and scale bucket, chunks of instances drawn as one path each
        (the ``highlight`` mask's instances last, highlighted)."""
        self._canvas.resetMatrix()
        draw_draft(self._canvas, terms, symbol, da, db, sscale, visible, highlight)

    _batch_path = staticmethod(batch_path)

    def _draw_highlight(self, terms, symbol, da, db, mask, antialias: bool) -> None:
        """Draw the selected instances on top in the highlight colour (full mode)."""
        self._canvas.resetMatrix()
        draw_highlight(self._canvas, terms, symbol, da, db, mask, antialias)


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
    w, h = png_size(drawing, width, height, dpi, MAX_SIDE, MAX_PNG_PIXELS)
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
