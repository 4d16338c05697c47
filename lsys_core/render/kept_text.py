"""SVG text layout for the own renderer: ``<text>``, ``<tspan>`` and ``<textPath>`` as glyph outlines.

The layout follows SVG's text model for horizontal, left-to-right text without line breaking:

* white space as ``xml:space="default"`` says (newlines removed, tabs to spaces, runs of
  spaces collapsed across elements, leading and trailing spaces dropped; ``preserve`` and
  ``white-space: pre`` keep them as spaces);
* ``x``/``y``/``dx``/``dy``/``rotate`` lists give characters their positions, the innermost
  element with a value for a character winning (``rotate``'s last value repeats);
* every absolute ``x`` or ``y`` starts a text chunk, which ``text-anchor`` aligns;
* ``dominant-baseline``/``alignment-baseline`` (middle, central, hanging, text-top/bottom and
  the before/after edges) move the baseline by the font's metrics;
* ``letter-spacing``, ``word-spacing`` and the font's kerning pairs (unless
  ``font-kerning: none``; as in librsvg, not across the boundary of a ``<tspan>``) adjust
  the advances;
* a ``<textPath>``'s characters go along its path (``href`` to a path of the document's
  definitions, or SVG 2's ``path``), from ``startOffset``, each glyph turned to the tangent at
  its middle; glyphs beyond the path's end are not drawn.

Fonts: the face fontconfig matches for the ``font-family`` list, weight and slant, as librsvg
gets through pango (:mod:`.fonts`); a character missing from it is drawn from a face that has it.  Outlines and advances are
taken unhinted at :data:`_UNIT` and scaled, so the text scales like any other shape.  Not
drawn: ``text-decoration``, vertical and right-to-left text, shaping (ligatures, complex scripts).
"""

from __future__ import annotations

import itertools
import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

from lsys_core.render.fonts import typeface
from lsys_core.render.kept_style import computed, font_px, lengths
from lsys_core.svg.tree import href_of, local_name
from lsys_core.svg.values import parse_length, parse_number, parse_transform

__all__ = ["TextRun", "layout_text"]

#: Font size at which glyph outlines and advances are taken (then scaled linearly).
_UNIT = 64.0
_XML_SPACE = "{http://www.w3.org/XML/1998/namespace}space"
_CONTENT = {"tspan", "textPath", "a"}
_ATTRS = ("x", "y", "dx", "dy", "rotate")
#: The family of text that names none (librsvg's initial value; fontconfig binds it to a serif face).
INITIAL_FONT_FAMILY = "Times New Roman"


@dataclass(frozen=True)
class TextRun:
    """Glyph outlines of consecutive characters of one element, in the text's user space."""

    path: Any  # skia.Path
    style: Mapping[str, str]


class _Face:
    """One typeface at :data:`_UNIT`: glyph ids, advances, outlines and kerning, cached."""

    def __init__(self, typeface, embolden: bool = False) -> None:
        import skia

        self.typeface = typeface
        self.font = skia.Font(typeface, _UNIT)
        self.font.setEmbolden(embolden)
        self.font.setHinting(skia.FontHinting.kNone)
        self.font.setLinearMetrics(True)
        self.font.setSubpixel(True)
        self.upem = max(1, typeface.getUnitsPerEm())
        self.metrics = self.font.getMetrics()
        self._advance: dict[int, float] = {}
        self._path: dict[int, object] = {}

    def glyph(self, ch: str) -> int:
        return int(self.font.unicharToGlyph(ord(ch)))

    def advance(self, glyph: int) -> float:
        if glyph not in self._advance:
            self._advance[glyph] = float(self.font.getWidths([glyph])[0])
        return self._advance[glyph]

    def outline(self, glyph: int):
        if glyph not in self._path:
            self._path[glyph] = self.font.getPath(glyph)
        return self._path[glyph]

    def kerning(self, first: int, second: int) -> float:
        adj = self.typeface.getKerningPairAdjustments([first, second])
        return float(adj[0]) * _UNIT / self.upem if adj else 0.0


