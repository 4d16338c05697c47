"""Write a :class:`~lsys_core.derive.model.Drawing` as SVG.

Every terminal instance becomes one ``<path>`` element, in paint order — the terminal's
path data, its pose as ``transform="matrix(a b c d e f)"`` and its own style — so a
designer can select and edit each one in a vector editor.  Stroke widths and dashes are in
canvas units (see :meth:`~lsys_core.derive.model.Drawing.stroke_scale`), so they are written
divided by the instance's scale.  Instances whose style refers to ``url(#id)`` (gradients,
patterns, clip paths, masks) are written with their path data in canvas coordinates and no
transform, so the referenced content keeps the canvas's user space.  The drawing's ``defs``
go into ``<defs>``; verbatim content is written at its place in the paint order.

The number formatting is a single ``%`` operation over all instances, so 100,000 instances
export in well under a second.
"""

from __future__ import annotations

import os
import re
from xml.sax.saxutils import escape

import numpy as np

from lsys_core.derive.model import Drawing
from lsys_core.derive.paint import css_decls, css_text
from lsys_core.errors import LsysError
from lsys_core.geometry.paths import d_from_cubics
from lsys_core.geometry.shapes import shape_arrays
from lsys_core.io import write_atomic

__all__ = ["check_finite", "drawing_bounds", "drawing_to_svg", "export_svg", "terminal_points"]

#: Significant digits of pose matrices and of the computed canvas.
DIGITS = 7
#: Fraction of the larger side added around the instances when the canvas is computed.
MARGIN = 0.02

_ATTR_ENTITIES = {'"': "&quot;", "\n": "&#10;", "\r": "&#13;", "\t": "&#9;"}
_LENGTH = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)(?:px)?\s*$")
_NUM = f"%.{DIGITS}g"


def _attr(text: str) -> str:
    """Escape text for a double-quoted XML attribute."""
    return escape(text, _ATTR_ENTITIES)


def _parse_terminal(path: str) -> tuple[np.ndarray, np.ndarray, tuple[bool, ...]]:
    """Return a terminal's cubic arrays (parsed once per distinct path text)."""
    return shape_arrays(path)


def terminal_points(drawing: Drawing) -> list[np.ndarray]:
    """Return the control points of each terminal's path (local frame; empty if it has none)."""
    out = []
    for term in drawing.terminals:
        cubics = _parse_terminal(term.path)[0]
        out.append(np.unique(cubics.ravel()) if cubics.size else np.zeros(0, dtype=complex))
    return out


def _length(text: str | None) -> float | None:
    """Return a plain or ``px`` length, or None."""
    mt = _LENGTH.match(text or "")
    if mt is None:
        return None
    v = float(mt.group(1))
    return v if np.isfinite(v) else None


def _stroke_half_width(style: str) -> float:
    """Return half the stroke width a style draws with (0 without a stroke)."""
    decl = css_decls(style)
    if decl.get("stroke", "none").lower() in ("none", ""):
        return 0.0
    w = _length(decl.get("stroke-width", "1"))
    return max(w if w is not None else 1.0, 0.0) / 2.0


def drawing_bounds(drawing: Drawing, *, chunk: int = 1_000_000) -> tuple[float, float, float, float] | None:
    """Return ``(xmin, ymin, xmax, ymax)`` of all instances, strokes included, or None if empty.

    The bounds of each instance are those of its terminal's transformed control
    points (which contain the curve), widened by half its stroke width.
    """
    n = len(drawing)
    if n == 0:
        return None
    symbol = np.asarray(drawing.symbol)
    a = np.asarray(drawing.a, dtype=complex)
    b = np.asarray(drawing.b, dtype=complex)
    styles, style = drawing.instance_styles()
    half = np.array([_stroke_half_width(s) for s in styles] + [0.0])
    with np.errstate(invalid="ignore", over="ignore"):
        pad = (
            half[np.where((style >= 0) & (style < len(styles)), style, len(styles))] * drawing.stroke_scale()
        )
    pts = terminal_points(drawing)
    lo = np.array([np.inf, np.inf])
    hi = -lo
    for t, p in enumerate(pts):
        idx = np.flatnonzero(symbol == t)
        if idx.size == 0 or p.size == 0:
            continue
        step = max(1, chunk // p.size)
        for s in range(0, idx.size, step):
            sel = idx[s : s + step]
            with np.errstate(invalid="ignore", over="ignore"):  # non-finite bounds give None below
                z = a[sel, None] * p[None, :] + b[sel, None]
                r = pad[sel] * np.abs(a[sel])
                lo = np.minimum(lo, [np.min(z.real.min(axis=1) - r), np.min(z.imag.min(axis=1) - r)])
                hi = np.maximum(hi, [np.max(z.real.max(axis=1) + r), np.max(z.imag.max(axis=1) + r)])
    if not np.all(np.isfinite(lo)) or not np.all(np.isfinite(hi)):
        return None
    return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))


