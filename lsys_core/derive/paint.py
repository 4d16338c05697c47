"""Resolve the style of every derived instance: terminal style, occurrence paint, ``paint:`` table.

An instance is painted with its terminal's base style, replaced by the named style of the
occurrence's paint (``A{s1}``), replaced in turn by the named style the grammar's ``paint:``
table gives the instance; then the occurrence's properties, evaluated at the counter of the
rule application (``A{opacity: 0.2 + 0.1*m}``), set their declarations.  ``hue`` rotates the fill and stroke
colours (HSL, degrees).  Only distinct combinations are resolved, so a drawing of a million
instances in a few styles costs a few numpy calls.
"""

from __future__ import annotations

import colorsys
from functools import lru_cache

import numpy as np

from lsys_core.grammar.model import Grammar, Paint
from lsys_core.svg.verbatim import style_text as css_text  # one writer of style text

__all__ = ["css_decls", "css_text", "paint_z", "resolve_styles", "rotate_hue"]


def paint_z(paints: list[Paint], paint: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Return each instance's paint-order value from its occurrence's ``z`` property (0 without)."""
    z = np.zeros(paint.size)
    for p, pt in enumerate(paints):
        for key, lin in pt.props:
            if key == "z":
                sel = paint == p
                z[sel] += lin.c0 + lin.cd * m[sel]
    return z


def css_decls(style: str) -> dict[str, str]:
    """Split CSS declarations ``"a:b;c:d"`` into an ordered dict with lower-case keys."""
    out: dict[str, str] = {}
    for part in style.split(";"):
        key, sep, value = part.partition(":")
        if sep and key.strip():
            out[key.strip().lower()] = value.strip()
    return out


@lru_cache(maxsize=4096)
def _rgb(color: str) -> tuple[float, float, float] | None:
    """Return a CSS colour's RGB in [0, 1], or None for ``none``, ``url(...)`` and unknown text."""
    c = color.strip().lower()
    if not c or c in ("none", "transparent", "currentcolor") or c.startswith("url("):
        return None
    from svgelements import Color

    col = Color(c)
    if col.value is None:
        return None
    return col.red / 255.0, col.green / 255.0, col.blue / 255.0


def rotate_hue(color: str, degrees: float) -> str:
    """Return ``color`` with its hue turned by ``degrees`` (HSL) as ``#rrggbb``; others unchanged."""
    rgb = _rgb(color)
    if rgb is None:
        return color
    h, lum, s = colorsys.rgb_to_hls(*rgb)
    r, g, b = colorsys.hls_to_rgb((h + degrees / 360.0) % 1.0, lum, s)
    return "#{:02x}{:02x}{:02x}".format(*(round(min(max(v, 0.0), 1.0) * 255) for v in (r, g, b)))


def _number(v: float) -> str:
    return f"{float(v):.6g}"


def _apply_props(decls: dict[str, str], paint: Paint, m: int) -> None:
    """Set the paint's properties at counter ``m`` in ``decls``."""
    for key, lin in paint.props:
        v = float(lin.c0 + lin.cd * m)
        if key == "z":
            continue
        if key == "hue":
            for k in ("fill", "stroke"):
                if k in decls:
                    decls[k] = rotate_hue(decls[k], v)
        elif key == "stroke-width":
            decls[key] = _number(max(v, 0.0))
        else:
            decls[key] = _number(min(max(v, 0.0), 1.0))


def resolve_styles(
    g: Grammar, paints: list[Paint], sym: np.ndarray, paint: np.ndarray, m: np.ndarray, pos: np.ndarray
) -> tuple[tuple[str, ...], np.ndarray]:
    """Return the distinct styles and each instance's index into them.

    Parameters
    ----------
    g : Grammar
        Its terminals' base styles, named styles and ``paint:`` table.
    paints : list of Paint
        The compiled occurrence paints; ``paint`` indexes them (-1: none).
    sym, paint, m, pos : ndarray
        Terminal, paint, counter and derived-string position of every instance.
    """
    n = sym.size
    only_z = all(p.style is None and all(k == "z" for k, _ in p.props) for p in paints)
    if not g.paint and only_z:
        return tuple(t.style for t in g.terminals), sym.astype(np.int32)
    named = {s.name: s.css for s in g.styles}
    table_names = list(dict.fromkeys(p for p in g.paint if p is not None))
    table = np.full(n, -1, np.int64)
    if g.paint:
        codes = np.array([-1 if p is None else table_names.index(p) for p in g.paint], np.int64)
        listed = pos < codes.size
        table[listed] = codes[pos[listed]]
    varying = np.array([any(v.cd != 0 for k, v in p.props if k != "z") for p in paints] + [False], bool)
    mm = np.where(varying[paint], m, 0)
    keys = np.stack([sym.astype(np.int64), paint.astype(np.int64), table, mm], axis=1)
    uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
    texts: dict[str, int] = {}
    index = np.empty(len(uniq), np.int32)
    for u, (t, p, s, mu) in enumerate(uniq.tolist()):
        base = g.terminals[t].style
        if p < 0 and s < 0:
            css = base
        else:
            decls = css_decls(base)
            if p >= 0 and paints[p].style is not None:
                decls = css_decls(named.get(paints[p].style, ""))
            if s >= 0:
                decls = css_decls(named.get(table_names[s], ""))
            if p >= 0:
                _apply_props(decls, paints[p], mu)
            css = css_text(decls)
        index[u] = texts.setdefault(css, len(texts))
    return tuple(texts), index[inverse.reshape(-1)]