@lru_cache(maxsize=256)
def _face(family: str, weight: int, italic: bool) -> _Face:
    """The face fontconfig gives for a ``font-family`` list (see :mod:`.fonts`)."""
    return _Face(*typeface(family, weight, italic))


@lru_cache(maxsize=1024)
def _fallback(ch: str, weight: int, italic: bool) -> _Face | None:
    """A face that has ``ch`` (for characters the requested face lacks), or None."""
    import skia

    slant = skia.FontStyle.kItalic_Slant if italic else skia.FontStyle.kUpright_Slant
    style = skia.FontStyle(weight, skia.FontStyle.kNormal_Width, slant)
    typeface = skia.FontMgr.RefDefault().matchFamilyStyleCharacter("", style, [], ord(ch))
    return _Face(typeface) if typeface is not None else None


def _weight(text: str) -> int:
    t = text.strip().lower()
    if t in ("bold", "bolder"):
        return 700
    if t == "lighter":
        return 300
    v = parse_number(t)
    return int(min(max(v, 1.0), 1000.0)) if v is not None else 400


def _face_of(style: Mapping[str, str]) -> _Face:
    italic = style.get("font-style", "normal").strip().lower() in ("italic", "oblique")
    family = style.get("font-family", INITIAL_FONT_FAMILY)
    return _face(family, _weight(style.get("font-weight", "normal")), italic)


@dataclass
class _Char:
    ch: str
    stack: tuple[int, ...]  # indices of the elements the character is in, outermost first
    span: int  # the piece of character data it comes from (kerning stays within one)
    face: _Face | None = None
    glyph: int = 0
    size: float = 0.0
    advance: float = 0.0
    x: float = 0.0
    y: float = 0.0
    rotate: float = 0.0
    new_chunk: bool = False


@dataclass
class _Element:
    el: ET.Element
    style: dict[str, str]
    lists: dict[str, list[float] | None]
    count: int = 0


class _Collector:
    """The characters of a ``<text>`` after white-space handling, with the elements they are in."""

    def __init__(self, viewport: tuple[float, float]) -> None:
        self.viewport = viewport
        self.elements: list[_Element] = []
        self.chars: list[_Char] = []
        self.spans = 0

    def visit(self, el: ET.Element, style: dict[str, str], stack: tuple[int, ...], preserve: bool) -> None:
        if style.get("display", "").strip().lower() == "none":
            return
        lists = {}
        if local_name(el.tag) != "textPath":
            axes = {"x": "x", "dx": "x", "y": "y", "dy": "y"}
            lists = {k: lengths(el.get(k), style, self.viewport, axes.get(k, "o")) for k in _ATTRS}
        self.elements.append(_Element(el, style, lists))
        stack = (*stack, len(self.elements) - 1)
        space = el.get(_XML_SPACE)
        preserve = space == "preserve" if space else preserve
        pre = preserve or style.get("white-space", "").strip().lower() in ("pre", "pre-wrap", "break-spaces")
        self.add(el.text, stack, pre)
        for child in el:
            if local_name(child.tag) in _CONTENT:
                self.visit(child, computed(style, child), stack, preserve)
            self.add(child.tail, stack, pre)

    def add(self, text: str | None, stack: tuple[int, ...], pre: bool) -> None:
        self.spans += 1
        for ch in text or "":
            if ch in "\r\n":
                if not pre:
                    continue
                ch = " "
            if ch == "\t":
                ch = " "
            if ch == " " and not pre and (not self.chars or self.chars[-1].ch == " "):
                continue
            self.chars.append(_Char(ch, stack, self.spans))

    def finish(self) -> list[_Char]:
        while self.chars and self.chars[-1].ch == " " and not self._pre(self.chars[-1]):
            self.chars.pop()
        return self.chars

    def _pre(self, c: _Char) -> bool:
        el = self.elements[c.stack[-1]]
        return el.el.get(_XML_SPACE) == "preserve"


