"""Check the parsed XML tree and re-serialise it for svgelements.

Counts elements and nesting, detects ``<use>`` cycles and fan-out, parses path data with the fast
array parser, clamps opacities, drops unusable viewports and moves ``<symbol>``, ``<mask>`` and
``<marker>`` content out of the drawing flow.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

from lsys_core.errors import LimitError, SvgError
from lsys_core.geometry.paths import ArrayPath, path_from_d
from lsys_core.svg.xmlsafe import (
    INTERNAL_SUBSET,
    SVG_NS,
    XLINK_HREF,
    check_bytes,
    local_name,
    parse_xml,
    snippet,
)

__all__ = ["DRAWABLE", "NOT_RENDERED", "SRC_ATTR", "Prepared", "parse_viewbox", "prepare"]

#: Attribute carrying the index of an element's source name through svgelements.
SRC_ATTR = "data-lsys-src"

DRAWABLE = frozenset({"path", "rect", "circle", "ellipse", "line", "polyline", "polygon"})
#: Containers whose content svgelements never draws.
NOT_RENDERED = frozenset({"defs", "clipPath", "pattern"})
#: Containers drawn only through ``<use>`` (unknown to svgelements): moved into ``<defs>``.
USE_ONLY = frozenset({"symbol", "mask", "marker"})
#: Elements ignored entirely (static geometry only): removed with their content.
IGNORED = frozenset(
    {
        "text",
        "image",
        "foreignObject",
        "metadata",
        "title",
        "desc",
        "script",
        "animate",
        "animateMotion",
        "animateTransform",
        "animateColor",
        "set",
        "linearGradient",
        "radialGradient",
        "filter",
    }
)

#: A canvas width or height svgelements can resolve (no font-relative units: the root has no font).
_LENGTH = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(?:px|pt|pc|mm|cm|in|%)?\s*")
#: An opacity declaration in a ``style`` attribute or a style sheet.
_OPACITY_DECL = re.compile(r"(?i)((?<![\w-])(?:fill-|stroke-)?opacity\s*:\s*)([^;}!\s]+)")
_OPACITY_ATTRS = ("opacity", "fill-opacity", "stroke-opacity")


@dataclass
class Prepared:
    """The checked tree, re-serialised for svgelements, and what the checks learnt."""

    data: bytes
    names: list[str]
    paths: dict[str, ArrayPath]
    expected: int
    viewbox: tuple[float, float, float, float] | None
    size: tuple[str, str] | None
    #: Why an element whose geometry comes out empty is skipped, by source index (default: degenerate).
    reasons: dict[str, str] = field(default_factory=dict)
    #: Warnings about attributes that were ignored (unusable viewBox, width, height).
    notes: list[str] = field(default_factory=list)
    #: ``(element description, transform text)`` of every element with a transform, for error messages.
    transforms: list[tuple[str, str]] = field(default_factory=list)


def prepare(source: str | bytes, max_elements: int, max_depth: int, name: str) -> Prepared:
    """Check the XML tree and re-serialise it for svgelements."""
    raw = source if isinstance(source, bytes) else source.encode("utf-8", "replace")
    check_bytes(raw, name)
    root = parse_xml(source, name)  # rejects entities (billion laughs, XXE) first
    if INTERNAL_SUBSET.search(raw, 0, 65536):
        raise SvgError(f"DTD internal subsets are not allowed in SVG input (possible XML attack): {name}")
    if local_name(root.tag) != "svg":
        raise SvgError(f"not an SVG: {name}: the root element is <{root.tag}>, not <svg>")

    names: list[str] = []
    paths: dict[str, ArrayPath] = {}
    reasons: dict[str, str] = {}
    notes: list[str] = []
    transforms: list[tuple[str, str]] = []
    counters: dict[str, int] = {}
    ids: dict[str, ET.Element] = {}
    uses: list[ET.Element] = []
    remove: list[tuple[ET.Element, ET.Element]] = []
    wrap: list[tuple[ET.Element, ET.Element]] = []
    direct = 0  # drawables outside non-rendered containers
    count = 0
    # Iterative pre-order walk: (element, parent, depth, hidden).
    stack: list[tuple[ET.Element, ET.Element | None, int, bool]] = [(root, None, 1, False)]
    while stack:
        el, parent, depth, hidden = stack.pop()
        if depth > max_depth:
            raise LimitError(f"{name}: elements are nested more than {max_depth} levels deep")
        count += 1
        if count > max_elements:
            raise LimitError(f"{name} has more than {max_elements:,} elements")
        tag = local_name(el.tag)
        if tag is None or tag in IGNORED:
            if parent is not None:
                remove.append((parent, el))
            continue
        if tag in USE_ONLY and not hidden and parent is not None:
            wrap.append((parent, el))
        el_id = el.get("id")
        if el_id is not None:
            ids[el_id] = el
        _clamp_opacities(el, tag)
        if tag == "svg":
            _drop_unusable_viewport(el, notes)
        if tag in DRAWABLE or tag == "use":
            i = counters.get(tag, 0)
            counters[tag] = i + 1
            key = str(len(names))
            el.set(SRC_ATTR, key)
            names.append(f"{tag}#{el_id}" if el_id else f"{tag}[{i}]")
            if tag == "path":
                # Parse path data here; svgelements then only resolves the transform.
                path_raw, reason = _path_raw(el.get("d"))
                paths[key] = path_raw
                el.set("d", "")
                if reason is not None:
                    reasons[key] = reason
            if tag == "use":
                uses.append(el)
            elif not hidden:
                direct += 1
        transform = el.get("transform")
        if transform:
            transforms.append((names[-1] if SRC_ATTR in el.attrib else f"<{tag}>", transform))
        child_hidden = hidden or tag in NOT_RENDERED or tag in USE_ONLY
        stack.extend((c, el, depth + 1, child_hidden) for c in reversed(el))

    _remove_children(remove)
    for parent, el in wrap:
        idx = list(parent).index(el)
        parent.remove(el)
        defs = ET.Element(SVG_NS + "defs")
        defs.append(el)
        parent.insert(idx, defs)

    expected = _check_uses(root, ids, max_elements, max_depth, name) if uses else direct
    viewbox = parse_viewbox(root.get("viewBox"))
    w, h = root.get("width"), root.get("height")
    size = (w or "100%", h or "100%") if (w is not None or h is not None) else None
    return Prepared(ET.tostring(root), names, paths, expected, viewbox, size, reasons, notes, transforms)


def _path_raw(d: str | None) -> tuple[ArrayPath, str | None]:
    """Return the segments of path data (drawn up to the first error, as SVG asks) and, if the
    data has an error, the reason to give when nothing is drawn."""
    path, error = path_from_d(d or "")
    return path, (None if error is None or d is None else "malformed path data")


def _clamp_opacity_text(text: str) -> str | None:
    """Return an opacity number outside [0, 1] clamped into it (svgelements overflows on huge ones), else None."""
    try:
        v = float(text.strip())
    except ValueError:
        return None
    if v > 1.0:
        return "1"
    if v < 0.0:
        return "0"
    return None


def _clamp_decl(mt: re.Match) -> str:
    fixed = _clamp_opacity_text(mt.group(2))
    return mt.group(0) if fixed is None else mt.group(1) + fixed


def _clamp_opacities(el, tag: str) -> None:
    """Clamp opacities in attributes, ``style`` and style sheets to [0, 1], as CSS does."""
    attrib = el.attrib
    if attrib:
        for key in _OPACITY_ATTRS:
            value = attrib.get(key)
            if value is not None and (fixed := _clamp_opacity_text(value)) is not None:
                attrib[key] = fixed
        style = attrib.get("style")
        if style and "opacity" in style.lower():
            attrib["style"] = _OPACITY_DECL.sub(_clamp_decl, style)
    if tag == "style" and el.text and "opacity" in el.text.lower():
        el.text = _OPACITY_DECL.sub(_clamp_decl, el.text)


def _usable_length(text: str) -> bool:
    """Tell whether a width or height is a positive, finite length."""
    mt = _LENGTH.fullmatch(text)
    if mt is None:
        return False
    v = float(mt.group(1))
    return math.isfinite(v) and v > 0


def _drop_unusable_viewport(el, notes: list[str]) -> None:
    """Remove a zero, negative, non-finite or unreadable ``viewBox``, ``width`` or ``height`` of an ``<svg>``."""
    vb = el.get("viewBox")
    if vb is not None and parse_viewbox(vb) is None:
        del el.attrib["viewBox"]
        notes.append(f"ignored the viewBox {snippet(vb)} of <svg>: it needs 4 numbers with width, height > 0")
    for key in ("width", "height"):
        value = el.get(key)
        if value is not None and not _usable_length(value):
            del el.attrib[key]
            unit = "a positive length in px, pt, pc, mm, cm, in or %"
            notes.append(f"ignored the {key} {snippet(value)} of <svg>: it must be {unit}")


def _remove_children(pairs: list[tuple[ET.Element, ET.Element]]) -> None:
    """Remove ``(parent, child)`` pairs, rebuilding each parent's children once (linear time)."""
    by_parent: dict[int, tuple[ET.Element, set[int]]] = {}
    for parent, el in pairs:
        by_parent.setdefault(id(parent), (parent, set()))[1].add(id(el))
    for parent, gone in by_parent.values():
        parent[:] = [c for c in parent if id(c) not in gone]


