"""Immutable values passed between the stages of the pipeline.

``SVG file ─svg.parse→ Scene ─similarity→ Instancing ─inference→ Grammar ─derive→ Drawing``

Geometry is kept as cubic Bézier segments in numpy arrays (lines, quadratics and
arcs are converted on import), so sampling and transforming many elements is
vectorised.  Points are complex numbers ``x + iy`` in SVG user units (y down).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .grammar.model import Terminal

__all__ = ["Drawing", "Element", "Instancing", "Scene"]


@dataclass(frozen=True, eq=False)
class Element:
    """One drawable shape of the input, transforms applied.

    Attributes
    ----------
    cubics : ndarray of complex, shape (k, 4)
        Control points of the element's cubic Bézier segments in document coordinates.
    subpaths : ndarray of int, shape (k,)
        Index of the subpath each segment belongs to.
    closed : tuple of bool
        Whether each subpath is closed (``Z``).
    style : str
        Resolved CSS declarations (``fill:#fff;stroke:none;...``) as the element is drawn.
    source : str
        A short description of where it came from (tag and id), for messages.
    """

    cubics: np.ndarray
    subpaths: np.ndarray
    closed: tuple[bool, ...]
    style: str = ""
    source: str = ""


@dataclass(frozen=True, eq=False)
class Scene:
    """An imported SVG: its elements and canvas.

    ``viewbox`` is ``(x, y, width, height)``; ``size`` the ``width``/``height`` attributes;
    ``warnings`` say what was skipped and why; ``source_bytes`` is the file's size.
    """

    elements: tuple[Element, ...]
    viewbox: tuple[float, float, float, float] | None = None
    size: tuple[str, str] | None = None
    warnings: tuple[str, ...] = ()
    source_bytes: int = 0


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
    """

    group: np.ndarray
    a: np.ndarray
    b: np.ndarray
    terminals: tuple[Terminal, ...]
    symmetry: np.ndarray
    mirrored_of: np.ndarray


@dataclass(frozen=True, eq=False)
class Drawing:
    """A derived picture: terminal instances with their poses.

    Attributes
    ----------
    terminals : tuple of Terminal
        The terminal shapes; ``symbol`` indexes into it.
    symbol : ndarray of int32, shape (n,)
        Terminal index of each instance.
    a, b : ndarray of complex, shape (n,)
        Pose of each instance (``z -> a*z + b``); :meth:`matrices` gives 3×3 affines.
    rule : ndarray of int32, shape (n,)
        Index of the rule whose production emitted the instance (-1: the axiom).
    viewbox, size
        The SVG canvas, as in :class:`~lsys_core.grammar.model.Grammar`.
    """

    terminals: tuple[Terminal, ...]
    symbol: np.ndarray
    a: np.ndarray
    b: np.ndarray
    rule: np.ndarray
    viewbox: tuple[float, float, float, float] | None = None
    size: tuple[str, str] | None = None
    meta: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return int(self.symbol.size)

    def matrices(self) -> np.ndarray:
        """Return the ``(n, 3, 3)`` affine pose matrices."""
        from .geometry import frames_to_matrices

        return frames_to_matrices(self.a, self.b)
