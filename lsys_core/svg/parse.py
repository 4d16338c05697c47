"""Read an SVG file into a :class:`~lsys_core.svg.model.Scene`, safely.

The bytes are checked and parsed by :mod:`lsys_core.svg.xmlsafe` (size, XML attacks, element and
nesting limits, while reading); :mod:`lsys_core.svg.uses` measures what ``<use>`` references
expand to before anything is expanded; :class:`~lsys_core.svg.walk.Reader` then draws the
document the way a renderer does, into elements (geometry in document coordinates, the style it
draws with, its place in the paint order), definitions and content kept as is.
"""

from __future__ import annotations

import gc
import math
import os
import sys
from collections import Counter
from pathlib import Path

import numpy as np

from lsys_core.errors import LimitError, SvgError
from lsys_core.geometry.paths import MAX_COORD, consecutive
from lsys_core.grammar.model import Verbatim
from lsys_core.quoting import quote_name
from lsys_core.svg.model import Element, Scene
from lsys_core.svg.style import DEFAULT_FONT_SIZE, font_size_px
from lsys_core.svg.tree import Tree, local_name, shown
from lsys_core.svg.uses import check_expansion
from lsys_core.svg.values import IDENTITY, Viewport, parse_length, parse_viewbox, to_user, viewbox_transform
from lsys_core.svg.walk import Ctx, Reader, ShapeRecord, VerbatimRecord
from lsys_core.svg.xmlsafe import (
    DEFAULT_MAX_BYTES,
    DEFAULT_MAX_DEPTH,
    DEFAULT_MAX_ELEMENTS,
    maybe_gunzip,
    read_xml,
)

__all__ = ["DEFAULT_MAX_BYTES", "DEFAULT_MAX_DEPTH", "DEFAULT_MAX_ELEMENTS", "load_svg", "parse_svg"]

_ABSOLUTE = ("", "px", "pt", "pc", "mm", "cm", "in", "q")
#: Segments placed at once by :func:`_placed`.
_BLOCK = 1 << 16
#: Bytes of cubics :func:`_joined` copies without trying to place them where they are.
_SMALL_COPY = 32 << 20


def _display_name(name: str) -> str:
    """A file name for messages: as is when plain, quoted and escaped otherwise (like ``ls``)."""
    return name if name == "<string>" else quote_name(name)


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
        Largest accepted number of elements, read or drawn (``<use>`` references expanded).
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
    shown_name = _display_name(str(p))
    try:
        size = p.stat().st_size
        if size > max_bytes:
            raise LimitError(f"{shown_name} is too large ({size:,} bytes; the limit is {max_bytes:,})")
        with open(p, "rb") as fh:
            data = fh.read(max_bytes + 1)
    except OSError as exc:
        raise SvgError(f"cannot read {shown_name}: {exc.strerror or exc}") from exc
    return parse_svg(data, max_bytes=max_bytes, max_elements=max_elements, max_depth=max_depth, name=str(p))


def parse_svg(
    source: str | bytes,
    *,
    max_bytes: int = DEFAULT_MAX_BYTES,
    max_elements: int = DEFAULT_MAX_ELEMENTS,
    max_depth: int = DEFAULT_MAX_DEPTH,
    name: str = "<string>",
    allow_empty: bool = False,
) -> Scene:
    """Parse SVG text or bytes into a scene (see :func:`load_svg`); ``name`` is used in messages.

    A document that draws nothing (no shapes, ``display="none"`` on the root, ...) is refused
    with :class:`SvgError`, unless ``allow_empty``: then the scene has no elements and a warning
    says the document draws nothing.
    """
    name = _display_name(name)
    data = source.encode("utf-8") if isinstance(source, str) else bytes(source)
    if len(data) > max_bytes:
        raise LimitError(f"{name} is too large ({len(data):,} bytes; the limit is {max_bytes:,})")
    data = maybe_gunzip(data, max_bytes, name)
    # The collector finds no cycles among the objects read here (the reader's own is freed with
    # it later), but walked them all again and again: 30 ms of reading a 50,052-leaf grid.
    was_enabled = gc.isenabled()
    gc.disable()
    old_limit = sys.getrecursionlimit()
    try:
        root = read_xml(data, name, max_elements, max_depth)
        if local_name(root.tag) != "svg":
            tag = str(root.tag).rpartition("}")[2]
            shown_tag = f"<{tag}>" if tag.isprintable() and tag.isascii() else shown(tag)
            raise SvgError(f"not an SVG: {name}: the root element is {shown_tag}, not <svg>")
        tree = Tree(root)
        if tree.of_kind("use"):  # without, the drawing is part of the tree, read within these limits
            check_expansion(tree, max_elements, max_depth, name)
        sys.setrecursionlimit(max(old_limit, 8 * max_depth + 1000))
        reader = Reader(tree, name, max_elements, max_depth)
        viewbox, size, ctx = _root_context(reader, root)
        reader.walk(root, ctx)
        reader.paths.release()
        elements, skips = _elements(reader)
    finally:
        sys.setrecursionlimit(old_limit)
        if was_enabled:
            gc.enable()
    warnings = [*reader.notes, *_skip_messages(skips), *_kept_messages(reader.kept)]
    if not elements:
        reasons = [
            *_skip_messages(skips),
            *(n for n in reader.notes if "cycle" in n),
            *_kept_messages(reader.kept),
        ]
        detail = f" ({'; '.join(reasons)})" if reasons else ""
        if not allow_empty:
            raise SvgError(f"no drawable elements in {name}{detail}")
        warnings.append(f"{name} draws nothing: it has no drawable elements")  # reasons: above
    verbatim = tuple(
        Verbatim(r.order, r.xml, r.what) for r in reader.records if isinstance(r, VerbatimRecord)
    )
    scene = Scene(
        elements=tuple(elements),
        viewbox=viewbox,
        size=size,
        warnings=tuple(dict.fromkeys(warnings)),
        source_bytes=len(data),
        defs=reader.resources.markup(),
        verbatim=verbatim,
    )
    # The reader is in reference cycles (its definitions call back into it): emptied, it and the
    # document's tree are freed here, not by a later collection (41 ms of the cyclic collector,
    # and their memory held for seconds, in the inference of a 50,052-leaf grid).
    reader.__dict__.clear()
    return scene