def _href(el) -> str | None:
    """Return the reference of a ``<use>`` as svgelements resolves it (``href`` wins over ``xlink:href``)."""
    url = el.get("href")
    if url is None:
        url = el.get(XLINK_HREF)
    return url


def _check_uses(root, ids: dict, max_elements: int, max_depth: int, name: str) -> int:
    """Detect ``<use>`` cycles, fan-out and deep reference chains; count drawable instances.

    Walks the graph of child and ``<use>``-reference edges iteratively with
    memoisation, so shared definitions are visited once however often they are
    instanced.

    Returns
    -------
    int
        Number of drawable shapes svgelements will produce once references are expanded.
    """
    visiting, done = 1, 2
    state: dict[int, int] = {}
    total: dict[int, int] = {}  # elements in the expanded subtree
    drawn: dict[int, int] = {}  # drawable shapes in the expanded subtree
    depth: dict[int, int] = {}  # expanded nesting depth

    def successors(el) -> list:
        succ = list(el)
        if local_name(el.tag) == "use":
            url = _href(el)
            target = ids.get(url[1:]) if url else None
            if target is not None:
                succ.append(target)
        return succ

    stack = [root]
    while stack:
        el = stack[-1]
        key = id(el)
        st = state.get(key)
        if st is None:
            state[key] = visiting
            for s in successors(el):
                s_state = state.get(id(s))
                if s_state == visiting:
                    ref = s.get("id")
                    where = f" (#{ref})" if ref else ""
                    raise SvgError(f"{name}: <use> references form a cycle{where}")
                if s_state is None:
                    stack.append(s)
            continue
        stack.pop()
        if st == done:
            continue
        succ = successors(el)
        tag = local_name(el.tag)
        t = 1 + sum(total[id(s)] for s in succ)
        d = 1 + max((depth[id(s)] for s in succ), default=0)
        if t > max_elements:
            raise LimitError(f"{name} expands to more than {max_elements:,} elements (<use> fan-out)")
        if d > max_depth:
            raise LimitError(f"{name}: <use> references nest more than {max_depth} levels deep")
        if tag in NOT_RENDERED:
            n = 0
        else:
            n = (1 if tag in DRAWABLE else 0) + sum(drawn[id(s)] for s in succ)
        total[key], depth[key], drawn[key] = t, d, n
        state[key] = done
    return drawn[id(root)]


def parse_viewbox(text: str | None) -> tuple[float, float, float, float] | None:
    """Parse a ``viewBox`` attribute; None if absent or unusable."""
    if not text:
        return None
    try:
        vals = [float(v) for v in re.split(r"[\s,]+", text.strip())]
    except ValueError:
        return None
    if len(vals) != 4 or not all(math.isfinite(v) for v in vals) or vals[2] <= 0 or vals[3] <= 0:
        return None
    return (vals[0], vals[1], vals[2], vals[3])