def _canvas(drawing: Drawing) -> tuple[tuple[float, float, float, float], tuple[str, str]]:
    """Return the viewBox and width/height to write."""
    vb = drawing.viewbox
    if vb is None:
        bounds = drawing_bounds(drawing)
        if bounds is None:
            vb = (0.0, 0.0, 1.0, 1.0)
        else:
            x0, y0, x1, y1 = bounds
            w, h = x1 - x0, y1 - y0
            m = MARGIN * max(w, h) or 1.0
            vb = (x0 - m, y0 - m, w + 2 * m, h + 2 * m)
    size = drawing.size
    if size is None:
        size = (f"{vb[2]:.{DIGITS}g}", f"{vb[3]:.{DIGITS}g}")
    return vb, size


def _style_template(style: str) -> tuple[str, list[float]]:
    """Split a style into a ``%``-template whose stroke lengths are placeholders, and those lengths.

    The lengths (``stroke-width``, each ``stroke-dasharray`` entry, ``stroke-dashoffset``) are
    in canvas units; the caller fills in each instance's value in its local frame.
    """
    decls = css_decls(style)
    lengths: list[float] = []
    if decls.get("stroke", "none").lower() not in ("none", ""):
        w = _length(decls.get("stroke-width", "1"))
        if w is not None:
            lengths.append(w)
            decls["stroke-width"] = "\0"
        dashes = [_length(x) for x in re.split(r"[\s,]+", decls.get("stroke-dasharray", "").strip()) if x]
        if dashes and all(x is not None for x in dashes):
            lengths += [float(x or 0.0) for x in dashes]
            decls["stroke-dasharray"] = " ".join(["\0"] * len(dashes))
        off = _length(decls.get("stroke-dashoffset"))
        if off is not None:
            lengths.append(off)
            decls["stroke-dashoffset"] = "\0"
    if not lengths:
        return _attr(style).replace("%", "%%"), []
    return _attr(css_text(decls)).replace("%", "%%").replace("\0", _NUM), lengths