def _root_context(reader: Reader, root) -> tuple:
    """The canvas (viewBox, size) and the context the root is drawn in."""
    notes = reader.notes
    vb_text = root.get("viewBox")
    vb = parse_viewbox(vb_text)
    if vb_text is not None and vb is None:
        notes.append(
            f"ignored the viewBox {shown(vb_text)} of <svg>: it needs 4 numbers with width, height > 0"
        )
    dims = []
    for key in ("width", "height"):
        text = root.get(key)
        got = parse_length(text) if text is not None else None
        ok = got is not None and math.isfinite(got.value) and got.value > 0 and got.unit in (*_ABSOLUTE, "%")
        if text is not None and not ok:
            unit = "a positive length in px, pt, pc, mm, cm, in or %"
            notes.append(f"ignored the {key} {shown(text)} of <svg>: it must be {unit}")
        dims.append(text.strip() if ok and text else None)
    size = (dims[0] or "100%", dims[1] or "100%") if any(dims) else None
    root_style = reader.cascade.computed(root, {}, DEFAULT_FONT_SIZE)
    reader.root_font = font_size_px(root_style.get("font-size", ""), DEFAULT_FONT_SIZE, DEFAULT_FONT_SIZE)
    px = []
    for i, d in enumerate(dims):
        got = parse_length(d) if d else None
        px.append(to_user(got, Viewport(1, 1), "x" if i == 0 else "y") if got and got.unit != "%" else None)
    ctm = IDENTITY
    if vb is not None:
        vp = Viewport(vb[2], vb[3], reader.root_font, reader.root_font)
        par = (root.get("preserveAspectRatio") or "").strip()
        if par and par.split()[0] != "xMidYMid" and px[0] and px[1]:
            # A non-default alignment is drawn into the viewport here: the canvas becomes the viewport.
            ctm = viewbox_transform(vb, 0.0, 0.0, px[0], px[1], par)
            vb = (0.0, 0.0, px[0], px[1])
    else:
        vp = Viewport(px[0] or 100.0, px[1] or 100.0, reader.root_font, reader.root_font)
    ctx = Ctx(ctm=ctm, style={}, vp=vp)
    return vb, size, ctx


def _elements(reader: Reader) -> tuple[list[Element], Counter]:
    """Transform the shape records into elements (one vectorised pass) and drop unusable ones."""
    skips: Counter = Counter(reader.skips)
    recs = [r for r in reader.records if isinstance(r, ShapeRecord) and not r.hidden]
    arrays = [r.path.cubics for r in recs]
    counts = np.fromiter(map(len, arrays), dtype=np.intp, count=len(arrays))
    if not counts.all():
        kept = np.flatnonzero(counts).tolist()
        recs, arrays, counts = [recs[i] for i in kept], [arrays[i] for i in kept], counts[kept]
    if not recs:
        return [], skips
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    cubics, seg_ok, spread = _placed(recs, arrays, counts, starts)
    del arrays
    with np.errstate(invalid="ignore", over="ignore"):
        bad = np.add.reduceat((~seg_ok).astype(np.intp), starts) > 0
        extent = np.maximum.reduceat(spread, starts)
        flat = ~bad & (extent <= 1e-12 * np.abs(cubics[starts, 0]))
    skips["non-finite or huge coordinates"] += int(bad.sum())
    skips["degenerate (zero size)"] += int(flat.sum())
    cubics.flags.writeable = False
    lows, highs = starts.tolist(), (starts + counts).tolist()
    out: list[Element] = []
    texts: dict[int, str] = {}  # records share declarations (the records hold them: ids stay unique)
    append, new = out.append, object.__new__
    for i in np.flatnonzero(~(bad | flat)).tolist():
        r = recs[i]
        path = r.path
        sub = path.subpaths
        sub.setflags(write=False)  # (0.13 microseconds; through ``flags``, 0.22)
        style = texts.get(id(r.style))
        if style is None:
            style = texts[id(r.style)] = ";".join(map(":".join, r.style.items()))  # name:value;...
        # Made without the frozen dataclass's ``__init__``, which sets each field through
        # ``object.__setattr__``: 1.2 microseconds an element (60 ms of a 50,052-leaf grid), this
        # 0.35; a test checks that the elements equal those the dataclass makes.
        el = new(Element)
        el.__dict__.update(
            cubics=cubics[lows[i] : highs[i]],
            subpaths=sub,
            closed=path.closed,
            style=style,
            source=r.source,
            order=r.order,
        )
        append(el)
    return out, skips


