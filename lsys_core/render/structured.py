"""Write a :class:`~lsys_core.derive.model.Drawing` as structured SVG: shapes once, instances as ``<use>``.

A designer who opens the file sees what repeats:

- every terminal is written once, in ``<defs>``, with its name as ``id`` (``A``, ``leaf``);
  a terminal that is a circle, an ellipse, a rectangle or a line is written as that element
  (:func:`~lsys_core.render.primitives.primitive`) when neither it nor an instance is
  turned; a turned one is written as a ``<path>``, because a widely used reader
  (svgelements 1.9) drops the rotation of a ``<rect>``, ``<circle>`` or ``<ellipse>`` when
  it turns one into points (the rendered pixels agree, its geometry does not);
- every instance is a ``<use xlink:href="#A" transform="…">`` (a clone in Inkscape: edit the
  shape once, every copy follows), with ``translate``/``rotate``/``scale`` written only where
  they are not the identity.  ``xlink:href`` rather than SVG 2's plain ``href``: Inkscape 1.2
  draws nothing for a plain ``href``, and every SVG 2 reader still reads ``xlink:href``;
- every rule call is a ``<g id="P1-1" data-rule="P1" data-m="7">`` around what it drew, nested
  as the calls nest (:class:`~lsys_core.derive.model.Calls`): the layers panel shows the
  hierarchy and selecting a group selects one call (a row of windows, one flower).  The
  repetitions of a sequence continue the call that started it (``Calls.continues``): one
  group per sequence, not one level per step; groups nest at most :data:`MAX_DEPTH` deep
  (deeper calls are written into their ancestor at that depth);
- styles: declarations shared by all instances of a terminal go on its definition, the rest
  on each ``<use>`` (CSS inheritance makes them apply to the shape); stroke widths and dashes
  are in canvas units like in :func:`~lsys_core.render.svg.drawing_to_svg`;
- paint order, ``defs``, verbatim content and instances whose style refers to ``url(#…)``
  (written with baked coordinates) are as in the flat export, and the input document's
  ``<title>``, ``<desc>`` and descriptive root attributes are kept when given
  (:class:`~lsys_core.svg.head.Head`).

If the paint order interleaves the instances of two calls, a call's group is written in parts
(the later parts with ids ``P1-1.2``, ``P1-1.3``, …), so the picture stays exact.

Numbers are formatted by one ``%`` operation over all instances, as in the flat export, and the
terminals' shapes are examined all at once (:func:`~lsys_core.render.primitives_many.primitives`,
:func:`~lsys_core.render.compact.compact_paths`): 10,000 distinct leaves took 15 s one by one and
take under a second so.
"""

from __future__ import annotations

import re
from xml.sax.saxutils import escape

import numpy as np

from lsys_core.derive.model import Calls, Drawing
from lsys_core.derive.paint import css_decls, css_text
from lsys_core.render.compact import compact_paths as _compact_paths
from lsys_core.render.primitives_many import Shape, primitives
from lsys_core.render.svg import DIGITS, _attr, _baked_path, _canvas, _length, check_finite

__all__ = ["drawing_to_structured_svg"]

_NUM = f"%.{DIGITS}g"
_LENGTH_KEYS = ("stroke-width", "stroke-dasharray", "stroke-dashoffset")
#: Styles that draw a shape from its path's start point or vertices: such shapes keep their path.
_PATH_ONLY = ("stroke-dasharray", "marker", "marker-start", "marker-mid", "marker-end")
_ID = re.compile(r"""\bid\s*=\s*["']([^"']*)["']""")
_XLINK = "http://www.w3.org/1999/xlink"
#: Deepest nesting of groups written (SVG readers, this project's included, limit nesting).
MAX_DEPTH = 100


