"""Runs of sibling shapes that differ only in their geometry: what their walk shares.

Grids, charts and patterns write thousands of sibling shapes whose attributes are equal apart
from their geometry (``d``, ``x``, ``points``, ...) and their ``id``.  Before it reads the
geometry, the walk (:meth:`.walk.Reader.walk`) works out for each element its specified and
computed style, what the walk needs of it (:mod:`.facts`), its own transform and the context it
is drawn in: about 5 of the 11 microseconds each element of a 50,052-leaf grid cost.  All of that
follows from the element's tag, its other attributes, its parent's context and the style sheet;
without style sheet rules (a selector can tell siblings apart by position, id or class), a
sibling with the same tag and the same other attributes gets the same.  A :class:`Run` keeps
it for the next siblings, which :func:`same_run` recognises by comparing their attributes
(a dictionary copy and comparison, well under a microsecond).

Only shapes whose walk added no note are remembered (a note names its element).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from lsys_core.svg.facts import StyleFacts
    from lsys_core.svg.records import Ctx

__all__ = ["GEOMETRY", "Run", "same_run"]

#: Attributes of each shape that only its geometry (or its name, ``id``) is read from.
GEOMETRY: dict[str, tuple[str, ...]] = {
    "path": ("d", "id"),
    "rect": ("x", "y", "width", "height", "rx", "ry", "id"),
    "circle": ("cx", "cy", "r", "id"),
    "ellipse": ("cx", "cy", "rx", "ry", "id"),
    "line": ("x1", "y1", "x2", "y2", "id"),
    "polyline": ("points", "id"),
    "polygon": ("points", "id"),
}


class Run:
    """What the walk worked out for a shape before its geometry, for its like siblings.

    Attributes
    ----------
    el : Element
        The shape it was worked out for.
    tag : str
        Its SVG local name.
    inner : Ctx
        The context it is drawn in (its style, matrix, viewport).
    facts : StyleFacts
        What the walk reads from its style.
    attributes : dict or None
        Its attributes apart from :data:`GEOMETRY` (set by :func:`same_run` when first compared).
    decls : dict or None
        Its declarations, when they depend on its style and context only (set by the walk).
    """

    __slots__ = ("attributes", "decls", "el", "facts", "inner", "tag")

    def __init__(self, el: ET.Element, tag: str, inner: Ctx, facts: StyleFacts) -> None:
        self.el = el
        self.tag = tag
        self.inner = inner
        self.facts = facts
        self.attributes: dict[str, str] | None = None
        self.decls: dict[str, str] | None = None


def _free(el: ET.Element, tag: str) -> dict[str, str]:
    """The attributes of a shape apart from its geometry and id."""
    got = dict(el.attrib)
    for name in GEOMETRY[tag]:
        got.pop(name, None)
    return got


def same_run(run: Run, el: ET.Element) -> bool:
    """Whether ``el``, a later sibling of ``run.el``, has its tag and attributes apart from geometry."""
    if el.tag != run.el.tag:
        return False
    if run.attributes is None:
        run.attributes = _free(run.el, run.tag)
    return _free(el, run.tag) == run.attributes
