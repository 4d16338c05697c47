"""Read an SVG file into a :class:`~lsys_core.svg.model.Scene`, safely.

The bytes are checked before any SVG library sees them: size, binary junk, XML
attacks (entities, internal DTD subsets), nesting depth, ``<use>`` cycles and
``<use>`` fan-out.  The checked tree is re-serialised (without DTD, with the
content of ``<symbol>``, ``<mask>`` and ``<marker>`` moved out of the drawing
flow) and handed to svgelements, which resolves CSS, inheritance, ``<use>`` and
transforms.  Each drawable shape becomes an :class:`~lsys_core.svg.model.Element`
with cubic Bézier arrays in viewBox user units and a resolved style string.
"""

from __future__ import annotations

import gc
import io
import math
import os
import re
import xml.etree.ElementTree as ET
import zlib
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from lsys_core.errors import LimitError, SvgError
from lsys_core.geometry.paths import (
    MAX_COORD,
    SVGELEMENTS_ERRORS,
    RawPath,
    assemble,
    raw_from_d,
    raw_from_segments,
)
from lsys_core.svg.model import Element, Scene

if TYPE_CHECKING:
    from svgelements import Shape

__all__ = ["DEFAULT_MAX_BYTES", "DEFAULT_MAX_DEPTH", "DEFAULT_MAX_ELEMENTS", "load_svg", "parse_svg"]

DEFAULT_MAX_BYTES = 50_000_000
DEFAULT_MAX_ELEMENTS = 200_000
DEFAULT_MAX_DEPTH = 500
#: Coordinates beyond this magnitude are treated as broken input.

SVG_NS = "{http://www.w3.org/2000/svg}"
XLINK_HREF = "{http://www.w3.org/1999/xlink}href"
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

_INTERNAL_SUBSET = re.compile(rb"<!DOCTYPE[^\[>]*\[")
#: A canvas width or height svgelements can resolve (no font-relative units: the root has no font).
_LENGTH = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(?:px|pt|pc|mm|cm|in|%)?\s*")
#: An opacity declaration in a ``style`` attribute or a style sheet.
_OPACITY_DECL = re.compile(r"(?i)((?<![\w-])(?:fill-|stroke-)?opacity\s*:\s*)([^;}!\s]+)")
_OPACITY_ATTRS = ("opacity", "fill-opacity", "stroke-opacity")


@dataclass
class _Prepared:
    """The checked tree, re-serialised for svgelements, and what the checks learnt."""

    data: bytes
    names: list[str]
    paths: dict[str, RawPath]
    expected: int
    viewbox: tuple[float, float, float, float] | None
    size: tuple[str, str] | None
    #: Why an element whose geometry comes out empty is skipped, by source index (default: degenerate).
    reasons: dict[str, str] = field(default_factory=dict)
    #: Warnings about attributes that were ignored (unusable viewBox, width, height).
    notes: list[str] = field(default_factory=list)
    #: ``(element description, transform text)`` of every element with a transform, for error messages.
    transforms: list[tuple[str, str]] = field(default_factory=list)


@dataclass
class _Skips:
    """Counts of skipped elements by reason."""

    counts: dict[str, int] = field(default_factory=dict)

    def add(self, reason: str, n: int = 1) -> None:
        """Count ``n`` more elements skipped for ``reason`` (non-positive ``n`` is ignored)."""
        if n > 0:
            self.counts[reason] = self.counts.get(reason, 0) + n

    def messages(self) -> tuple[str, ...]:
        """Return one ``"skipped N elements: reason"`` line per reason."""
        out = []
        for reason, n in self.counts.items():
            out.append(f"skipped {n} element{'s' if n != 1 else ''}: {reason}")
        return tuple(out)


def load_svg(
    path: str | os.PathLike,
    *,
    max_bytes: int = DEFAULT_MAX_BYTES,
    max_elements: int = DEFAULT_MAX_ELEMENTS,
    max_depth: int = DEFAULT_MAX_DEPTH,
) -> Scene:
    """Read an SVG (or gzip-compressed SVGZ) file into a scene.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    max_bytes : int
        Largest accepted file size (also for the decompressed content of SVGZ).
    max_elements : int
        Largest accepted number of elements once ``<use>`` references are expanded.
    max_depth : int
        Deepest accepted element nesting (``<use>`` references count as nesting).

    Returns
    -------
    Scene

    Raises
    ------
    SvgError
        The file cannot be read, is not a safe SVG, or has nothing drawable.
    LimitError
        The file exceeds one of the limits.
    """
    p = Path(path)
    try:
        size = p.stat().st_size
        if size > max_bytes:
            raise LimitError(f"{p} is too large ({size:,} bytes; the limit is {max_bytes:,})")
        with open(p, "rb") as fh:
            data = fh.read(max_bytes + 1)
    except OSError as exc:
        raise SvgError(f"cannot read {p}: {exc.strerror or exc}") from exc
    return parse_svg(data, max_bytes=max_bytes, max_elements=max_elements, max_depth=max_depth, name=str(p))