def drawing_to_structured_svg(drawing: Drawing, *, head=None) -> str:
    """Return the structured SVG document of a drawing (see the module docstring).

    Parameters
    ----------
    drawing : Drawing
        The derived instances, in paint order; its ``calls`` give the groups (without them
        the instances are written without groups).
    head : lsys_core.svg.head.Head, optional
        Root attributes, title and description of the input document to keep.

    Raises
    ------
    LsysError
        When a pose is not finite.
    """
    check_finite(drawing)
    n = len(drawing)
    extra_xml = drawing.defs + "".join(v.xml for v in drawing.verbatim)
    ids = _Ids(_ID.findall(extra_xml) + [v for k, v in (head.attributes if head else ()) if k == "id"])
    out = [_root(drawing, head)]
    symbol = np.asarray(drawing.symbol, np.intp).reshape(n)
    b = np.asarray(drawing.b, complex).reshape(n)
    shapes = primitives([term.path for term in drawing.terminals])
    a = _unturned_circles(shapes, symbol, np.asarray(drawing.a, complex).reshape(n))
    styles, style = drawing.instance_styles()
    style = np.asarray(style, np.intp).reshape(n)
    baked = np.array(["url(" in s for s in styles] + [False], bool)[style] if n else np.zeros(0, bool)
    scale = drawing.stroke_scale() if n else np.zeros(0)
    uses, defs = _uses(drawing, shapes, a, symbol, style, styles, scale, ~baked, ids)
    defs_xml = drawing.defs.strip()
    if defs_xml.startswith("<defs"):
        defs_xml = defs_xml[defs_xml.index(">") + 1 : defs_xml.rindex("</defs>")].strip()
    if defs_xml or defs:
        out.append("<defs>\n" + (defs_xml + "\n" if defs_xml else "") + "".join(defs) + "</defs>\n")
    head_text = "".join(out)
    if n == 0:
        return head_text + "".join(v.xml.strip() + "\n" for v in drawing.verbatim) + "</svg>\n"
    values, used, formats = _values(a, b, scale, uses, drawing)
    parts = np.asarray(formats, dtype=object)[uses.key]
    for i in np.flatnonzero(baked).tolist():
        parts[i] = _baked_path(drawing, int(symbol[i]), a[i], b[i], styles[style[i]])
        used[i] = False
    extra: dict[int, str] = {}
    for v in drawing.verbatim:
        k = min(max(int(v.order), 0), n)
        extra[k] = extra.get(k, "") + v.xml.strip().replace("%", "%%") + "\n"
    body = _grouped(parts, drawing.calls, extra, ids)
    values += 0.0  # no "-0"
    return head_text + body % tuple(values[used].tolist()) + "</svg>\n"


class _Ids:
    """Unique, readable XML ids: the wanted name, or the name with a number appended."""

    def __init__(self, taken) -> None:
        self.taken = set(taken)

    def get(self, wanted: str) -> str:
        base = re.sub(r"[^\w.-]", "_", wanted) or "shape"
        if not (base[0].isalpha() or base[0] == "_"):
            base = "_" + base
        name, k = base, 1
        while name in self.taken:
            k += 1
            name = f"{base}.{k}"
        self.taken.add(name)
        return name


def _root(drawing: Drawing, head) -> str:
    vb, size = _canvas(drawing)
    attrs = [("xmlns", "http://www.w3.org/2000/svg"), ("xmlns:xlink", _XLINK)]
    kept = list(head.attributes) if head else []
    attrs += [kv for kv in kept if kv[0].startswith("xmlns:") and kv[1] != _XLINK]
    attrs += [("width", size[0]), ("height", size[1]), ("viewBox", " ".join(f"{v:.{DIGITS}g}" for v in vb))]
    attrs += [kv for kv in kept if not kv[0].startswith("xmlns")]
    text = (
        '<?xml version="1.0" encoding="UTF-8"?>\n<svg '
        + " ".join(f'{k}="{_attr(v)}"' for k, v in attrs)
        + ">\n"
    )
    if head and head.title:
        text += f"<title>{escape(head.title)}</title>\n"
    if head and head.desc:
        text += f"<desc>{escape(head.desc)}</desc>\n"
    return text


class _Uses:
    """Per instance: the key of its ``<use>`` format; per key: its format pieces."""

    def __init__(self, key: np.ndarray, pieces: list[tuple[str, str, tuple[float, ...]]]) -> None:
        self.key = key
        self.pieces = pieces  # (href id, style template, stroke lengths in canvas units)