def _placed(
    recs: list[ShapeRecord], arrays: list[np.ndarray], counts: np.ndarray, starts: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """All records' cubics in document coordinates, which segments are usable, and their spread.

    Works in blocks of :data:`_BLOCK` segments, so a path of 10^6 segments needs a few MiB of
    temporaries beside its cubics (one vectorised pass over all of them took about 300 MiB), and
    in place when the records are the only users of their cubics (:func:`_joined`).
    Returns the cubics ``(K, 4)``, finite and within :data:`MAX_COORD` per segment, and every
    segment's largest distance from its record's first point.
    """
    cubics = _joined(arrays, counts)
    first = cubics[starts, 0]  # (a copy, taken before the cubics are placed)
    mats = _matrices([r.ctm for r in recs])
    owner = np.repeat(np.arange(len(recs)), counts)
    with np.errstate(invalid="ignore", over="ignore"):
        first = (mats[:, 0] * first.real + mats[:, 2] * first.imag + mats[:, 4]) + 1j * (
            mats[:, 1] * first.real + mats[:, 3] * first.imag + mats[:, 5]
        )
    ok = np.empty(cubics.shape[0], bool)
    spread = np.empty(cubics.shape[0])
    for lo in range(0, cubics.shape[0], _BLOCK):
        block, who = cubics[lo : lo + _BLOCK], owner[lo : lo + _BLOCK]
        a, b, c, d, e, f = (mats[who, i : i + 1] for i in range(6))
        x, y = block.real.copy(), block.imag.copy()
        with np.errstate(invalid="ignore", over="ignore"):
            block.real = a * x + c * y + e
            block.imag = b * x + d * y + f
            ok[lo : lo + _BLOCK] = np.isfinite(block).all(axis=1) & (np.abs(block).max(axis=1) <= MAX_COORD)
            spread[lo : lo + _BLOCK] = np.abs(block - first[who, None]).max(axis=1)
    return cubics, ok, spread


def _matrices(ctms: list[tuple[float, ...]]) -> np.ndarray:
    """The matrices as an ``(n, 6)`` array, each distinct matrix object converted once.

    Siblings share their matrix object (:mod:`.siblings`): converting 50,052 of them one by one
    took 18 ms, converting the distinct ones and repeating them 5 ms.
    """
    ids = np.fromiter(map(id, ctms), dtype=np.int64, count=len(ctms))  # all alive: ids are distinct
    _, first, inverse = np.unique(ids, return_index=True, return_inverse=True)
    return np.array([ctms[i] for i in first.tolist()], dtype=float).reshape(-1, 6)[inverse.ravel()]


def _joined(arrays: list[np.ndarray], counts: np.ndarray) -> np.ndarray:
    """The records' cubics one after another: their own array when they are views that tile it.

    The path reader converts all paths of a document into one array; when the records hold
    its pieces, in order, one each, and no other view of it exists (its reference count says
    so: the reader has let go of its parsed paths), that array is the concatenation and is
    placed in place, without a copy (61 MiB for a path of 10^6 segments).  The records' cubics
    are not read again once placed (a hidden record may share a drawn one's piece).  Otherwise
    the cubics are copied.

    A copy of at most :data:`_SMALL_COPY` bytes is made without looking: telling whether the
    pieces tile the array costs about 2 microseconds a record (40 ms of reading 20,000 leaves,
    whose copy takes 4 ms and 5 MiB).
    """
    if int(counts.sum()) * 64 <= _SMALL_COPY:
        return np.concatenate(arrays)
    joined = consecutive(arrays)
    owner = None if joined is None else joined.base
    if (
        owner is not None
        and owner.shape == (int(counts.sum()), 4)
        and owner.dtype == complex
        and owner.flags.writeable
        and sys.getrefcount(owner)
        == len(arrays) + 3  # a view per record, ``joined``, ``owner``, the argument
    ):
        return owner
    return np.concatenate(arrays)


def _skip_messages(skips: Counter) -> list[str]:
    return [f"skipped {n} element{'s' if n != 1 else ''}: {reason}" for reason, n in skips.items() if n > 0]


def _kept_messages(kept: Counter) -> list[str]:
    if not kept:
        return []
    parts = [f"{n} {what}" for what, n in kept.items()]
    return ["kept as is: " + ", ".join(parts)]
