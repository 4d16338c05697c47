"""The CSS cascade for SVG: presentation attributes, style sheets, ``style`` attributes, inheritance.

:class:`Cascade` gives every element its *specified* declarations (invalid values dropped, as
CSS drops them: the next value in the cascade applies) and folds them into *computed* styles,
plain ``{property: value}`` dictionaries in which inherited properties come from the parent.
Paint keywords such as ``currentColor`` stay keywords until an element draws with them, so a
``stroke="currentColor"`` set on a group takes the ``color`` of each element below it.
"""

from __future__ import annotations

import functools
import xml.etree.ElementTree as ET

from lsys_core.svg.colors import parse_color
from lsys_core.svg.css import Declaration, StyleSheet, parse_declarations
from lsys_core.svg.tree import Tree
from lsys_core.svg.values import parse_length, parse_number, parse_numbers

__all__ = ["INHERITED", "PROPERTIES", "Cascade", "font_size_px", "valid"]

INHERITED = frozenset(
    {
        "clip-rule", "color", "color-interpolation", "color-interpolation-filters", "color-rendering",
        "cursor", "direction", "dominant-baseline", "fill", "fill-opacity", "fill-rule", "font",
        "font-family", "font-feature-settings", "font-kerning", "font-size", "font-size-adjust",
        "font-stretch", "font-style", "font-variant", "font-weight", "glyph-orientation-horizontal",
        "glyph-orientation-vertical", "image-rendering", "letter-spacing", "line-height", "marker-end",
        "marker-mid", "marker-start", "paint-order", "pointer-events", "shape-rendering", "stroke",
        "stroke-dasharray", "stroke-dashoffset", "stroke-linecap", "stroke-linejoin",
        "stroke-miterlimit", "stroke-opacity", "stroke-width", "text-anchor", "text-rendering",
        "visibility", "white-space", "word-spacing", "writing-mode",
    }
)  # fmt: skip
NOT_INHERITED = frozenset(
    {
        "alignment-baseline", "baseline-shift", "clip", "clip-path", "display", "enable-background",
        "filter", "flood-color", "flood-opacity", "isolation", "lighting-color", "mask", "mask-type",
        "mix-blend-mode", "opacity", "overflow", "stop-color", "stop-opacity", "text-decoration",
        "transform", "transform-origin", "unicode-bidi", "vector-effect",
    }
)  # fmt: skip
PROPERTIES = INHERITED | NOT_INHERITED
#: Properties that are never presentation attributes (CSS only).
CSS_ONLY = frozenset({"marker", "font", "transform-origin"})
#: Properties that are presentation attributes.
_ATTRIBUTES = PROPERTIES - CSS_ONLY

_ENUMS = {
    "fill-rule": {"nonzero", "evenodd"},
    "clip-rule": {"nonzero", "evenodd"},
    "stroke-linecap": {"butt", "round", "square"},
    "stroke-linejoin": {"miter", "round", "bevel", "miter-clip", "arcs"},
    "visibility": {"visible", "hidden", "collapse"},
    "overflow": {"visible", "hidden", "scroll", "auto"},
}
#: Font-size keywords as factors of ``medium`` (CSS Fonts 3, section 3.5).
_FONT_SIZES = {
    "xx-small": 3 / 5, "x-small": 3 / 4, "small": 8 / 9, "medium": 1.0,
    "large": 6 / 5, "x-large": 3 / 2, "xx-large": 2.0, "xxx-large": 3.0,
}  # fmt: skip
#: Distinct styles each memo of a :class:`Cascade` keeps (it starts again when full).
MEMO_SIZE = 4096
#: Font size of the root when none is given (what rsvg and many tools use for ``medium``).
DEFAULT_FONT_SIZE = 12.0


def _url_or_none(v: str) -> bool:
    low = v.lower()
    return low == "none" or (low.startswith("url(") and ")" in low)