def _baseline(style: Mapping[str, str], face: _Face, size: float) -> float:
    """How far down the alphabetic baseline goes for the element's dominant/alignment baseline."""
    key = style.get("alignment-baseline") or style.get("dominant-baseline") or "auto"
    m, k = face.metrics, size / _UNIT
    ascent, descent = -m.fAscent * k, m.fDescent * k
    return {
        "middle": m.fXHeight * k / 2,
        "central": (ascent - descent) / 2,
        "hanging": 0.8 * ascent,
        "text-top": ascent,
        "text-before-edge": ascent,
        "before-edge": ascent,
        "mathematical": 0.5 * ascent,
        "text-bottom": -descent,
        "text-after-edge": -descent,
        "after-edge": -descent,
        "ideographic": -descent,
    }.get(key.strip().lower(), 0.0)


def _resolve(c: _Char, elements: list[_Element]) -> dict[str, float | None]:
    """A character's x, y, dx, dy and rotate: the innermost element with a value for it."""
    out: dict[str, float | None] = dict.fromkeys(_ATTRS)
    for key in _ATTRS:
        for j in reversed(c.stack):
            values = elements[j].lists.get(key)
            if values:
                n = elements[j].count
                if n < len(values):
                    out[key] = values[n]
                    break
                if key == "rotate":
                    out[key] = values[-1]
                    break
    for j in c.stack:
        elements[j].count += 1
    return out


def layout_text(
    text: ET.Element,
    style: dict[str, str],
    find: Callable[[str], ET.Element | None],
    viewport: tuple[float, float],
) -> tuple[list[TextRun], tuple[float, float, float, float] | None]:
    """Lay out a ``<text>`` element (its own computed ``style``) into runs of glyph outlines.

    ``find(id)`` returns the element a ``<textPath>`` refers to (or None); percentages are of
    the ``viewport`` size.  Also returns the text's box (None: nothing drawn): its glyphs' ink
    bounds (what librsvg sizes ``objectBoundingBox`` gradients on text with, measured).
    """
    import skia

    col = _Collector(viewport)
    col.visit(text, style, (), False)
    chars = col.finish()
    elements = col.elements
    pen_x = pen_y = 0.0
    path_of: dict[int, tuple[Any, float]] = {}  # textPath element -> (measure, length)
    last_path = -1
    for i, c in enumerate(chars):
        st = elements[c.stack[-1]].style
        pos = _resolve(c, elements)
        c.face, c.size = _face_of(st), font_px(st)
        c.glyph = c.face.glyph(c.ch)
        if c.glyph == 0 and not c.ch.isspace():
            italic = st.get("font-style", "normal").strip().lower() in ("italic", "oblique")
            other = _fallback(c.ch, _weight(st.get("font-weight", "normal")), italic)
            if other is not None and other.glyph(c.ch):
                c.face, c.glyph = other, other.glyph(c.ch)
        k = c.size / _UNIT
        tp = next((j for j in reversed(c.stack) if local_name(elements[j].el.tag) == "textPath"), -1)
        if tp != last_path:
            if tp >= 0:
                path_of[tp] = _measure(elements[tp], find)
                pen_x, pen_y, c.new_chunk = _start_offset(elements[tp], path_of[tp][1]), 0.0, True
            last_path = tp
        if pos["x"] is not None:
            pen_x, c.new_chunk = pos["x"], True
        if pos["y"] is not None:
            pen_y, c.new_chunk = pos["y"], True
        pen_x += pos["dx"] or 0.0
        pen_y += pos["dy"] or 0.0
        c.x, c.y, c.rotate = pen_x, pen_y + _baseline(st, c.face, c.size), pos["rotate"] or 0.0
        c.advance = c.face.advance(c.glyph) * k
        spacing = _spacing(st, "letter-spacing", viewport)
        if c.ch == " ":
            spacing += _spacing(st, "word-spacing", viewport)
        pen_x += c.advance + spacing
        kerning = st.get("font-kerning", "auto").strip().lower() != "none"
        if kerning and i + 1 < len(chars) and chars[i + 1].span == c.span:  # as librsvg: within a span
            pen_x += c.face.kerning(c.glyph, c.face.glyph(chars[i + 1].ch)) * k
    _anchor(chars, elements)
    runs: list[TextRun] = []
    for c in chars:
        st = elements[c.stack[-1]].style
        if (
            c.face is None
            or c.size <= 0
            or st.get("visibility", "visible").strip().lower() in ("hidden", "collapse")
        ):
            continue
        outline = c.face.outline(c.glyph)
        if outline is None or outline.isEmpty():
            continue
        tp = next((j for j in reversed(c.stack) if local_name(elements[j].el.tag) == "textPath"), -1)
        m = skia.Matrix()
        if tp >= 0:
            measure, length = path_of[tp]
            mid = c.x + c.advance / 2
            if measure is None or not 0.0 <= mid <= length:
                continue
            point, tangent = measure.getPosTan(mid)
            m.setTranslate(point.x(), point.y())
            m.preRotate(math.degrees(math.atan2(tangent.y(), tangent.x())))
            m.preTranslate(-c.advance / 2, c.y)
        else:
            m.setTranslate(c.x, c.y)
        m.preRotate(c.rotate)
        m.preScale(c.size / _UNIT, c.size / _UNIT)
        if runs and runs[-1].style is st:
            runs[-1].path.addPath(outline, m)
        else:
            path = skia.Path()
            path.addPath(outline, m)
            runs.append(TextRun(path, st))
    box = None
    if runs:
        bounds = skia.Rect.MakeEmpty()
        for run in runs:
            bounds.join(run.path.computeTightBounds())
        box = (bounds.left(), bounds.top(), bounds.right(), bounds.bottom())
    return runs, box