def parse_svg(
    source: str | bytes,
    *,
    max_bytes: int = DEFAULT_MAX_BYTES,
    max_elements: int = DEFAULT_MAX_ELEMENTS,
    max_depth: int = DEFAULT_MAX_DEPTH,
    name: str = "<string>",
) -> Scene:
    """Parse SVG text or bytes into a scene (see :func:`load_svg`).

    ``name`` is used in messages.
    """
    data = source.encode("utf-8") if isinstance(source, str) else bytes(source)
    if len(data) > max_bytes:
        raise LimitError(f"{name} is too large ({len(data):,} bytes; the limit is {max_bytes:,})")
    data = _maybe_gunzip(data, max_bytes, name)
    source_bytes = len(data)
    prepared = _prepare(source if isinstance(source, str) else data, max_elements, max_depth, name)
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        elements, skips = _extract(prepared, name)
    finally:
        if was_enabled:
            gc.enable()
    if not elements:
        detail = f" ({'; '.join(skips.messages())})" if skips.counts else ""
        raise SvgError(f"no drawable elements in {name}{detail}")
    return Scene(
        elements=tuple(elements),
        viewbox=prepared.viewbox,
        size=prepared.size,
        warnings=(*prepared.notes, *skips.messages()),
        source_bytes=source_bytes,
    )


# ---------------------------------------------------------------------------
# Safety checks on the raw bytes and the XML tree


def _maybe_gunzip(data: bytes, max_bytes: int, name: str) -> bytes:
    """Decompress SVGZ content, refusing to inflate beyond ``max_bytes``."""
    if not data.startswith(b"\x1f\x8b"):
        return data
    d = zlib.decompressobj(16 + zlib.MAX_WBITS)
    try:
        out = d.decompress(data, max_bytes + 1)
    except zlib.error as exc:
        raise SvgError(f"not an SVG: {name}: corrupt gzip data ({exc})") from exc
    if len(out) > max_bytes or d.unconsumed_tail:
        raise LimitError(f"{name} decompresses to more than {max_bytes:,} bytes")
    if not d.eof:
        raise SvgError(f"not an SVG: {name}: truncated gzip data")
    return out


def _check_bytes(data: bytes, name: str) -> None:
    """Reject empty input and binary junk before XML parsing."""
    if not data.strip():
        raise SvgError(f"not an SVG: {name} is empty")
    head = data[:4096]
    utf16 = head.startswith((b"\xff\xfe", b"\xfe\xff"))
    if not utf16 and b"\x00" in head:
        raise SvgError(f"not an SVG: {name} holds binary data")


def _parse_xml(source: str | bytes, name: str):
    """Parse with defusedxml: no entities, no external references."""
    import defusedxml
    import defusedxml.ElementTree as DET

    try:
        return DET.fromstring(source, forbid_dtd=False, forbid_entities=True, forbid_external=True)
    except defusedxml.EntitiesForbidden as exc:
        raise SvgError(f"entities are not allowed in SVG input (possible XML attack): {name}") from exc
    except defusedxml.ExternalReferenceForbidden as exc:
        raise SvgError(f"external references are not allowed in SVG input: {name}") from exc
    except defusedxml.DefusedXmlException as exc:
        raise SvgError(f"unsafe XML in {name}: {type(exc).__name__}") from exc
    except ET.ParseError as exc:
        raise SvgError(f"not an SVG: {name}: {exc}") from exc
    except (ValueError, LookupError) as exc:  # unknown or inconsistent encoding declaration
        raise SvgError(f"not an SVG: {name}: {exc}") from exc


def _local(tag) -> str | None:
    """Return the SVG local name of a tag, or None for comments and foreign namespaces."""
    if not isinstance(tag, str):
        return None
    if tag.startswith(SVG_NS):
        return tag[len(SVG_NS) :]
    if tag.startswith("{"):
        return None
    return tag


