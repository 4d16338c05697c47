"""Paint servers rewritten in document coordinates, for the scene's ``<defs>`` (clip paths and masks: :mod:`.masking`).

An element of the scene is geometry in document coordinates, so what its style refers to must be
in document coordinates too.  Each reference is rewritten for the element that uses it: the
element's transform (and, for ``objectBoundingBox`` units, its bounding box) is folded into a
``gradientTransform`` / ``patternTransform`` or into the clip path's own geometry, and units
become ``userSpaceOnUse``.  A copy is made once per distinct (resource, transform, box) and gets
a new id, unique among all ids of the input and of the copies; everything a copy refers to is
copied as well, so every reference in the definitions resolves.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable

from lsys_core.geometry.paths import ArrayPath
from lsys_core.svg.colors import hex_of, parse_color
from lsys_core.svg.paint import Paint, unit_value
from lsys_core.svg.tree import Tree, describe, href_of, local_name, shown
from lsys_core.svg.values import (
    IDENTITY,
    Matrix,
    Viewport,
    multiply,
    parse_length,
    parse_transform,
    to_user,
)
from lsys_core.svg.verbatim import matrix_text, style_text, subtree_markup

__all__ = ["Box", "Resources"]

_GRADIENTS = ("linearGradient", "radialGradient")
_GRADIENT_ATTRS = {
    "linearGradient": (("x1", "0%"), ("y1", "0%"), ("x2", "100%"), ("y2", "0%")),
    "radialGradient": (("cx", "50%"), ("cy", "50%"), ("r", "50%"), ("fx", None), ("fy", None), ("fr", "0%")),
}
Box = tuple[float, float, float, float]  # x, y, width, height


def _box_matrix(box: Box) -> Matrix:
    return (box[2], 0.0, 0.0, box[3], box[0], box[1])


def no_area(bbox: Box | None) -> bool:
    """Whether there is no bounding box with area to map ``objectBoundingBox`` units onto."""
    return bbox is None or bbox[2] <= 0 or bbox[3] <= 0


def unit_rect(
    texts: tuple[str | None, ...], defaults: tuple[str, ...], obb: bool, bbox: Box | None, vp: Viewport
) -> list[float]:
    """``x, y, width, height`` of a region (a pattern tile, a mask) in user units.

    With ``obb`` the lengths are fractions (or percentages) of ``bbox``; otherwise user lengths
    in the viewport ``vp``.  Missing or unreadable values take their ``defaults``.
    """
    unit_vp = Viewport(1.0, 1.0, vp.font_size, vp.root_font_size)
    rect = []
    for text, default, axis in zip(texts, defaults, "xyxy", strict=True):
        got = parse_length(text or default) or parse_length(default)
        rect.append(to_user(got, unit_vp if obb else vp, axis))  # type: ignore[arg-type]
    if obb and bbox:
        rect = [
            bbox[0] + rect[0] * bbox[2],
            bbox[1] + rect[1] * bbox[3],
            rect[2] * bbox[2],
            rect[3] * bbox[3],
        ]
    return rect


def _f(v: float) -> str:
    return f"{v:.10g}"


class Resources:
    """The definitions of one scene: ids, raw copies and rewritten paint servers."""

    def __init__(
        self,
        tree: Tree,
        style_at: Callable[[ET.Element], dict[str, str]],
        specified: Callable[[ET.Element], dict[str, str]],
        geometry: Callable[[ET.Element, Viewport], ArrayPath | None],
        notes: list[str],
    ) -> None:
        self.tree = tree
        self.style_at = style_at
        self.specified = specified
        self.geometry = geometry
        self.notes = notes
        self.parts: list[str] = []
        self.taken: set[str] = set(tree.ids)
        self._cache: dict[tuple, object] = {}
        self._raw_done: set[str] = set()
        self._emitted_ids: set[str] = set()
        self._busy: set[int] = set()
        self._clip_body: dict[str, list[tuple[str, str | None]]] = {}

    def markup(self) -> str:
        """All definitions, one after another."""
        return "\n".join(self.parts)

    def new_id(self, base: str) -> str:
        """Return a fresh id derived from ``base`` (unique among input ids and earlier copies)."""
        stem = "".join(c if c.isalnum() or c in "-_." else "_" for c in base)[:40] or "r"
        if not (stem[0].isalpha() or stem[0] == "_"):
            stem = "r" + stem
        k = 1
        while f"{stem}-{k}" in self.taken:
            k += 1
        new = f"{stem}-{k}"
        self.taken.add(new)
        return new

    def keep_id(self, el_id: str) -> bool:
        """Whether a copied element may keep its id (only its first copy does)."""
        if el_id in self._emitted_ids:
            return False
        self._emitted_ids.add(el_id)
        return True

    # -- raw copies (content kept as is refers to these in its own coordinates) -------------------

    def raw(self, el_id: str) -> None:
        """Copy the element with this id (and what it refers to) into the definitions, once."""
        if el_id in self._raw_done:
            return
        self._raw_done.add(el_id)
        el = self.tree.ids.get(el_id)
        if el is None:
            return
        self.parts.append(self.content_markup(el))

    def content_markup(self, el: ET.Element) -> str:
        """Markup of an element subtree with styles baked in and its references copied."""
        return subtree_markup(el, self.specified, self.raw, self.keep_id)

    # -- paint servers --------------------------------------------------------------------------

    def paint_server(self, ref: str, ctm: Matrix, bbox: Box | None, vp: Viewport) -> Paint | str:
        """Resolve ``url(ref)`` for an element: a paint, None (paints nothing) or ``"missing"``."""
        target = self.tree.target(ref)
        tag = local_name(target.tag) if target is not None else None
        if target is None or tag not in (*_GRADIENTS, "pattern"):
            return "missing"
        key = (id(target), ctm, bbox, vp)
        if key in self._cache:
            return self._cache[key]  # type: ignore[return-value]
        if id(target) in self._busy:
            return None
        self._busy.add(id(target))
        try:
            if tag == "pattern":
                got = self._pattern(target, ctm, bbox, vp)
            else:
                got = self._gradient(target, tag, ctm, bbox, vp)
        finally:
            self._busy.discard(id(target))
        self._cache[key] = got
        return got

    def _chain(self, el: ET.Element, kinds: tuple[str, ...]) -> list[ET.Element] | None:
        """The element and the ones it inherits from through ``href`` (of the given kinds).

        None if a local reference (``#id``) leads nowhere, to another kind of element or back into
        the chain: renderers then paint nothing with it.  A reference into another document (not
        ``#id``) is not followed: the chain ends there and the element keeps its own attributes,
        as renderers draw it.
        """
        out = [el]
        seen = {id(el)}
        cur = el
        while True:
            href = href_of(cur)
            if not href:
                return out
            if not href.startswith("#"):
                self.notes.append(
                    f"ignored the reference {shown(href)} of {describe(cur)}: not in this document"
                )
                return out
            nxt = self.tree.target(href)
            if nxt is None or id(nxt) in seen or local_name(nxt.tag) not in kinds or len(out) >= 64:
                return None
            out.append(nxt)
            seen.add(id(nxt))
            cur = nxt

    @staticmethod
    def _attr(chain: list[ET.Element], name: str, kinds: tuple[str, ...] | None = None) -> str | None:
        for el in chain:
            if kinds is not None and local_name(el.tag) not in kinds:
                continue
            v = el.get(name)
            if v is not None:
                return v
        return None

    def _gradient(self, el: ET.Element, tag: str, ctm: Matrix, bbox: Box | None, vp: Viewport) -> Paint | str:
        chain = self._chain(el, _GRADIENTS)
        if chain is None:
            return None
        stops = self._stops(chain)
        if not stops:
            return None
        if len(stops) == 1:
            _, color, opacity = stops[0]
            return ("color", color, opacity)
        units = (self._attr(chain, "gradientUnits") or "objectBoundingBox").strip()
        obb = units != "userSpaceOnUse"
        if obb and no_area(bbox):
            return "missing"  # no box to map onto: the fallback paint applies (as renderers draw)
        gt = parse_transform(self._attr(chain, "gradientTransform")) or IDENTITY
        m = multiply(multiply(ctm, _box_matrix(bbox)), gt) if obb and bbox else multiply(ctm, gt)
        unit_vp = Viewport(1.0, 1.0, vp.font_size, vp.root_font_size)
        coords: dict[str, float] = {}
        for name, default in _GRADIENT_ATTRS[tag]:
            text = self._attr(chain, name, (tag,))
            if text is None:
                if default is None:
                    continue
                text = default
            got = parse_length(text)
            if got is None or (name in ("r", "fr") and got.value < 0):
                got = parse_length(default) if default else None
                if got is None:
                    continue
            axis = (
                "x" if name in ("x1", "x2", "cx", "fx") else "y" if name in ("y1", "y2", "cy", "fy") else "o"
            )
            coords[name] = to_user(got, unit_vp if obb else vp, axis)
        if tag == "radialGradient":
            coords.setdefault("fx", coords["cx"])
            coords.setdefault("fy", coords["cy"])
            if coords.get("r", 0) <= 0:
                return None  # a radial gradient of radius 0 paints nothing (as renderers draw it)
        spread = (self._attr(chain, "spreadMethod") or "pad").strip()
        new = self.new_id(el.get("id") or "gradient")
        attrs = " ".join(f'{k}="{_f(v)}"' for k, v in coords.items())
        spread_attr = f' spreadMethod="{spread}"' if spread in ("reflect", "repeat") else ""
        body = "".join(
            f'<stop offset="{_f(o)}" stop-color="{c}"' + (f' stop-opacity="{_f(a)}"' if a < 1 else "") + "/>"
            for o, c, a in stops
        )
        self.parts.append(
            f'<{tag} id="{new}" gradientUnits="userSpaceOnUse" {attrs} '
            f'gradientTransform="{matrix_text(m)}"{spread_attr}>{body}</{tag}>'
        )
        return ("url", "#" + new, 1.0)

    def _stops(self, chain: list[ET.Element]) -> list[tuple[float, str, float]]:
        """The stops of the first gradient in the chain that has any: (offset, colour, opacity)."""
        for el in chain:
            stops = [c for c in el if local_name(c.tag) == "stop"]
            if not stops:
                continue
            out = []
            last = 0.0
            for s in stops:
                off_text = (s.get("offset") or "0").strip()
                off = unit_value(off_text, 0.0)
                off = max(off, last)
                last = off
                st = self.style_at(s)
                rgba = parse_color(st.get("stop-color", "black"), parse_color(st.get("color", "black")))
                rgba = rgba or (0.0, 0.0, 0.0, 1.0)
                opacity = unit_value(st.get("stop-opacity"), 1.0) * rgba[3]
                out.append((off, hex_of(rgba), opacity))
            return out
        return []

    def _pattern(self, el: ET.Element, ctm: Matrix, bbox: Box | None, vp: Viewport) -> Paint | str:
        chain = self._chain(el, ("pattern",))
        if chain is None:
            return None
        units = (self._attr(chain, "patternUnits") or "objectBoundingBox").strip()
        content_units = (self._attr(chain, "patternContentUnits") or "userSpaceOnUse").strip()
        obb = units != "userSpaceOnUse"
        if (obb or content_units == "objectBoundingBox") and no_area(bbox):
            return "missing"  # no box to map onto: the fallback paint applies (as renderers draw)
        names = ("x", "y", "width", "height")
        tile = unit_rect(tuple(self._attr(chain, n) for n in names), ("0",) * 4, obb, bbox, vp)
        if tile[2] <= 0 or tile[3] <= 0:
            return None
        content_el = next((c for c in chain if any(isinstance(k.tag, str) for k in c)), None)
        if content_el is None:
            return None
        pt = parse_transform(self._attr(chain, "patternTransform")) or IDENTITY
        m = multiply(ctm, pt)
        viewbox = self._attr(chain, "viewBox")
        par = self._attr(chain, "preserveAspectRatio")
        inner = "".join(self.content_markup(c) for c in content_el if isinstance(c.tag, str))
        if viewbox is None and content_units == "objectBoundingBox" and bbox:
            inner = f'<g transform="matrix({_f(bbox[2])} 0 0 {_f(bbox[3])} 0 0)">{inner}</g>'
        # Content inherits from the pattern element, not from the element it paints.
        inherited = {k: v for k, v in self.style_at(content_el).items() if k != "display"}
        if inherited:
            inner = f'<g style="{_esc(style_text(inherited))}">{inner}</g>'
        new = self.new_id(el.get("id") or "pattern")
        extra = (f' viewBox="{_esc(viewbox)}"' if viewbox else "") + (
            f' preserveAspectRatio="{_esc(par)}"' if par else ""
        )
        self.parts.append(
            f'<pattern id="{new}" patternUnits="userSpaceOnUse" x="{_f(tile[0])}" y="{_f(tile[1])}" '
            f'width="{_f(tile[2])}" height="{_f(tile[3])}" patternTransform="{matrix_text(m)}"{extra}>'
            f"{inner}</pattern>"
        )
        return ("url", "#" + new, 1.0)

    # -- clip paths and masks -------------------------------------------------------------------


def _esc(text: str) -> str:
    return text.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;")
