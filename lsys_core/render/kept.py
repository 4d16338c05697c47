"""Content kept as is (``<text>``, ``<image>``) drawn by the own renderer, in paint order with the instances.

A drawing's :attr:`~lsys_core.derive.model.Drawing.verbatim` items are self-contained SVG
fragments in document coordinates (styles baked in by the reader, ancestors' transforms and
inherited properties on a wrapping ``<g>``), each placed after the ``order`` first instances.
:class:`Kept` says where they go among the instances drawn, and draws each one from a skia
picture recorded once per fragment (:func:`_picture`, cached), under the view's matrix.

What a fragment draws here: ``<g>``, ``<a>`` and ``<switch>`` (its first child) groups with
their transforms (attribute or CSS property) and group ``opacity``; ``<text>`` with
``<tspan>``, ``<a>`` and ``<textPath>`` (:mod:`.kept_text`), filled and stroked in solid
colours or gradients (:mod:`.paint_servers`, over the whole text's box) in their ``paint-order``; ``<image>`` from a ``data:`` URI (PNG, JPEG, GIF, WebP,
BMP, ICO) with ``x``/``y``/``width``/``height`` (``auto``: the image's own size) and
``preserveAspectRatio``, sampled linearly (nearest for ``image-rendering: pixelated``,
``optimizeSpeed`` or ``crisp-edges``).  An image's ``href`` to anything but a ``data:`` URI is
never fetched, read or drawn, by design (a drawing must not make the renderer open files or
reach the network).  Clip paths apply (:mod:`.clipping`; ``objectBoundingBox`` units on text
and sized images only).  Not drawn: patterns on text (their fallback colour if given), masks
and filters on kept content, SVG images, and shapes kept as is.

Why not skia's SVG module (``skia.SVGDOM``) fed the fragment: measured with skia-python
144.1, it draws neither text (a ``<text>`` of 30-px glyphs: 0 pixels inked, the ``<rect>``
beside it 2,500) nor ``<image>`` with a ``data:`` URI (0 pixels): the bindings give it no
font manager and no resource provider.  It would also ignore the ``transform`` CSS property
the reader writes.  So the text is laid out here with skia fonts, matched by family through
fontconfig, the font manager skia uses on Linux as librsvg does through pango, so the same
family gives the same face.  On the real-art charts this takes the own renderer from 2.53 %
and 3.81 % of inked pixels differing to the rsvg-like figures listed in the benchmark.
"""

from __future__ import annotations

import base64
import binascii
import math
import urllib.parse
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from functools import cached_property, lru_cache
from typing import Any

import numpy as np

from lsys_core.derive.model import Drawing
from lsys_core.render.clipping import clip_region
from lsys_core.render.kept_style import computed, group_opacity, lengths, shape_paints, transform_of
from lsys_core.render.kept_text import layout_text
from lsys_core.render.paint_servers import defs_index, gradient_shader, parse_fragment
from lsys_core.render.served import draw_served, served_instances
from lsys_core.render.sizing import default_view
from lsys_core.svg.tree import href_of, local_name
from lsys_core.svg.values import Matrix, viewbox_transform

__all__ = ["Kept"]

#: Most kept fragments whose recorded pictures are kept between draws.
PICTURE_CACHE = 512
#: Largest ``data:`` URI decoded for an ``<image>`` (characters), and largest image (pixels).
MAX_IMAGE_URI = 64 * 2**20
MAX_IMAGE_PIXELS = 50_000_000
#: Deepest nesting of groups drawn in a fragment.
MAX_DEPTH = 64
_GROUPS = {"g", "a", "switch"}
_NEAREST = {"pixelated", "optimizespeed", "crisp-edges"}
_BIG = 1e9


