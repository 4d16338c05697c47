"""Small constructed scenes for the inference tests: a shape placed at given poses."""

from __future__ import annotations

import numpy as np

from lsys_core.derive.model import Drawing
from lsys_core.geometry.transforms import DEG
from lsys_core.svg.model import Element, Scene

#: An asymmetric leaf: two cubics from its base at the origin (local frame).
LEAF = np.array(
    [[0, 3 + 4j, 9 + 4j, 14 + 1j], [14 + 1j, 9 - 2j, 4 - 2j, 0]],
    dtype=complex,
)
#: A hook (open polyline as degenerate cubics), clearly different from the leaf.
HOOK = np.array([[0, 0, 18j, 18j], [18j, 18j, 10 + 20j, 10 + 20j], [10 + 20j, 10 + 20j, 7 + 18j, 7 + 18j]])


def pose(x: float, y: float, heading: float = 0.0, scale: float = 1.0) -> tuple[complex, complex]:
    """Return the frame ``(a, b)`` of a turtle at ``(x, y)`` with ``heading`` degrees and ``scale``."""
    return scale * np.exp(1j * heading * DEG), complex(x, y)


def place(shape: np.ndarray, frames, style: str = "fill:none;stroke:#000") -> list[Element]:
    """Return one element per frame: ``shape`` mapped by ``z -> a*z + b``."""
    out = []
    for a, b in frames:
        c = a * shape + b
        out.append(Element(c, np.zeros(len(c), int), (False,), style))
    return out


def scene(*groups: list[Element]) -> Scene:
    """Return a scene of the given element lists."""
    return Scene(tuple(e for g in groups for e in g))


def turtle_sequence(n: int, start, step) -> list[tuple[complex, complex]]:
    """Frames of ``P(n-1)`` with ``P(m) -> A T P(m-1)``: ``T`` is ``(alpha, d, s, beta)``."""
    from lsys_core.geometry.transforms import rel_from_t4

    A, B = rel_from_t4(*step)
    a, b = start
    out = []
    for _ in range(n):
        out.append((a, b))
        a, b = a * A, b + a * B
    return out


def make_drawing(terminals, symbol, a, b, viewbox=None, size=None, rule: int = -1) -> Drawing:
    """Return a Drawing of ``terminals`` with instances ``symbol`` at poses ``a``, ``b``."""
    n = len(symbol)
    return Drawing(
        terminals=tuple(terminals),
        symbol=np.asarray(symbol, dtype=np.int32),
        a=np.asarray(a, dtype=complex),
        b=np.asarray(b, dtype=complex),
        rule=np.full(n, rule, np.int32),
        viewbox=viewbox,
        size=size,
    )