def _paint_ok(v: str) -> bool:
    low = v.lower()
    if low in ("none", "currentcolor", "context-fill", "context-stroke"):
        return True
    if low.startswith("url("):
        close = v.find(")")
        rest = v[close + 1 :].strip() if close >= 0 else None
        return rest is not None and (not rest or _paint_ok(rest))
    return parse_color(v) is not None


def _opacity_ok(v: str) -> bool:
    t = v.strip()
    return parse_number(t[:-1] if t.endswith("%") else t) is not None


def _length_ok(v: str) -> bool:
    return parse_length(v) is not None


def _dasharray_ok(v: str) -> bool:
    if v.strip().lower() == "none":
        return True
    parts = v.replace(",", " ").split()
    return bool(parts) and all(parse_length(p) is not None for p in parts)


def _paint_order_ok(v: str) -> bool:
    words = v.split()
    if words == ["normal"]:
        return True
    return bool(words) and len(words) <= 3 and len(set(words)) == len(words)
    # (each word must be fill, stroke or markers: checked below)


_VALIDATORS = {
    "fill": _paint_ok,
    "stroke": _paint_ok,
    "color": lambda v: parse_color(v) is not None,
    "stop-color": lambda v: parse_color(v) is not None,
    "flood-color": lambda v: parse_color(v) is not None,
    "opacity": _opacity_ok,
    "fill-opacity": _opacity_ok,
    "stroke-opacity": _opacity_ok,
    "stop-opacity": _opacity_ok,
    "stroke-width": _length_ok,
    "stroke-dashoffset": _length_ok,
    "stroke-dasharray": _dasharray_ok,
    "stroke-miterlimit": lambda v: (parse_number(v) or 0.0) >= 1.0,  # below 1 is invalid (SVG 2)
    "clip-path": _url_or_none,
    "mask": _url_or_none,
    "marker-start": _url_or_none,
    "marker-mid": _url_or_none,
    "marker-end": _url_or_none,
    "paint-order": lambda v: (
        _paint_order_ok(v) and all(w in ("normal", "fill", "stroke", "markers") for w in v.split())
    ),
}


@functools.lru_cache(maxsize=8192)
def valid(name: str, value: str) -> bool:
    """Tell whether a property value can be used (``inherit`` always can).

    Remembered per ``(name, value)``: documents repeat a few values thousands of times (the
    colour checks alone took 0.5 of 6.7 profiled seconds reading 20,000 leaves).
    """
    low = value.strip().lower()
    if not low:
        return False
    if low in ("inherit", "initial", "unset"):
        return True
    enum = _ENUMS.get(name)
    if enum is not None:
        return low in enum
    check = _VALIDATORS.get(name)
    return check is None or check(value.strip())


def font_size_px(value: str, parent_px: float, root_px: float) -> float:
    """Resolve a ``font-size`` value to user units (keywords, lengths, ``em`` and ``%``)."""
    low = value.strip().lower()
    if low in _FONT_SIZES:
        return DEFAULT_FONT_SIZE * _FONT_SIZES[low]
    if low == "larger":
        return parent_px * 1.2
    if low == "smaller":
        return parent_px / 1.2
    length = parse_length(low)
    if length is None:
        return parent_px
    v, unit = length
    if unit in ("em",):
        return v * parent_px
    if unit in ("ex", "ch"):
        return v * parent_px / 2
    if unit == "%":
        return v * parent_px / 100
    if unit == "rem":
        return v * root_px
    from lsys_core.svg.values import ABSOLUTE_UNITS

    return v * ABSOLUTE_UNITS.get(unit, 1.0)