def _spacing(style: Mapping[str, str], key: str, viewport: tuple[float, float]) -> float:
    text = style.get(key)
    values = lengths(text, style, viewport) if text and text.strip().lower() != "normal" else None
    return values[0] if values else 0.0


def _anchor(chars: list[_Char], elements: list[_Element]) -> None:
    """Shift every text chunk by its ``text-anchor`` (start, middle or end)."""
    starts = [i for i, c in enumerate(chars) if c.new_chunk or i == 0] + [len(chars)]
    for lo, hi in itertools.pairwise(starts):
        anchor = elements[chars[lo].stack[-1]].style.get("text-anchor", "start").strip().lower()
        if anchor not in ("middle", "end"):
            continue
        left = min(c.x for c in chars[lo:hi])
        right = max(c.x + c.advance for c in chars[lo:hi])
        shift = -(right - left) / 2 if anchor == "middle" else -(right - left)
        shift += chars[lo].x - left
        for c in chars[lo:hi]:
            c.x += shift


def _measure(element: _Element, find: Callable[[str], ET.Element | None]) -> tuple[Any, float]:
    """The path a ``<textPath>`` follows, measured: (skia.PathMeasure or None, its length)."""
    import skia

    from lsys_core.render.paths import _geometry, _path_from_arrays

    el = element.el
    d, transform = el.get("path"), None
    if d is None:
        href = href_of(el)
        target = find(href[1:]) if href and href.startswith("#") else None
        if target is None or local_name(target.tag) != "path":
            return None, 0.0
        d, transform = target.get("d"), parse_transform(target.get("transform"))
    geometry = _geometry(d or "")  # unreadable path data: empty, so no text drawn on it
    path = _path_from_arrays(geometry.points, geometry.verbs, False)
    if transform is not None:
        a, b, c, dd, e, f = transform
        path.transform(skia.Matrix.MakeAll(a, c, e, b, dd, f, 0, 0, 1))
    measure = skia.PathMeasure(path, False)
    return measure, float(measure.getLength())


def _start_offset(element: _Element, length: float) -> float:
    text = element.el.get("startOffset")
    if text is None:
        return 0.0
    value = parse_length(text)
    if value is None:
        return 0.0
    return value.value * length / 100.0 if value.unit == "%" else value.value
