"""Markup of content kept as is: self-contained copies of input subtrees with their styles baked in.

A copy must draw the same outside its document: its cascaded declarations (from style sheets,
presentation attributes and ``style``) are written into its ``style`` attributes, what it inherits
from its ancestors goes on a wrapping ``<g>`` together with the transform to document
coordinates, ``xlink:href`` becomes ``href``, and everything it refers to by ``url(#id)`` or
``href="#id"`` is copied into the scene's definitions (:meth:`.resources.Resources.raw`).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable

from lsys_core.svg.style import INHERITED
from lsys_core.svg.tree import XLINK_HREF, local_name
from lsys_core.svg.values import IDENTITY, Matrix, parse_transform

__all__ = ["matrix_text", "references", "style_text", "subtree_markup", "wrap"]

#: Attributes that carry references to other elements by ``url(#id)``.
_URL_PROPS = ("fill", "stroke", "clip-path", "mask", "filter", "marker-start", "marker-mid", "marker-end")


def matrix_text(m: Matrix) -> str:
    """Write a matrix for a ``transform`` attribute."""
    return "matrix(" + " ".join(f"{v:.10g}" for v in m) + ")"


def style_text(decls: dict[str, str]) -> str:
    """Write declarations as a ``style`` attribute value."""
    return ";".join(f"{k}:{v}" for k, v in decls.items())


def references(decls: dict[str, str], el: ET.Element | None = None) -> list[str]:
    """Return the ids referenced by ``url(#id)`` values and (for ``el``) a local ``href``."""
    out = []
    for k in _URL_PROPS:
        v = decls.get(k)
        if v and "url(" in v:
            start = v.find("url(") + 4
            end = v.find(")", start)
            ref = v[start:end].strip().strip("'\"").strip()
            if ref.startswith("#"):
                out.append(ref[1:])
    if el is not None:
        href = el.get("href") or el.get(XLINK_HREF)
        if href and href.strip().startswith("#"):
            out.append(href.strip()[1:])
    return out


def subtree_markup(
    el: ET.Element,
    specified: Callable[[ET.Element], dict[str, str]],
    on_reference: Callable[[str], None],
    keep_id: Callable[[str], bool],
    max_nodes: int = 1_000_000,
) -> str:
    """Copy an element and its content with styles baked in; return its markup.

    ``specified(el)`` gives an element's cascaded declarations; ``on_reference(id)`` is called for
    every referenced id (to copy the target); ``keep_id(id)`` says whether an element keeps its id
    (ids must stay unique in the output).
    """
    copy = _copy(el, specified, on_reference, keep_id, [max_nodes])
    return ET.tostring(copy, encoding="unicode", short_empty_elements=True)


def _copy(el, specified, on_reference, keep_id, budget) -> ET.Element:
    budget[0] -= 1
    tag = local_name(el.tag)
    new_tag = tag if tag is not None else el.tag
    out = ET.Element(new_tag)
    decls = specified(el) if tag is not None else {}
    own_transform = "transform" in decls
    if own_transform:
        # Written as the attribute (renderers differ on the CSS property), in matrix form, which
        # reads the same in both syntaxes; an unreadable transform is left out, as it is ignored.
        decls = dict(decls)
        m = parse_transform(decls.pop("transform"), css=True)
        if m is not None and m != IDENTITY:
            out.set("transform", matrix_text(m))
    for k, v in el.attrib.items():
        if k == "style" or k in decls or (k == "transform" and own_transform):
            continue
        if k == XLINK_HREF:
            k = "href"
        if k == "id" and not keep_id(v):
            continue
        out.set(k, v)
    if decls:
        out.set("style", style_text(decls))
    for ref in references(decls, el):
        on_reference(ref)
    out.text = el.text
    for child in el:
        if not isinstance(child.tag, str):
            continue
        if budget[0] <= 0:
            break
        c = _copy(child, specified, on_reference, keep_id, budget)
        c.tail = child.tail
        out.append(c)
    return out


def inherited_declarations(computed: dict[str, str]) -> dict[str, str]:
    """The inherited part of a computed style (what a copy must receive from a wrapper)."""
    return {k: v for k, v in computed.items() if k in INHERITED}


def wrap(inner: str, ctm: Matrix, inherited: dict[str, str], extra: dict[str, str] | None = None) -> str:
    """Wrap markup in a ``<g>`` carrying a transform, inherited properties and group effects."""
    attrs = []
    if ctm != IDENTITY:
        attrs.append(f'transform="{matrix_text(ctm)}"')
    decls = dict(inherited)
    if extra:
        decls.update(extra)
    if decls:
        attrs.append(f'style="{_escape(style_text(decls))}"')
    if not attrs:
        return inner
    head = "<g" + "".join(" " + a for a in attrs) + ">"
    return f"{head}{inner}</g>"


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;")