class Cascade:
    """Specified and computed styles of the elements of one document."""

    def __init__(self, tree: Tree, sheet: StyleSheet) -> None:
        self.tree = tree
        self.sheet = sheet
        self._specified: dict[int, dict[str, str]] = {}
        self._same: dict[tuple[tuple[str, str], ...], dict[str, str]] = {}
        self._computed: dict[tuple[int, int, float], tuple[dict, dict, dict[str, str]]] = {}
        self._attributes: dict[str, tuple[Declaration, ...]] = {}

    def specified(self, el: ET.Element) -> dict[str, str]:
        """Return the declared properties of an element after the cascade (cached)."""
        key = id(el)
        got = self._specified.get(key)
        if got is not None:
            return got
        normal: dict[str, str] = {}
        important: dict[str, str] = {}
        for name, value in el.attrib.items():
            if name in _ATTRIBUTES and valid(name, value):
                normal[name] = value.strip()
        if self.sheet.rules:
            for rule in self.sheet.matching(el, self.tree):
                for d in rule.declarations:
                    _declare(normal, important, d.name, d.value, d.important)
        style = el.get("style")
        if style:
            for d in self._style_attribute(style):
                _declare(normal, important, d.name, d.value, d.important)
        normal.update(important)
        normal = self._shared(normal)
        self._specified[key] = normal
        return normal

    def _style_attribute(self, text: str) -> tuple[Declaration, ...]:
        """The declarations of a ``style`` attribute, remembered per text.

        Editors write the same few ``style`` texts on thousands of elements, and reading one
        with the CSS tokenizer costs tens of microseconds.
        """
        got = self._attributes.get(text)
        if got is None:
            got = tuple(parse_declarations(text))
            if len(self._attributes) >= MEMO_SIZE:
                self._attributes.clear()
            self._attributes[text] = got
        return got

    def _shared(self, spec: dict[str, str]) -> dict[str, str]:
        """One dictionary for equal specified styles (same order), so that identity tells them apart."""
        items = tuple(spec.items())
        got = self._same.get(items)
        if got is None:
            if len(self._same) >= MEMO_SIZE:
                self._same.clear()
            self._same[items] = got = spec
        return got

    def computed(self, el: ET.Element, parent: dict[str, str], root_font: float) -> dict[str, str]:
        """Fold an element's specified properties onto its parent's computed ones.

        The result is shared by the elements with the same specified style under the same parent
        style (both told apart by identity: :meth:`_shared`); nothing changes a style once made.
        Children of one group mostly have equal styles: folding each one again took 0.46 of 5.3
        profiled seconds reading 20,000 leaves, and sharing lets later steps remember what they
        derive from a style by its identity.
        """
        spec = self.specified(el)
        key = (id(parent), id(spec), root_font)
        got = self._computed.get(key)
        if got is not None and got[0] is parent and got[1] is spec:
            return got[2]
        out = self._fold(spec, parent, root_font)
        if len(self._computed) >= MEMO_SIZE:
            self._computed.clear()
        self._computed[key] = (parent, spec, out)  # holds both, so their ids are not reused
        return out

    @staticmethod
    def _fold(spec: dict[str, str], parent: dict[str, str], root_font: float) -> dict[str, str]:
        out = {k: v for k, v in parent.items() if k in INHERITED}
        for name, value in spec.items():
            low = value.lower()
            if low == "inherit":
                if name in parent:
                    out[name] = parent[name]
            elif low in ("initial", "unset"):
                if low == "initial" or name not in INHERITED:
                    out.pop(name, None)
            else:
                out[name] = value
        if "font-size" in spec:
            parent_px = float(parent.get("font-size", DEFAULT_FONT_SIZE))
            out["font-size"] = repr(font_size_px(out.get("font-size", ""), parent_px, root_font))
        return out


def _declare(normal: dict[str, str], important: dict[str, str], name: str, value: str, imp: bool) -> None:
    """Record one declaration (the ``marker`` shorthand sets the three marker properties)."""
    names = ("marker-start", "marker-mid", "marker-end") if name == "marker" else (name,)
    for n in names:
        if n not in PROPERTIES and n != "marker":
            continue
        if not valid(n, value):
            continue
        (important if imp else normal)[n] = value.strip()


def dash_lengths(value: str) -> list[str] | None:
    """Split a ``stroke-dasharray`` value into its lengths (None for ``none``)."""
    if value.strip().lower() == "none":
        return None
    return value.replace(",", " ").split()


def numbers_or_none(text: str | None) -> list[float] | None:
    """Read a number list attribute (``points``), or None if malformed."""
    return parse_numbers(text)