def _lengths_of(decls: dict[str, str]) -> list[tuple[str, list[float]]] | None:
    """Return the stroke lengths of declarations (canvas units) by key, or None if one is unreadable."""
    out = []
    for key in _LENGTH_KEYS:
        if key not in decls:
            continue
        parts = [p for p in re.split(r"[\s,]+", decls[key].strip()) if p]
        values = [_length(p) for p in parts]
        if not values or any(v is None for v in values):
            return None
        out.append((key, [float(v) for v in values if v is not None]))
    return out


def _stroked(decls: dict[str, str]) -> dict[str, str]:
    """Declarations with the default stroke width written out when the style strokes."""
    if decls.get("stroke", "none").strip().lower() not in ("none", "") and "stroke-width" not in decls:
        return {**decls, "stroke-width": "1"}
    return decls


def _unturned_circles(shapes: list[Shape | None], symbol: np.ndarray, a: np.ndarray) -> np.ndarray:
    """The poses ``a`` with the turns of circles about their own centre taken out (they do not show).

    An inferred ring of round dots turns each dot as it goes round; written as a ``<circle>``
    with no ``rotate`` the instance is shorter and reads as the dot it is.  ``shapes`` holds
    each terminal's basic shape (:func:`~lsys_core.render.primitives.primitive`).
    """
    centred = np.array(
        [
            s is not None and s[0] == "circle" and float(s[1]["cx"]) == 0 and float(s[1]["cy"]) == 0
            for s in shapes
        ]
        + [False],
        bool,
    )
    mine = centred[symbol] if symbol.size else np.zeros(0, bool)
    a = a.copy()
    a[mine] = np.abs(a[mine])
    return a


