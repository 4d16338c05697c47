"""How big a document becomes once its ``<use>`` references are expanded, computed without expanding.

The graph of child and reference edges is walked once, depth first and iteratively, with the size
and depth of each element's expansion memoised: a definition used a thousand times is measured
once, so a chain of 450 nested ``<use>`` levels, each doubling the drawing, is found to be too
big in linear time instead of being expanded.  Reference cycles contribute nothing here (the
reader skips the ``<use>`` that closes a cycle, as renderers do).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from lsys_core.errors import LimitError
from lsys_core.svg.tree import SVG_NS, Tree, href_of, local_name

__all__ = ["check_expansion", "has_use"]

#: Elements whose content is never drawn in place (only through a reference, or not at all).
_NOT_IN_FLOW = frozenset(
    {"defs", "clipPath", "mask", "marker", "pattern", "symbol", "linearGradient", "radialGradient"}
)


def check_expansion(tree: Tree, max_elements: int, max_depth: int, name: str) -> int:
    """Return the number of elements the drawing expands to; raise if beyond the limits.

    Raises
    ------
    LimitError
        More than ``max_elements`` elements, or nesting deeper than ``max_depth`` levels,
        once references are expanded.
    """
    if not has_use(tree.root):
        size, height = _tree_size(tree.root)
        if size <= max_elements and height <= max_depth:
            return size
    visiting, done = 1, 2
    state: dict[int, int] = {}
    total: dict[int, int] = {}
    depth: dict[int, int] = {}

    def successors(el: ET.Element) -> list[ET.Element]:
        tag = local_name(el.tag)
        succ = [c for c in el if isinstance(c.tag, str) and local_name(c.tag) not in _NOT_IN_FLOW]
        if tag == "use":
            target = tree.target(href_of(el))
            if target is not None:
                succ.append(target)
        return succ

    stack = [tree.root]
    while stack:
        el = stack[-1]
        key = id(el)
        st = state.get(key)
        if st is None:
            state[key] = visiting
            stack.extend(s for s in successors(el) if id(s) not in state)
            continue
        stack.pop()
        if st == done:
            continue
        succ = [s for s in successors(el) if state.get(id(s)) == done]  # cycles contribute nothing
        t = 1 + sum(total[id(s)] for s in succ)
        d = 1 + max((depth[id(s)] for s in succ), default=0)
        if t > max_elements:
            raise LimitError(f"{name} expands to more than {max_elements:,} elements (<use> fan-out)")
        if d > max_depth:
            raise LimitError(f"{name}: <use> references nest more than {max_depth} levels deep")
        total[key], depth[key] = t, d
        state[key] = done
    return total.get(id(tree.root), 1)


def has_use(root: ET.Element) -> bool:
    """Whether the document has a ``<use>`` (found at the speed of ElementTree's own search)."""
    return any(next(root.iter(tag), None) is not None for tag in (SVG_NS + "use", "use"))


def _tree_size(root: ET.Element) -> tuple[int, int]:
    """The number of elements drawn in place and their nesting depth, for a document without ``<use>``.

    Without references the expansion is the tree itself, counted a level at a time: the general
    walk took 0.12 s (6 microseconds per element) reading 20,000 leaves.  Its results are the
    same; the general walk still tells what is beyond a limit.
    """
    size = height = 0
    level = [root]
    while level:
        size += len(level)
        height += 1
        level = [
            c for el in level for c in el if isinstance(c.tag, str) and local_name(c.tag) not in _NOT_IN_FLOW
        ]
    return size, height