class Kept:
    """A drawing's kept content, and its instances painted by gradients: where they go among the
    other instances, and drawing them.

    Kept items go after the ``order`` first instances (those with the same ``order`` in
    document order); an instance painted by a gradient (:mod:`.served`) goes at its own place,
    after the kept items placed before it.  Without ``terminal`` (the renderer's cache of
    terminal paths), there are no such instances: all are drawn by the renderer's passes.
    """

    def __init__(self, drawing: Drawing, terminal: Callable[[str, str], Any] | None = None) -> None:
        n = len(drawing)
        kept = np.array([min(max(int(v.order), 0), n) for v in drawing.verbatim], dtype=np.intp)
        served = served_instances(drawing) if terminal is not None else np.zeros(0, np.intp)
        orders = np.concatenate([kept, served])
        kind = np.r_[np.zeros(kept.size, np.intp), np.ones(served.size, np.intp)]
        perm = np.lexsort((np.arange(orders.size), kind, orders))
        self.orders = orders[perm]
        #: What each item is: verbatim markup, or the index of an instance painted by a gradient.
        self.refs: list[str | int] = [
            drawing.verbatim[k].xml if k < kept.size else int(served[k - kept.size]) for k in perm.tolist()
        ]
        self.served = served
        self.drawing, self.terminal, self.defs = drawing, terminal, drawing.defs
        self._styles: tuple[tuple[str, ...], np.ndarray] | None = None

    @cached_property
    def viewport(self) -> tuple[float, float]:
        """The size percentages refer to: the drawing's viewBox or bounds.

        Computed when first needed: the bounds of 10,000 instances took ~4 ms of every frame,
        and most frames draw no kept item.
        """
        _, _, w, h = default_view(self.drawing)
        return (float(w), float(h))

    def __bool__(self) -> bool:
        return bool(self.refs)

    def steps(
        self, idx: np.ndarray, runs: list[tuple[int, int]]
    ) -> Iterator[tuple[str, int, int, list[int]]]:
        """Order the drawing of the instances ``idx`` (ascending) and the kept items.

        Yields ``("each", lo, hi, [])`` (positions ``lo:hi`` of ``idx`` one by one), ``("run", lo,
        hi, [])`` (a part of one of the batchable ``runs``) and ``("kept", p, p, items)`` (kept
        items drawn after the first ``p`` positions).
        """
        pos = np.searchsorted(idx, self.orders, side="left").tolist()
        cuts: dict[int, list[int]] = {}
        for k, p in enumerate(pos):
            cuts.setdefault(int(p), []).append(k)
        done = 0
        for p in sorted({*cuts, int(idx.size)}):
            for lo, hi in runs:
                lo, hi = max(lo, done), min(hi, p)
                if lo < hi:
                    if done < lo:
                        yield "each", done, lo, []
                    yield "run", lo, hi, []
                    done = hi
            if done < p:
                yield "each", done, p, []
                done = p
            if p in cuts:
                yield "kept", p, p, cuts[p]

    def _served(self, canvas, i: int, view: tuple[float, float, float]) -> None:
        """Draw instance ``i``, painted by a gradient (see :mod:`.served`)."""
        assert self.terminal is not None
        if self._styles is None:
            self._styles = self.drawing.instance_styles()
        styles, style = self._styles
        d, sym, k = self.drawing, int(self.drawing.symbol[i]), int(style[i])
        if 0 <= sym < len(d.terminals) and 0 <= k < len(styles):
            a, b = complex(d.a[i]), complex(d.b[i])
            draw_served(
                canvas, d.terminals[sym], styles[k], a, b, self.terminal, self.defs, self.viewport, view
            )

    def draw(self, canvas, items: list[int] | None, view: tuple[float, float, float]) -> None:
        """Draw the ``items`` (all: None) under the view ``(scale, tx, ty)``."""
        import skia

        s, tx, ty = view
        for k in range(len(self.refs)) if items is None else items:
            ref = self.refs[k]
            if isinstance(ref, int):
                if self.terminal is not None:
                    self._served(canvas, ref, view)
                continue
            picture = _picture(ref, self.defs, self.viewport)
            if picture is None:
                continue
            canvas.save()
            canvas.setMatrix(skia.Matrix.MakeAll(s, 0, tx, 0, s, ty, 0, 0, 1))
            canvas.drawPicture(picture)
            canvas.restore()


@lru_cache(maxsize=PICTURE_CACHE)
def _picture(markup: str, defs: str, viewport: tuple[float, float]):
    """Record what a kept fragment draws, in document coordinates (None: nothing to draw)."""
    import skia

    root = parse_fragment(markup)
    if root is None:
        return None
    local: dict[str, ET.Element] = {}

    def find(ident: str) -> ET.Element | None:
        if "" not in local:  # built on first use: the fragment's ids, then the definitions'
            for node in root.iter():
                local.setdefault(node.get("id") or "", node)
            local[""] = root
        if not ident:
            return None
        found = local.get(ident)
        return found if found is not None else defs_index(defs).get(ident)

    recorder = skia.PictureRecorder()
    canvas = recorder.beginRecording(skia.Rect.MakeLTRB(-_BIG, -_BIG, _BIG, _BIG))
    painter = _Painter(canvas, find, viewport)
    for el in root:
        painter.element(el, {}, 0)
    return recorder.finishRecordingAsPicture()


def _skia_matrix(m: Matrix):
    import skia

    a, b, c, d, e, f = m
    return skia.Matrix.MakeAll(a, c, e, b, d, f, 0, 0, 1)