def _prepare(source: str | bytes, max_elements: int, max_depth: int, name: str) -> _Prepared:
    """Check the XML tree and re-serialise it for svgelements."""
    raw = source if isinstance(source, bytes) else source.encode("utf-8", "replace")
    _check_bytes(raw, name)
    root = _parse_xml(source, name)  # rejects entities (billion laughs, XXE) first
    if _INTERNAL_SUBSET.search(raw, 0, 65536):
        raise SvgError(f"DTD internal subsets are not allowed in SVG input (possible XML attack): {name}")
    if _local(root.tag) != "svg":
        raise SvgError(f"not an SVG: {name}: the root element is <{root.tag}>, not <svg>")

    names: list[str] = []
    paths: dict[str, RawPath] = {}
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
        tag = _local(el.tag)
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
    viewbox = _parse_viewbox(root.get("viewBox"))
    w, h = root.get("width"), root.get("height")
    size = (w or "100%", h or "100%") if (w is not None or h is not None) else None
    return _Prepared(ET.tostring(root), names, paths, expected, viewbox, size, reasons, notes, transforms)


def _path_raw(d: str | None) -> tuple[RawPath, str | None]:
    """Return the segments of path data and, if they may come out empty, why.

    Data the fast parser declines (arcs, or errors) goes to svgelements, which draws
    malformed data up to the first error as SVG asks; data it cannot read at all gives an
    empty path with the reason ``malformed path data``.
    """
    if d is None:
        return RawPath([], [], [], []), None
    raw = raw_from_d(d)
    if raw is not None:
        return raw, None
    from svgelements import Path

    try:
        path = Path(d)
    except (*SVGELEMENTS_ERRORS, RecursionError):
        return RawPath([], [], [], []), "malformed path data"
    try:
        raw = raw_from_segments(path)
    except SVGELEMENTS_ERRORS:
        return RawPath([], [], [], []), "invalid geometry"
    has_arc = "a" in d or "A" in d
    return raw, (None if has_arc else "malformed path data")


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
    if vb is not None and _parse_viewbox(vb) is None:
        del el.attrib["viewBox"]
        notes.append(
            f"ignored the viewBox {_snippet(vb)} of <svg>: it needs 4 numbers with width, height > 0"
        )
    for key in ("width", "height"):
        value = el.get(key)
        if value is not None and not _usable_length(value):
            del el.attrib[key]
            unit = "a positive length in px, pt, pc, mm, cm, in or %"
            notes.append(f"ignored the {key} {_snippet(value)} of <svg>: it must be {unit}")


def _snippet(text: str, n: int = 40) -> str:
    """Return ``text`` quoted for a message, shortened to about ``n`` characters."""
    text = " ".join(text.split())
    return repr(text if len(text) <= n else text[: n - 3] + "...")


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
        if _local(el.tag) == "use":
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
        tag = _local(el.tag)
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


def _parse_viewbox(text: str | None) -> tuple[float, float, float, float] | None:
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


# ---------------------------------------------------------------------------
# Geometry and style extraction with svgelements


