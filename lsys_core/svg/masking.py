"""Clip paths and masks rewritten in document coordinates, for the scene's ``<defs>``.

As for paint servers (:mod:`.resources`), a clip path or mask is rewritten for each element that
uses it: the element's transform and, for ``objectBoundingBox`` units, its box are folded into the
clip path's geometry or the mask's content transform, and units become ``userSpaceOnUse``.
Clips that meet (a group's and its child's, a viewport's and a shape's) are intersected into one
outline (:mod:`.clipregion`), which every renderer draws.  A clip path on a clip path or on one of
its children, and intersections involving text, are written as clip paths on the pieces (valid
SVG, which librsvg 2.54 ignores, as it does in the input).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable

import numpy as np

from lsys_core.geometry.bezier import transform_cubics
from lsys_core.geometry.paths import d_from_cubics
from lsys_core.svg.clipregion import Region, intersect_regions, piece_region, region_d, union_regions
from lsys_core.svg.paint import split_url
from lsys_core.svg.resources import Box, Resources, _box_matrix, _esc, _f, no_area, unit_rect
from lsys_core.svg.tree import href_of, local_name, shown
from lsys_core.svg.values import IDENTITY, Matrix, Viewport, multiply, parse_length, parse_transform, to_user
from lsys_core.svg.verbatim import matrix_text, style_text, subtree_markup

__all__ = ["EMPTY", "MAX_REGION_PIECES", "Definitions"]

#: Returned by :meth:`Definitions.clip` for a clip path that lets nothing through.
EMPTY = "empty"
#: Clip paths of more pieces than this are intersected piece-wise (unions of many outlines are slow).
MAX_REGION_PIECES = 64
_CLIP_SHAPES = frozenset({"path", "rect", "circle", "ellipse", "line", "polyline", "polygon"})


class Definitions(Resources):
    """The definitions of one scene: paint servers (see :class:`Resources`), clip paths and masks."""

    def clip(self, value: str | None, ctm: Matrix, bbox: Box | None, vp: Viewport) -> str | None:
        """Rewrite a ``clip-path`` value for an element: an id, None (no clipping) or :data:`EMPTY`."""
        return self._referenced(value, "clipPath", ctm, bbox, vp, self._clip, self._clip_cycle)

    def _clip_cycle(self, value: str) -> None:
        """Note and ignore a clip-path reference that closes a cycle."""
        # The reference that closes a cycle (a clip path clipped by itself, directly or through
        # its children) is ignored, as renderers draw it: the cycle is cut there.
        self.notes.append(
            f"ignored the clip-path {shown(value)}: it refers back to itself (a reference cycle)"
        )

    def _referenced(
        self,
        value: str | None,
        tag: str,
        ctm: Matrix,
        bbox: Box | None,
        vp: Viewport,
        build: Callable[[ET.Element, Matrix, Box | None, Viewport], str | None],
        cycle: Callable[[str], str | None],
    ) -> str | None:
        """``build(target, ctm, bbox, vp)`` for the ``tag`` element that ``value`` (a ``url()``) names.

        None when it names none (or ``none``); each result is cached per target, transform and
        box; a reference back into a target being built gives ``cycle(value)``.
        """
        if value is None or value.strip().lower() == "none":
            return None
        ref, _ = split_url(value)
        target = self.tree.target(ref)
        if target is None or local_name(target.tag) != tag:
            return None
        key = (tag, id(target), ctm, bbox)
        if key in self._cache:
            return self._cache[key]  # type: ignore[return-value]
        if id(target) in self._busy:
            return cycle(value)
        self._busy.add(id(target))
        try:
            got = build(target, ctm, bbox, vp)
        finally:
            self._busy.discard(id(target))
        self._cache[key] = got
        return got

    def _clip(self, el: ET.Element, ctm: Matrix, bbox: Box | None, vp: Viewport) -> str | None:
        obb = (el.get("clipPathUnits") or "").strip() == "objectBoundingBox"
        if obb and no_area(bbox):
            return EMPTY
        base = multiply(ctm, _box_matrix(bbox)) if obb and bbox else ctm
        base = multiply(base, parse_transform(el.get("transform")) or IDENTITY)
        pieces: list[tuple[str, str | None]] = []
        for child in el:
            piece = self._clip_piece(child, base, vp)
            if piece is not None:
                pieces.append(piece)
        own = self.clip(self.style_at(el).get("clip-path"), base, bbox, vp)
        if own == EMPTY or not pieces:
            return EMPTY
        return self._add_clip(el.get("id") or "clip", pieces, own)

    def _clip_piece(self, child: ET.Element, base: Matrix, vp: Viewport) -> tuple[str, str | None] | None:
        """One child of a clip path in document coordinates: its start tag and own clip; None if it adds nothing."""
        tag = local_name(child.tag)
        if tag is None:
            return None
        style = self.style_at(child)
        source = child
        m = multiply(base, parse_transform(style.get("transform")) or IDENTITY)
        if tag == "use":
            target = self.tree.target(href_of(child))
            if target is None or local_name(target.tag) not in (*_CLIP_SHAPES, "text"):
                return None
            m = multiply(
                m, (1.0, 0.0, 0.0, 1.0, _length(child.get("x"), vp, "x"), _length(child.get("y"), vp, "y"))
            )
            source, tag = target, local_name(target.tag)
            target_style = self.specified(target)
            m = multiply(m, parse_transform(target_style.get("transform")) or IDENTITY)
            style = {**style, **target_style}
        if style.get("display", "").lower() == "none" or style.get("visibility", "visible") != "visible":
            return None
        own = self.clip(style.get("clip-path"), m, None, vp)
        if own == EMPTY:
            return None
        rule = style.get("clip-rule", "nonzero")
        if tag in _CLIP_SHAPES:
            geom = self.geometry(source, vp)
            if geom is None or geom.cubics.shape[0] == 0:
                return None
            cub = transform_cubics(geom.cubics, m)
            if not np.isfinite(cub).all():
                return None
            d = d_from_cubics(cub, geom.subpaths, geom.closed)
            return f'<path d="{d}" clip-rule="{rule}"/>', own
        if tag == "text":
            decls = {k: v for k, v in self.specified(source).items() if k not in ("transform", "clip-path")}
            markup = subtree_markup(
                source, lambda e: decls if e is source else self.specified(e), self.raw, self.keep_id
            )
            head_end = markup.index(">")
            if markup[head_end - 1] == "/":
                head_end -= 1
            # The text's own transform is part of m: replace it.
            head = _drop_attr(markup[:head_end], "transform") + f' transform="{matrix_text(m)}"'
            return head + markup[head_end:], own
        return None  # not a valid child of a clip path

    def _add_clip(self, base: str, pieces: list[tuple[str, str | None]], outer: str | None = None) -> str:
        """Write a clip path of ``pieces`` (each clipped by its own clip and by ``outer``); return its id.

        Intersections are written as clip paths on the pieces, which renderers agree on.
        """
        stored = [(markup, self.intersect(own, outer)) for markup, own in pieces]
        stored = [(markup, clip) for markup, clip in stored if clip != EMPTY]
        if not stored:
            return EMPTY
        new = self.new_id(base)
        self._clip_body[new] = stored
        body = "".join(_with_clip(markup, clip) for markup, clip in stored)
        self.parts.append(f'<clipPath id="{new}" clipPathUnits="userSpaceOnUse">{body}</clipPath>')
        return new

    def intersect(self, inner: str | None, outer: str | None) -> str | None:
        """Return a clip path letting through what both let through."""
        if inner is None or outer is None or inner == outer:
            return inner or outer
        if EMPTY in (inner, outer):
            return EMPTY
        key = ("and", inner, outer)
        if key not in self._cache:
            flat = self._flat_intersection(inner, outer)
            self._cache[key] = flat or self._add_clip("clip", self._clip_body[inner], outer)
        return self._cache[key]  # type: ignore[return-value]

    def _flat_intersection(self, inner: str, outer: str) -> str | None:
        """The intersection as one outline (see :mod:`.clipregion`); None where it cannot be made."""
        a, b = self._region(inner), self._region(outer)
        if a is None or b is None:
            return None
        both = intersect_regions(a, b)
        if both.isEmpty():
            return EMPTY
        d, rule = region_d(both, _f)
        return self._add_clip("clip", [(f'<path d="{d}" clip-rule="{rule}"/>', None)])

    def _region(self, clip: str) -> Region | None:
        """The region a clip path written here lets through (None: it has text, or no skia)."""
        key = ("region", clip)
        body = self._clip_body[clip]
        if len(body) > MAX_REGION_PIECES:
            return None
        if key not in self._cache:
            regions = []
            for markup, own in body:
                r = piece_region(markup)
                if r is not None and own is not None:
                    o = self._region(own)
                    r = None if o is None else intersect_regions(r, o)
                if r is None:
                    break
                regions.append(r)
            else:
                self._cache[key] = union_regions(regions)
            self._cache.setdefault(key, None)
        return self._cache[key]

    def mask(self, value: str | None, ctm: Matrix, bbox: Box | None, vp: Viewport) -> str | None:
        """Rewrite a ``mask`` value for an element: an id, None (no mask) or :data:`EMPTY`."""
        return self._referenced(value, "mask", ctm, bbox, vp, self._mask, lambda _: EMPTY)

    def _mask(self, el: ET.Element, ctm: Matrix, bbox: Box | None, vp: Viewport) -> str | None:
        obb = (el.get("maskUnits") or "objectBoundingBox").strip() != "userSpaceOnUse"
        content_obb = (el.get("maskContentUnits") or "").strip() == "objectBoundingBox"
        if (obb or content_obb) and no_area(bbox):
            return EMPTY
        texts = tuple(el.get(n) for n in ("x", "y", "width", "height"))
        region = unit_rect(texts, ("-10%", "-10%", "120%", "120%"), obb, bbox, vp)
        if region[2] <= 0 or region[3] <= 0:
            return EMPTY
        corners = [complex(region[0] + dx, region[1] + dy) for dx in (0, region[2]) for dy in (0, region[3])]
        a, b, c, d, e, f = ctm
        pts = [complex(a * p.real + c * p.imag + e, b * p.real + d * p.imag + f) for p in corners]
        x0, x1 = min(p.real for p in pts), max(p.real for p in pts)
        y0, y1 = min(p.imag for p in pts), max(p.imag for p in pts)
        content_m = multiply(ctm, _box_matrix(bbox)) if content_obb and bbox else ctm
        inner = "".join(self.content_markup(ch) for ch in el if isinstance(ch.tag, str))
        inherited = self.style_at(el)
        style = f' style="{_esc(style_text(inherited))}"' if inherited else ""
        kind = self.specified(el).get("mask-type") or el.get("mask-type")
        kind_attr = f' mask-type="{_esc(kind)}"' if kind else ""
        new = self.new_id(el.get("id") or "mask")
        self.parts.append(
            f'<mask id="{new}" maskUnits="userSpaceOnUse" x="{_f(x0)}" y="{_f(y0)}" '
            f'width="{_f(x1 - x0)}" height="{_f(y1 - y0)}"{kind_attr}>'
            f'<g transform="{matrix_text(content_m)}"{style}>{inner}</g></mask>'
        )
        return new

    def clip_rect(self, corners: list[complex]) -> str:
        """A clip path of a quadrilateral given in document coordinates (viewports, markers)."""
        key = ("rect", tuple(corners))
        if key in self._cache:
            return self._cache[key]  # type: ignore[return-value]
        d = "M" + " L".join(f"{_f(p.real)} {_f(p.imag)}" for p in corners) + " Z"
        new = self._add_clip("viewport", [(f'<path d="{d}"/>', None)])
        self._cache[key] = new
        return new


def _length(text: str | None, vp: Viewport, axis: str) -> float:
    got = parse_length(text) if text is not None else None
    return 0.0 if got is None else to_user(got, vp, axis)


def _drop_attr(head: str, name: str) -> str:
    """Remove one attribute from a start tag written by ElementTree (values are double-quoted)."""
    key = f' {name}="'
    i = head.find(key)
    if i < 0:
        return head
    j = head.index('"', i + len(key))
    return head[:i] + head[j + 1 :]


def _with_clip(markup: str, clip: str | None) -> str:
    """Add a clip path to the start tag of a clip piece."""
    if not clip:
        return markup
    end = markup.index(">")
    if markup[end - 1] == "/":
        end -= 1
    return markup[:end] + f' clip-path="url(#{clip})"' + markup[end:]
