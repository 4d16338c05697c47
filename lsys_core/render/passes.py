"""Drawing passes of :mod:`lsys_core.render.raster`: per-terminal skia objects and the full-mode pass.

:class:`_Terminal` holds one (path, style) pair's skia path and paints; :class:`_FullPass`
draws culled instances in order, one by one or as batched paths where runs of instances
cover no pixel twice (see the notes of :mod:`lsys_core.render.raster`).  Stroke widths of a
style are in canvas units: each instance strokes ``width * sscale`` of its local frame
(:meth:`~lsys_core.derive.model.Drawing.stroke_scale`).  skia is imported inside the functions.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from lsys_core.render.paths import (
    _BUCKETS_PER_OCTAVE,
    _disjoint_runs,
    _flatten,
    _Geometry,
    _groups,
    _Paints,
    _path_from_xy,
    _skia_paint,
)

#: Colour of highlighted instances (RGBA).
HIGHLIGHT = (255, 111, 0, 255)
#: Translucent fill of highlighted instances (RGBA): the highlight at half opacity.
HIGHLIGHT_FILL = (255, 111, 0, 127)
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


def batch_path(points: np.ndarray, verbs: np.ndarray, a: np.ndarray, b: np.ndarray, evenodd: bool):
    """Return one path of the outline ``points``/``verbs`` placed at every pose ``z -> a z + b``."""
    pts = a[:, None] * points[None, :] + b[:, None]  # complex (instances, points)
    xy = pts.view(np.float64).astype(np.float32).reshape(-1, 2)
    return _path_from_xy(xy, np.tile(verbs, a.size), evenodd)


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


class _FullPass:
    """One full-mode drawing of instances (already culled) into a canvas, in their order."""

    def __init__(self, canvas, terms: list[_Terminal], symbol, a, b, antialias: bool, sscale=None) -> None:
        self.canvas, self.terms, self.antialias = canvas, terms, antialias
        self.symbol, self.a, self.b = symbol, a, b
        self.sscale = np.ones(a.size) if sscale is None else np.asarray(sscale, float)
        self.sscales = self.sscale.tolist()
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
        widths = [t.paints.width if t.paints.stroke is not None else None for t in self.terms]
        mats, symbols, sscales = self.mats, self.symbols, self.sscales
        matrix = skia.Matrix()
        # The identity, then the instance's matrix: concat takes a Matrix at once, where
        # setMatrix first tries its M44 overload (1 µs a call: 9 ms of 10,000 instances' 90).
        canvas = self.canvas
        set_all, reset, concat, draw_path = matrix.setAll, canvas.resetMatrix, canvas.concat, canvas.drawPath
        for k in positions:
            set_all(*mats[k])
            reset()
            concat(matrix)
            t = symbols[k]
            ops = table[t]
            if widths[t] is not None and sscales[k] != 1.0:  # canvas-unit stroke: the local width
                ops[-1][1].setStrokeWidth(widths[t] * sscales[k])
                for path, paint in ops:
                    draw_path(path, paint)
                ops[-1][1].setStrokeWidth(widths[t])
                continue
            for path, paint in ops:
                draw_path(path, paint)
        self.canvas.resetMatrix()

    def run(self, lo: int, hi: int) -> None:
        """Draw instances ``lo:hi``, which cover no pixel twice, in any order: batched where possible.

        Per terminal, the fills go into batched paths; a stroke joins them when the instances
        share one scale (stroke widths scale with the instance), else strokes of equal scale
        are batched and the others drawn one by one, as are terminals used fewer than four times.
        """
        if self._same_scale is None:  # stroke widths in pixels equal within 1e-6 share a key
            px = np.abs(self.a) * self.sscale
            self._same_scale = np.round(np.log2(np.maximum(px, 1e-300)) * 2**20).astype(np.int64)
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
                width = paints.width * abs(self.a[order[s0]]) * self.sscale[order[s0]]
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
            path = batch_path(geo.points, geo.verbs, self.a[part], self.b[part], term.paints.evenodd)
            for paint in (fill, stroke):
                if paint is not None:
                    self.canvas.drawPath(path, paint)


def _draft_batches(terms, symbol, da, db, sscale, idx):
    """Yield ``(term, stroke_px, path)``: instances ``idx`` per terminal and scale bucket, chunked.

    Each path is the draft outline (curves flattened for the bucket's largest scale) placed at
    up to :data:`DRAFT_CHUNK` instances; ``stroke_px`` is the median device width of a unit
    stroke in the bucket (one width per bucket: within a quarter octave of every instance's).
    """
    scale = np.abs(da[idx])
    bucket = np.round(np.log2(np.maximum(scale, 1e-30)) * _BUCKETS_PER_OCTAVE).astype(np.int64)
    sym = symbol[idx]
    for group in _groups(sym, bucket):
        term = terms[int(sym[group[0]])]
        points, verbs = term.flattened(int(bucket[group[0]]))
        inst = idx[group]
        stroke_px = float(np.median(scale[group] * sscale[inst]))
        for lo in range(0, inst.size, DRAFT_CHUNK):
            part = inst[lo : lo + DRAFT_CHUNK]
            yield term, stroke_px, batch_path(points, verbs, da[part], db[part], term.paints.evenodd)


def draw_draft(canvas, terms, symbol, da, db, sscale, visible, highlight=None) -> None:
    """Draft: per terminal and scale bucket, chunks of instances drawn as one path each.

    Instances in the ``highlight`` mask (None: none) are drawn after the others, each in one
    pass that looks like the draft plus :func:`draw_highlight` on top: their fill already
    blended with the translucent highlight, the highlight's hairline outline instead of a
    hairline stroke (it covers the same pixels).  Measured on 10,000 highlighted leaves, the
    separate highlight pass made a draft frame take 16–28 ms instead of 10–12 ms.
    """
    plain = visible if highlight is None else visible & ~highlight
    idx = np.flatnonzero(plain)
    for term, stroke_px, path in _draft_batches(terms, symbol, da, db, sscale, idx):
        paints = term.paints
        if term.fill_noaa is not None:
            canvas.drawPath(path, term.fill_noaa)
        if paints.stroke is not None:
            width = _draft_width(paints, stroke_px)
            canvas.drawPath(path, _skia_paint(paints.stroke, False, paints, width))
    if highlight is None:
        return
    idx = np.flatnonzero(visible & highlight & (symbol < len(terms)))
    outline = _highlight_paints(False, True)[1]
    for term, stroke_px, path in _draft_batches(terms, symbol, da, db, sscale, idx):
        paints = term.paints
        if paints.fill is not None:
            canvas.drawPath(path, _skia_paint(over(HIGHLIGHT_FILL, paints.fill), False))
        if paints.stroke is not None:
            width = _draft_width(paints, stroke_px)
            if width > 0.0:  # a hairline stroke is what the outline covers anyway
                canvas.drawPath(path, _skia_paint(paints.stroke, False, paints, width))
        canvas.drawPath(path, outline)


def _draft_width(paints: _Paints, stroke_px: float) -> float:
    """The draft's stroke width in pixels: 0 (a hairline, far cheaper) under :data:`DRAFT_HAIRLINE`."""
    width = paints.width * stroke_px
    return 0.0 if width < DRAFT_HAIRLINE else width


def over(top: tuple[int, int, int, int], under: tuple[int, int, int, int]) -> tuple[int, int, int, int]:
    """Return the one straight RGBA colour that paints like ``under`` then ``top`` (source over)."""
    ta, ua = top[3] / 255.0, under[3] / 255.0
    alpha = ta + ua * (1.0 - ta)
    if alpha <= 0.0:
        return (0, 0, 0, 0)
    rgb = ((t * ta + u * ua * (1.0 - ta)) / alpha for t, u in zip(top[:3], under[:3], strict=True))
    r, g, b = (min(255, max(0, round(c))) for c in rgb)
    return (r, g, b, min(255, round(alpha * 255.0)))


def _highlight_paints(antialias: bool, draft: bool):
    """The highlight's translucent fill and its outline (a hairline in drafts, else 1.5 pixels)."""
    r, g, b, a = HIGHLIGHT
    width = 0.0 if draft else 1.5
    fill = _skia_paint(HIGHLIGHT_FILL, antialias)
    stroke = _Paints(None, None, width, "round", "round", 4.0, False)
    return fill, _skia_paint((r, g, b, a), antialias, stroke, width)


def highlight_mask(highlight: np.ndarray, n: int) -> np.ndarray:
    """Return the boolean mask of ``n`` instances that ``highlight`` (indices or mask) selects."""
    mask = np.zeros(n, dtype=bool)
    hl = np.asarray(highlight).reshape(-1)
    if hl.dtype == bool:
        mask[: min(n, hl.size)] = hl[:n]
    else:
        hl = hl.astype(np.intp)
        mask[hl[(hl >= 0) & (hl < n)]] = True
    return mask


def draw_highlight(canvas, terms, symbol, da, db, mask, antialias: bool) -> None:
    """Draw the selected instances on top in the :data:`HIGHLIGHT` colour (full mode).

    Filled terminals get a translucent fill, every one a 1.5-pixel outline (drafts draw their
    highlighted instances in :func:`draw_draft`).
    """
    fill, outline = _highlight_paints(antialias, False)
    for t, term in enumerate(terms):
        sel = np.flatnonzero(mask & (symbol == t))
        if sel.size == 0:
            continue
        geo = term.geometry
        path = batch_path(geo.points, geo.verbs, da[sel], db[sel], term.paints.evenodd)
        if term.paints.fill is not None:
            canvas.drawPath(path, fill)
        canvas.drawPath(path, outline)
