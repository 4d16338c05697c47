"""The value similarity detection and inverse instancing produce (§4.1–4.2)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lsys_core.grammar.model import Terminal
from lsys_core.svg.model import Element

__all__ = ["Instancing", "terminal_shapes"]


@dataclass(frozen=True, eq=False)
class Instancing:
    """Result of similarity detection and inverse instancing (§4.1–4.2).

    Attributes
    ----------
    group : ndarray of int, shape (n,)
        Similarity group (terminal index) of every element.
    a, b : ndarray of complex, shape (n,)
        Pose of every element: the element is its group's representative shape
        (in the terminal's local frame) mapped by ``z -> a*z + b``.
    terminals : tuple of Terminal
        One terminal per group: the representative's shape in its local frame.
    symmetry : ndarray of int, shape (groups,)
        Rotational symmetry order of each terminal's shape (1: none, k: k-fold,
        0: continuous, e.g. a circle), so inference may choose among equivalent poses.
    mirrored_of : ndarray of int, shape (groups,)
        For a terminal that is the mirror image of another, that group's index; else -1.
    deviation : ndarray of float, shape (n,), optional
        Distance of every element from its terminal drawn at its pose (document units), once
        measured (:func:`~lsys_core.instancing.fidelity.split_unfaithful`).
    stretch_base : ndarray of int, shape (groups,), optional
        For a terminal that is a stretched copy of another (:mod:`lsys_core.instancing.stretch`),
        that terminal's index (its *base*); else -1.  None: no stretched copies were looked for.
    stretch : ndarray of float, shape (groups,), optional
        The stretch (``~(t)``, in the base's units) that draws each stretched copy from its base;
        its terminal's path is exactly that stretched shape.
    """

    group: np.ndarray
    a: np.ndarray
    b: np.ndarray
    terminals: tuple[Terminal, ...]
    symmetry: np.ndarray
    mirrored_of: np.ndarray
    deviation: np.ndarray | None = None
    stretch_base: np.ndarray | None = None
    stretch: np.ndarray | None = None


def terminal_shapes(inst: Instancing) -> list[Element]:
    """Every terminal's shape as an element in its local frame (the terminal's path data parsed)."""
    from lsys_core.geometry.shapes import shape_arrays

    return [Element(*shape_arrays(t.path)) for t in inst.terminals]
