"""Geometry and style extraction with svgelements: shapes of the prepared tree to elements."""

from __future__ import annotations

import io
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from lsys_core.errors import LimitError, SvgError
from lsys_core.geometry.paths import (
    MAX_COORD,
    SVGELEMENTS_ERRORS,
    ArrayPath,
    _to_arrays,
    assemble,
    raw_from_segments,
)
from lsys_core.svg.model import Element
from lsys_core.svg.prepare import SRC_ATTR, Prepared
from lsys_core.svg.styles import own_opacity, style_of
from lsys_core.svg.xmlsafe import local_name, snippet

if TYPE_CHECKING:
    from svgelements import Shape

__all__ = ["Skips", "extract"]


@dataclass
class Skips:
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


def extract(prepared: Prepared, name: str) -> tuple[list[Element], Skips]:
    """Run svgelements on the prepared tree and convert its shapes to elements.

    svgelements resolves structure, CSS and transforms (without ``reify``); path
    data already parsed by :func:`prepare` is looked up and transformed here in
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

    skips = Skips()
    raws: list[ArrayPath] = []
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
                raw = ArrayPath(*_to_arrays(raw_from_segments(shape.segments(transformed=True))))
                mat = _IDENTITY
            if not raw.cubics.shape[0]:
                skips.add(prepared.reasons.get(key, "degenerate (zero size)"))
                continue
            style = style_of(shape, vp_scale, opacity)
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


def _diagnose(prepared: Prepared, name: str, exc: Exception) -> SvgError:
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
            return SvgError(f"cannot read SVG {name}: invalid transform {snippet(text)} on {where}")
    detail = str(exc).strip() or type(exc).__name__
    culprit = _failing_element(exc, prepared.names)
    at = f" on {culprit}" if culprit else ""
    return SvgError(f"cannot read SVG {name}: invalid attribute value{at} ({snippet(detail, 80)[1:-1]})")


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
    tag = local_name(found.tag) or "?"
    el_id = found.attrib.get("id")
    return f"<{tag}{f' id={snippet(el_id, 20)}' if el_id else ''}>"


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
            yield node, chain, opacity * own_opacity(node)
        elif isinstance(node, (Group, Use)):
            own = own_opacity(node)
            if isinstance(node, Use):
                chain = (*chain, str(node.values.get(SRC_ATTR, "")))
            stack.extend((c, chain, opacity * own) for c in reversed(node))


def _source(values: dict, chain: tuple[str, ...], names: list[str]) -> str:
    """Describe where a shape came from, e.g. ``circle[3]`` or ``use#u1>path#leaf``."""

    def lookup(idx: str) -> str:
        try:
            return names[int(idx)]
        except (ValueError, IndexError):
            return "?"

    own = lookup(str(values.get(SRC_ATTR, "")))
    return ">".join([*(lookup(i) for i in chain), own])