def _extract(prepared: _Prepared, name: str) -> tuple[list[Element], _Skips]:
    """Run svgelements on the prepared tree and convert its shapes to elements.

    svgelements resolves structure, CSS and transforms (without ``reify``); path
    data already parsed by :func:`_prepare` is looked up and transformed here in
    one vectorised pass together with all other shapes.
    """
    from svgelements import SVG, Matrix, Path

    try:
        doc = SVG.parse(io.BytesIO(prepared.data), reify=False, parse_display_none=True)
        vbt = doc.viewbox_transform if isinstance(doc, SVG) else ""
    except RecursionError as exc:
        raise LimitError(f"{name}: the SVG is nested too deeply to read") from exc
    except SVGELEMENTS_ERRORS as exc:
        raise _diagnose(prepared, name, exc) from exc

    # Undo the viewBox -> viewport mapping svgelements applies: keep viewBox user units.
    inverse = _IDENTITY
    vp_scale = 1.0
    if vbt:
        m = Matrix(vbt)
        det = m.a * m.d - m.b * m.c
        if det != 0 and math.isfinite(det):
            vp_scale = math.sqrt(abs(det))
            inv = ~m
            inverse = (inv.a, inv.b, inv.c, inv.d, inv.e, inv.f)

    skips = _Skips()
    raws: list[RawPath] = []
    mats: list[tuple[float, ...]] = []
    styles: list[str] = []
    sources: list[str] = []
    produced = 0
    for shape, chain, opacity in _shapes(doc):
        produced += 1
        values = shape.values
        if str(values.get("display", "")).strip().lower() == "none":
            continue
        if str(values.get("visibility", "")).strip().lower() in ("hidden", "collapse"):
            continue
        key = values.get(SRC_ATTR, "")
        raw = prepared.paths.get(key) if type(shape) is Path else None
        try:
            if raw is not None:
                t = shape.transform
                mat = (float(t.a), float(t.b), float(t.c), float(t.d), float(t.e), float(t.f))
            else:
                raw = raw_from_segments(shape.segments(transformed=True))
                mat = _IDENTITY
            if not raw.pts:
                skips.add(prepared.reasons.get(key, "degenerate (zero size)"))
                continue
            style = _style(shape, vp_scale, opacity)
        except SVGELEMENTS_ERRORS:
            skips.add("invalid geometry")
            continue
        if style is None:
            skips.add("non-finite or huge coordinates")
            continue
        raws.append(raw)
        mats.append(mat)
        styles.append(style)
        sources.append(_source(values, chain, prepared.names))
    skips.add("degenerate (zero size)", prepared.expected - produced)
    if not raws:
        return [], skips

    cubics, subpaths, counts = assemble(raws)
    full = _compose(np.array(inverse, dtype=float), np.array(mats, dtype=float).reshape(-1, 6))
    cubics = _apply(cubics, np.repeat(full, counts, axis=0))
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    with np.errstate(invalid="ignore", over="ignore"):
        seg_ok = np.isfinite(cubics).all(axis=1) & (np.abs(cubics).max(axis=1) <= MAX_COORD)
        bad = np.add.reduceat((~seg_ok).astype(np.intp), starts) > 0
        first = cubics[starts, 0]
        spread = np.abs(cubics - np.repeat(first, counts)[:, None]).max(axis=1)
        extent = np.maximum.reduceat(spread, starts)
        flat = ~bad & (extent <= 1e-12 * np.abs(first))
    skips.add("non-finite or huge coordinates", int(bad.sum()))
    skips.add("degenerate (zero size)", int(flat.sum()))
    keep = ~(bad | flat)
    cubics.flags.writeable = False
    subpaths.flags.writeable = False
    ends = starts + counts
    elements = [
        Element(
            cubics=cubics[starts[i] : ends[i]],
            subpaths=subpaths[starts[i] : ends[i]],
            closed=tuple(raws[i].closed),
            style=styles[i],
            source=sources[i],
        )
        for i in np.flatnonzero(keep).tolist()
    ]
    return elements, skips


_IDENTITY = (1.0, 0.0, 0.0, 1.0, 0.0, 0.0)


def _diagnose(prepared: _Prepared, name: str, exc: Exception) -> SvgError:
    """Return the error for a document svgelements failed on, naming the culprit when it can be found."""
    from svgelements import Matrix

    seen: set[str] = set()
    for where, text in prepared.transforms:
        if text in seen:
            continue
        seen.add(text)
        try:
            Matrix(text)
        except (*SVGELEMENTS_ERRORS, RecursionError):
            return SvgError(f"cannot read SVG {name}: invalid transform {_snippet(text)} on {where}")
    detail = str(exc).strip() or type(exc).__name__
    culprit = _failing_element(exc, prepared.names)
    at = f" on {culprit}" if culprit else ""
    return SvgError(f"cannot read SVG {name}: invalid attribute value{at} ({_snippet(detail, 80)[1:-1]})")


def _failing_element(exc: BaseException, names: list[str]) -> str | None:
    """Describe the element svgelements was reading when it failed (from its parse loop's frame), if known."""
    tb = exc.__traceback__
    found = None
    while tb is not None:
        frame = tb.tb_frame
        if frame.f_code.co_name == "parse" and "svgelements" in frame.f_code.co_filename:
            elem = frame.f_locals.get("elem")
            if elem is not None and hasattr(elem, "attrib"):
                found = elem
        tb = tb.tb_next
    if found is None:
        return None
    key = found.attrib.get(SRC_ATTR)
    if key is not None and key.isdigit() and int(key) < len(names):
        return names[int(key)]
    tag = _local(found.tag) or "?"
    el_id = found.attrib.get("id")
    return f"<{tag}{f' id={_snippet(el_id, 20)}' if el_id else ''}>"


