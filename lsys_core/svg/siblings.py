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
(well under a microsecond).  A run of plain paths (:attr:`Run.plain`) is recorded without
asking again what the first one answered: with both, the walk of that grid takes 3 of the
11 microseconds an element.

Only shapes whose walk added no note are remembered (a note names its element).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable, KeysView
from operator import itemgetter
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
    decls : dict or None
        Its declarations, when they depend on its style and context only (set by the walk).
    plain : dict or None
        Its declarations when it is a ``<path>`` drawn as one visible record with them, without
        markers or caps: a like sibling with path data draws the same way (set by the walk).
    """

    __slots__ = ("_get", "_keys", "_values", "decls", "el", "facts", "inner", "plain", "tag")

    def __init__(self, el: ET.Element, tag: str, inner: Ctx, facts: StyleFacts) -> None:
        self.el = el
        self.tag = tag
        self.inner = inner
        self.facts = facts
        self.decls: dict[str, str] | None = None
        self.plain: dict[str, str] | None = None
        self._get: Callable[[dict[str, str]], object] | None = None
        self._keys: KeysView[str] | None = None
        self._values: object = None

    def _key(self) -> None:
        """Remember which attributes siblings must share, and their values."""
        attrib = self.el.attrib
        shared = [k for k in attrib if k not in GEOMETRY[self.tag]]
        self._keys = attrib.keys()
        self._get = itemgetter(*shared) if shared else None
        self._values = self._get(attrib) if self._get is not None else None


def same_run(run: Run, el: ET.Element) -> bool:
    """Whether ``el``, a later sibling of ``run.el``, has its tag and attributes apart from geometry.

    The sibling must have the same attribute names (its geometry given the same way) and the
    same values of the others: compared in C (a key view and an ``itemgetter``), 0.3 of the 1.5
    microseconds a copy of the attributes without the geometry cost.
    """
    if el.tag != run.el.tag:
        return False
    if run._keys is None:
        run._key()
    attrib = el.attrib
    if attrib.keys() != run._keys:
        return False
    return run._get is None or run._get(attrib) == run._values