class _Painter:
    """Draws the elements of one fragment into a (recording) canvas."""

    def __init__(
        self, canvas, find: Callable[[str], ET.Element | None], viewport: tuple[float, float]
    ) -> None:
        self.canvas, self.find, self.viewport = canvas, find, viewport

    def element(self, el: ET.Element, parent: dict[str, str], depth: int) -> None:
        import skia

        tag = local_name(el.tag)
        if (tag not in _GROUPS and tag not in ("text", "image")) or depth > MAX_DEPTH:
            return
        style = computed(parent, el)
        if style.get("display", "").strip().lower() == "none":
            return
        m = transform_of(el, style)
        alpha = group_opacity(style)
        if m is None or not all(math.isfinite(v) for v in m) or alpha <= 0.0:
            return
        canvas = self.canvas
        canvas.save()
        canvas.concat(_skia_matrix(m))
        runs, box = layout_text(el, style, self.find, self.viewport) if tag == "text" else ([], None)
        bbox = box or (0.0, 0.0, 0.0, 0.0)
        clip = style.get("clip-path", "")
        if "url(" in clip:
            known = bbox if tag == "text" else self._image_box(el, style) if tag == "image" else None
            region = clip_region(clip, self.find, known, self.viewport)
            if region is not None:
                canvas.clipPath(region, skia.ClipOp.kIntersect, True)
        if alpha < 1.0:
            canvas.saveLayerAlpha(None, round(alpha * 255))
        if tag == "text":

            def servers(value: str) -> Any:
                return gradient_shader(value, self.find, bbox, self.viewport)

            for run in runs:
                for paint in shape_paints(run.style, True, servers, self.viewport):
                    canvas.drawPath(run.path, paint)
        elif tag == "image":
            self.image(el, style)
        else:
            children = [c for c in el if local_name(c.tag) is not None]
            for child in children[:1] if tag == "switch" else children:
                self.element(child, style, depth + 1)
        if alpha < 1.0:
            canvas.restore()
        canvas.restore()

    def _length(self, el: ET.Element, key: str, style: dict[str, str]) -> float | None:
        """One length attribute in user units (None: missing, ``auto`` or unreadable)."""
        values = lengths(el.get(key), style, self.viewport, "y" if key in ("y", "height") else "x")
        return values[0] if values else None

    def _image_box(self, el: ET.Element, style: dict[str, str]) -> tuple[float, float, float, float] | None:
        """An image's box when its width and height are given (None: they depend on the image)."""
        x, y, w, h = (self._length(el, k, style) for k in ("x", "y", "width", "height"))
        if w is None or h is None:
            return None
        return (x or 0.0, y or 0.0, (x or 0.0) + w, (y or 0.0) + h)

    def image(self, el: ET.Element, style: dict[str, str]) -> None:
        """Draw an ``<image>`` whose ``href`` is a ``data:`` URI (nothing else is ever fetched)."""
        import skia

        image = _decode(href_of(el) or "")
        if image is None:
            return
        iw, ih = float(image.width()), float(image.height())
        x, y, w, h = (self._length(el, k, style) for k in ("x", "y", "width", "height"))
        x, y = x or 0.0, y or 0.0
        if w is None and h is None:
            w, h = iw, ih
        elif w is None:
            w = iw * h / ih  # type: ignore[operator]
        elif h is None:
            h = ih * w / iw
        assert w is not None and h is not None
        if not (w > 0 and h > 0 and math.isfinite(w) and math.isfinite(h)):
            return
        m = viewbox_transform((0.0, 0.0, iw, ih), x, y, w, h, el.get("preserveAspectRatio"))
        mode = style.get("image-rendering", "auto").strip().lower()
        sampling = skia.SamplingOptions(
            skia.FilterMode.kNearest if mode in _NEAREST else skia.FilterMode.kLinear, skia.MipmapMode.kLinear
        )
        paint = skia.Paint()
        paint.setAntiAlias(True)
        canvas = self.canvas
        canvas.save()
        canvas.clipRect(skia.Rect.MakeXYWH(x, y, w, h), True)
        canvas.concat(_skia_matrix(m))
        canvas.drawImage(image, 0, 0, sampling, paint)
        canvas.restore()


def _decode(href: str):
    """Decode the image of a ``data:`` URI with skia (None: not a data URI, too big, or unreadable)."""
    import skia

    if href[:5].lower() != "data:" or len(href) > MAX_IMAGE_URI:
        return None
    head, sep, data = href[5:].partition(",")
    if not sep:
        return None
    try:
        if head.strip().lower().endswith(";base64"):
            raw = base64.b64decode("".join(urllib.parse.unquote(data).split()), validate=False)
        else:
            raw = urllib.parse.unquote_to_bytes(data)
    except (binascii.Error, ValueError):
        return None
    image = skia.Image.MakeFromEncoded(skia.Data.MakeWithCopy(raw))
    if image is None or image.width() <= 0 or image.height() <= 0:
        return None
    if image.width() * image.height() > MAX_IMAGE_PIXELS:
        return None
    return image