def _compose(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Return the affine matrices ``p @ q`` in SVG ``(a, b, c, d, e, f)`` order; ``q`` is ``(n, 6)``."""
    pa, pb, pc, pd, pe, pf = p
    qa, qb, qc, qd, qe, qf = q.T
    with np.errstate(invalid="ignore", over="ignore"):  # non-finite results are skipped later
        return np.stack(
            [
                pa * qa + pc * qb,
                pb * qa + pd * qb,
                pa * qc + pc * qd,
                pb * qc + pd * qd,
                pa * qe + pc * qf + pe,
                pb * qe + pd * qf + pf,
            ],
            axis=1,
        )


def _apply(cubics: np.ndarray, mats: np.ndarray) -> np.ndarray:
    """Apply one affine matrix per segment (``mats`` is ``(k, 6)``) to the control points."""
    x, y = cubics.real, cubics.imag
    a, b, c, d, e, f = (mats[:, i : i + 1] for i in range(6))
    with np.errstate(invalid="ignore", over="ignore"):
        return (a * x + c * y + e) + 1j * (b * x + d * y + f)


def _shapes(doc) -> Iterator[tuple[Shape, tuple[str, ...], float]]:
    """Yield ``(shape, use_chain, opacity)`` for every shape in document order.

    ``use_chain`` holds the source indices of the ``<use>`` elements the shape is
    instanced through; ``opacity`` is the product of the group opacities above it.
    """
    from svgelements import Group, Shape, Use

    stack: list[tuple[object, tuple[str, ...], float]] = [(doc, (), 1.0)]
    while stack:
        node, chain, opacity = stack.pop()
        if isinstance(node, Shape):
            yield node, chain, opacity * _own_opacity(node)
        elif isinstance(node, (Group, Use)):
            own = _own_opacity(node)
            if isinstance(node, Use):
                chain = (*chain, str(node.values.get(SRC_ATTR, "")))
            stack.extend((c, chain, opacity * own) for c in reversed(node))


def _own_opacity(node) -> float:
    """Return the ``opacity`` set on the element itself (not inherited), clamped to [0, 1]."""
    attrs = node.values.get("attributes")
    raw = attrs.get("opacity") if isinstance(attrs, dict) else None
    v = _unit_float(raw, 1.0)
    return 1.0 if v is None else v


def _unit_float(raw, default: float | None) -> float | None:
    """Parse an opacity-like value (number or percentage) clamped to [0, 1]."""
    if raw is None:
        return default
    text = str(raw).strip()
    try:
        v = float(text[:-1]) / 100.0 if text.endswith("%") else float(text)
    except ValueError:
        return default
    if not math.isfinite(v):
        return default
    return min(1.0, max(0.0, v))


def _source(values: dict, chain: tuple[str, ...], names: list[str]) -> str:
    """Describe where a shape came from, e.g. ``circle[3]`` or ``use#u1>path#leaf``."""

    def lookup(idx: str) -> str:
        try:
            return names[int(idx)]
        except (ValueError, IndexError):
            return "?"

    own = lookup(str(values.get(SRC_ATTR, "")))
    return ">".join([*(lookup(i) for i in chain), own])


def _num(v: float) -> str:
    """Format a style number compactly."""
    return f"{v:.6g}"


def _style(shape, vp_scale: float, opacity: float) -> str | None:
    """Return the resolved drawing style of a shape as CSS declarations (None if unusable)."""
    values = shape.values
    parts: list[str] = []
    fill = shape.fill
    if fill is None or fill.value is None:
        parts.append("fill:none")
    else:
        parts.append(f"fill:{fill.hexrgb}")
        fo = _unit_float(values.get("fill-opacity"), None) if "fill-opacity" in values else None
        fo = fill.opacity if fo is None else fo
        if fo < 1.0:
            parts.append(f"fill-opacity:{_num(fo)}")
        rule = str(values.get("fill-rule", "")).strip().lower()
        if rule == "evenodd":
            parts.append("fill-rule:evenodd")
    stroke = shape.stroke
    if stroke is None or stroke.value is None:
        parts.append("stroke:none")
    else:
        parts.append(f"stroke:{stroke.hexrgb}")
        width = shape.implicit_stroke_width
        width = 1.0 if width is None else float(width) / vp_scale
        if not math.isfinite(width):
            return None
        parts.append(f"stroke-width:{_num(max(width, 0.0))}")
        so = _unit_float(values.get("stroke-opacity"), None) if "stroke-opacity" in values else None
        so = stroke.opacity if so is None else so
        if so < 1.0:
            parts.append(f"stroke-opacity:{_num(so)}")
        cap = str(values.get("stroke-linecap", "")).strip().lower()
        if cap in ("round", "square"):
            parts.append(f"stroke-linecap:{cap}")
        join = str(values.get("stroke-linejoin", "")).strip().lower()
        if join in ("round", "bevel", "miter-clip", "arcs"):
            parts.append(f"stroke-linejoin:{join}")
    if opacity < 1.0:
        parts.append(f"opacity:{_num(opacity)}")
    return ";".join(parts)