def _uses(drawing, shapes, a_all, symbol, style, styles, scale, plain, ids: _Ids) -> tuple[_Uses, list[str]]:
    """Choose each terminal's definition and each instance's ``<use>`` format (style part).

    The instances are grouped by terminal, and by terminal and style, with one sort each
    (a mask per terminal made 10,000 distinct terminals quadratic: 4.6 s).
    """
    n = symbol.size
    key = np.zeros(n, np.intp)
    pieces: list[tuple[str, str, tuple[float, ...]]] = []
    defs: list[str] = []
    chosen: list[tuple[str, Shape | None, str, dict[str, str]]] = []  # path, shape, id, common style
    decls = [_stroked(css_decls(s)) for s in styles]
    order = np.flatnonzero(plain)
    if order.size == 0:
        return _Uses(key, pieces), defs
    order = order[np.argsort(symbol[order], kind="stable")]  # by terminal, in paint order
    sym = symbol[order]
    starts = np.flatnonzero(np.r_[True, sym[1:] != sym[:-1]])
    factor = scale[order]
    constant = (
        np.maximum.reduceat(factor, starts) - np.minimum.reduceat(factor, starts)
    ) <= 1e-12 * np.maximum(1.0, np.maximum.reduceat(np.abs(factor), starts))
    a = a_all[order]
    turned = np.logical_or.reduceat((np.abs(a.imag) > 1e-9 * np.abs(a)) | (a.real < 0), starts)
    # (terminal, style) pairs in order: the pieces, numbered as they are made below
    width = int(style.max()) + 1
    pairs, key[order] = np.unique(sym.astype(np.int64) * width + style[order], return_inverse=True)
    pair_term = (pairs // width).tolist()
    pair_style = (pairs % width).tolist()
    at = 0
    for t, first, same, turn in zip(
        sym[starts].tolist(), factor[starts].tolist(), constant.tolist(), turned.tolist(), strict=True
    ):
        used_styles = []
        while at < len(pairs) and pair_term[at] == t:
            used_styles.append(pair_style[at])
            at += 1
        finals = [_scaled(decls[s], first) if same else decls[s] for s in used_styles]
        common = dict(finals[0])
        for d in finals[1:]:
            common = {k: v for k, v in common.items() if d.get(k) == v}
        if not same or any(_lengths_of(d) is None for d in finals):
            common = {k: v for k, v in common.items() if k not in _LENGTH_KEYS}
        term = drawing.terminals[t]
        ref = ids.get(term.name)
        path_only = turn or any(k in d for d in finals for k in _PATH_ONLY)
        shape = None if path_only else shapes[t]
        if shape is not None and "transform" in shape[1]:
            shape = None  # a turned rectangle or ellipse: a path (see the module docstring)
        chosen.append((term.path, shape, ref, common))
        for d in finals:
            rest = {k: v for k, v in d.items() if k not in common}
            template, lengths = _template(rest, varying=not same)
            pieces.append((ref, template, lengths))
    paths = iter(_compact_paths([c[0] for c in chosen if c[1] is None]))
    defs = [
        _definition(next(paths) if shape is None else "", shape, ref, common)
        for _, shape, ref, common in chosen
    ]
    return _Uses(key, pieces), defs


def _scaled(decls: dict[str, str], factor: float) -> dict[str, str]:
    """Declarations with their stroke lengths multiplied by ``factor`` (canvas units to local)."""
    lengths = _lengths_of(decls)
    if not lengths or factor == 1.0:
        return decls
    out = dict(decls)
    for key, values in lengths:
        out[key] = " ".join(f"{v * factor:.{DIGITS}g}" for v in values)
    return out


def _template(decls: dict[str, str], varying: bool) -> tuple[str, tuple[float, ...]]:
    """Return the ``style`` attribute template of a ``<use>`` and the lengths it takes (canvas units)."""
    if not decls:
        return "", ()
    lengths = _lengths_of(decls) if varying else None
    if not lengths:
        return f' style="{_attr(css_text(decls)).replace("%", "%%")}"', ()
    out = dict(decls)
    flat: list[float] = []
    for key, values in lengths:
        out[key] = " ".join(["\0"] * len(values))
        flat += values
    return f' style="{_attr(css_text(out)).replace("%", "%%").replace(chr(0), _NUM)}"', tuple(flat)


def _definition(path: str, shape: Shape | None, ref: str, common: dict[str, str]) -> str:
    """Return a terminal's element for ``<defs>``: its basic ``shape``, or else its (compacted) path."""
    style = f' style="{_attr(css_text(common))}"' if common else ""
    if shape is None:
        return f'<path id="{_attr(ref)}" d="{_attr(path)}"{style}/>\n'
    tag, attrs = shape
    # position attributes are 0 by default
    text = " ".join(
        f'{k}="{_attr(v)}"' for k, v in attrs.items() if not (k in ("x", "y", "cx", "cy") and v == "0")
    )
    return f'<{tag} id="{_attr(ref)}" {text}{style}/>\n'


def _values(a, b, scale, uses: _Uses, drawing) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Return the numbers of every ``<use>`` (a mask says which its format takes) and the formats."""
    n = a.size
    if not uses.pieces:  # every instance is baked (url() paint or clip): no <use> at all
        return np.zeros((n, 4)), np.zeros((n, 4), bool), [""]
    vb = _canvas(drawing)[0]
    size = max(abs(vb[2]), abs(vb[3]), 1e-300)
    s = np.abs(a)
    deg = np.degrees(np.angle(a))
    deg = np.where(deg <= -180.0, deg + 360.0, deg)
    tx = np.where(np.abs(b.real) <= 1e-9 * size, 0.0, b.real)
    ty = np.where(np.abs(b.imag) <= 1e-9 * size, 0.0, b.imag)
    kinds = (
        ((tx != 0) | (ty != 0)).astype(np.intp) * 4
        + (np.abs(deg) > 1e-9).astype(np.intp) * 2
        + (np.abs(s - 1.0) > 1e-12).astype(np.intp)
    )
    width = max((len(p[2]) for p in uses.pieces), default=0)
    values = np.zeros((n, 4 + width))
    values[:, 0], values[:, 1], values[:, 2], values[:, 3] = tx, ty, deg, s
    used = np.zeros((n, 4 + width), bool)
    used[:, 0] = used[:, 1] = kinds >= 4
    used[:, 2] = (kinds & 2) > 0
    used[:, 3] = (kinds & 1) > 0
    if width:
        table = np.zeros((len(uses.pieces), width))
        count = np.zeros(len(uses.pieces), np.intp)
        for i, (_, _, lengths) in enumerate(uses.pieces):
            table[i, : len(lengths)] = lengths
            count[i] = len(lengths)
        with np.errstate(invalid="ignore", over="ignore"):
            values[:, 4:] = table[uses.key] * scale[:, None]
        used[:, 4:] = np.arange(width)[None, :] < count[uses.key][:, None]
    combined = uses.key * 8 + kinds
    keys, inverse = np.unique(combined, return_inverse=True)
    uses.key = inverse.reshape(-1)
    formats = []
    for c in keys.tolist():
        ref, template, _ = uses.pieces[c // 8]
        kind = c % 8
        transform = " ".join(
            t
            for t, on in (
                (f"translate({_NUM} {_NUM})", kind >= 4),
                (f"rotate({_NUM})", kind & 2),
                (f"scale({_NUM})", kind & 1),
            )
            if on
        )
        tattr = f' transform="{transform}"' if transform else ""
        formats.append(f'<use xlink:href="#{_attr(ref).replace("%", "%%")}"{tattr}{template}/>\n')
    return values, used, formats


def _display_groups(calls: Calls) -> np.ndarray:
    """Return, for every call, the call whose group holds it: itself, or the call its sequence continues."""
    k = len(calls.rule)
    parent = np.asarray(calls.parent, np.int64)
    merge = np.asarray(calls.continues, bool) & (parent >= 0)
    rep = np.where(merge, np.where(parent >= 0, parent, 0), np.arange(k))
    while True:
        nxt = rep[rep]
        if np.array_equal(nxt, rep):
            return rep
        rep = nxt


def _grouped(parts: np.ndarray, calls: Calls | None, extra: dict[int, str], ids: _Ids) -> str:
    """Join the instances' ``<use>`` templates, with a ``<g>`` per call around them and verbatim content."""
    n = len(parts)
    if calls is None or len(calls.rule) <= 1:
        group = np.zeros(n, np.intp)
        rep = np.zeros(1, np.intp)
    else:
        rep = _display_groups(calls)
        group = rep[np.asarray(calls.call, np.intp)]
    parent = np.asarray(calls.parent, np.int64) if calls is not None else np.full(1, -1)
    cuts = np.flatnonzero(np.r_[True, group[1:] != group[:-1]]) if n else np.zeros(0, np.intp)
    cuts = np.union1d(cuts, [k for k in extra if 0 < k < n]).astype(np.intp)
    chains: dict[int, tuple[int, ...]] = {0: ()}
    names: dict[int, str] = {}
    opened: dict[int, int] = {}
    per_rule: dict[str, int] = {}
    out: list[str] = []
    stack: list[int] = []
    for s, e in zip(cuts.tolist(), [*cuts[1:].tolist(), n], strict=True):
        chain = _chain(int(group[s]), rep, parent, chains)[:MAX_DEPTH]
        keep = 0
        while keep < min(len(stack), len(chain)) and stack[keep] == chain[keep]:
            keep += 1
        while len(stack) > keep:
            out.append("</g>\n")
            stack.pop()
        for node in chain[keep:]:
            rule = calls.rule[node] if calls is not None else ""
            if node not in names:
                per_rule[rule] = per_rule.get(rule, 0) + 1
                names[node] = ids.get(f"{rule}-{per_rule[rule]}")
                gid = names[node]
            else:
                opened[node] = opened.get(node, 1) + 1
                gid = ids.get(f"{names[node]}.{opened[node]}")
            out.append(f'<g id="{_attr(gid)}" data-rule="{_attr(rule)}">\n'.replace("%", "%%"))
            stack.append(node)
        out.append(extra.get(s, ""))
        out.append("".join(parts[s:e].tolist()))
    out.append("</g>\n" * len(stack))
    out.append(extra.get(n, ""))
    return "".join(out)


def _chain(
    node: int, rep: np.ndarray, parent: np.ndarray, chains: dict[int, tuple[int, ...]]
) -> tuple[int, ...]:
    """Return the groups from the top down to ``node`` (the axiom, call 0, has none)."""
    path = []
    while node not in chains:
        path.append(node)
        node = int(rep[parent[node]])
    chain = chains[node]
    for p in reversed(path):
        chain = (*chain, p)
        chains[p] = chain
    return chain