def drawing_to_svg(drawing: Drawing) -> str:
    """Return the SVG document of a drawing, one ``<path>`` per terminal instance, in paint order.

    Instance ``i`` draws ``drawing.terminals[drawing.symbol[i]]`` mapped by
    ``z -> a[i] * z + b[i]``, written as ``matrix(Re a, Im a, -Im a, Re a, Re b, Im b)``.
    The root ``<svg>`` gets the drawing's viewBox and size; without a viewBox one
    is computed from the instances' bounds plus a small margin.  Raises
    :class:`~lsys_core.errors.LsysError` when a pose is not finite.
    """
    check_finite(drawing)
    vb, size = _canvas(drawing)
    head = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
        f'width="{_attr(size[0])}" height="{_attr(size[1])}" '
        f'viewBox="{" ".join(f"{v:.{DIGITS}g}" for v in vb)}">\n'
    )
    if drawing.defs.strip():
        defs = drawing.defs.strip()
        head += (defs if defs.startswith("<defs") else f"<defs>\n{defs}\n</defs>") + "\n"
    n = len(drawing)
    extra: dict[int, str] = {}
    for v in drawing.verbatim:
        k = min(max(int(v.order), 0), n)
        extra[k] = extra.get(k, "") + v.xml.strip() + "\n"
    if n == 0:
        return head + extra.get(0, "") + "</svg>\n"
    styles, style = drawing.instance_styles()
    symbol = np.asarray(drawing.symbol, dtype=np.intp).reshape(n)
    a = np.asarray(drawing.a, dtype=complex).reshape(n)
    b = np.asarray(drawing.b, dtype=complex).reshape(n)
    templates = [_style_template(s) for s in styles]
    width = max((len(t[1]) for t in templates), default=0)
    # Values per instance: the matrix, then its stroke lengths; a mask keeps the ones its format uses.
    values = np.zeros((n, 6 + width))
    values[:, 0] = a.real
    values[:, 1] = a.imag
    values[:, 2] = -a.imag
    values[:, 3] = a.real
    values[:, 4] = b.real
    values[:, 5] = b.imag
    used = np.zeros((n, 6 + width), bool)
    used[:, :6] = True
    if width:
        lengths = np.zeros((len(styles), width))
        count = np.array([len(t[1]) for t in templates])
        for s, (_, ls) in enumerate(templates):
            lengths[s, : len(ls)] = ls
        with np.errstate(invalid="ignore", over="ignore"):
            values[:, 6:] = lengths[style] * drawing.stroke_scale()[:, None]
        used[:, 6:] = np.arange(width)[None, :] < count[style][:, None]
    pair_ids, pair_of = np.unique(np.stack([symbol, style]), axis=1, return_inverse=True)
    pair_of = pair_of.reshape(-1)
    formats = []
    matrix = " ".join([_NUM] * 6)
    for t, s in pair_ids.T.tolist():
        d = _attr(drawing.terminals[t].path).replace("%", "%%")
        css = templates[s][0]
        attr = f' style="{css}"' if css else ""
        formats.append(f'<path d="{d}" transform="matrix({matrix})"{attr}/>\n')
    parts = np.asarray(formats, dtype=object)[pair_of]
    baked = np.array(["url(" in s for s in styles] + [False])[style]
    for i in np.flatnonzero(baked).tolist():  # canvas coordinates: no transform, lengths as given
        parts[i] = _baked_path(drawing, int(symbol[i]), a[i], b[i], styles[style[i]])
        used[i] = False
    head += extra.pop(0, "")  # before every instance (the head is not %-formatted)
    for k, xml in extra.items():
        parts[k - 1] = parts[k - 1] + xml.replace("%", "%%")
    values += 0.0  # no "-0"
    template = "".join(parts.tolist())
    return head + template % tuple(values[used].tolist()) + "</svg>\n"


def _baked_path(drawing: Drawing, t: int, a: complex, b: complex, style: str) -> str:
    """Return one instance as a ``<path>`` with its data in canvas coordinates (``%`` escaped)."""
    cubics, subpaths, closed = _parse_terminal(drawing.terminals[t].path)
    d = d_from_cubics(a * cubics + b, subpaths, closed) if cubics.size else ""
    attr = f' style="{_attr(style)}"' if style else ""
    return f'<path d="{_attr(d)}"{attr}/>\n'.replace("%", "%%")


def check_finite(drawing: Drawing) -> None:
    """Raise :class:`~lsys_core.errors.LsysError` if any pose is not finite (no file can hold it).

    Overflowing scales or distances in a grammar give infinite or NaN poses; this names
    how many instances are affected.
    """
    n = len(drawing)
    if n == 0:
        return
    a = np.asarray(drawing.a, dtype=complex).reshape(n)
    b = np.asarray(drawing.b, dtype=complex).reshape(n)
    bad = ~(np.isfinite(a) & np.isfinite(b))
    if bad.any():
        raise LsysError(
            f"{int(bad.sum()):,} of {n:,} instances have non-finite positions or sizes "
            "(a scale or distance overflows); lower the counter m, the scale or the distances"
        )


def export_svg(drawing: Drawing, path: str | os.PathLike, *, flat: bool = False, head=None) -> None:
    """Write a drawing as SVG to ``path`` atomically (see :func:`~lsys_core.io.write_atomic`).

    The default is the structured document of
    :func:`~lsys_core.render.structured.drawing_to_structured_svg` (shapes once in ``<defs>``,
    instances as ``<use>``, a ``<g>`` per rule call; ``head`` keeps the input's title,
    description and root attributes); ``flat`` writes :func:`drawing_to_svg` instead, one
    baked ``<path>`` per instance, for tools that do not understand ``<use>``.
    """
    if flat:
        write_atomic(path, drawing_to_svg(drawing))
        return
    from lsys_core.render.structured import drawing_to_structured_svg

    write_atomic(path, drawing_to_structured_svg(drawing, head=head))
