"""Values of an imported SVG: its drawable elements and canvas (what :mod:`lsys_core.svg` reads).

Geometry is kept as cubic Bézier segments in numpy arrays (lines, quadratics and arcs are
converted on import), so sampling and transforming many elements is vectorised.  Points are
complex numbers ``x + iy`` in SVG user units (y down).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lsys_core.grammar.model import Verbatim

__all__ = ["Element", "Scene", "Verbatim"]


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
    order : int
        Place in the document's paint order (shared numbering with :class:`Verbatim` content);
        -1: not given (the element's index in :attr:`Scene.elements` is its order).
    """

    cubics: np.ndarray
    subpaths: np.ndarray
    closed: tuple[bool, ...]
    style: str = ""
    source: str = ""
    order: int = -1


@dataclass(frozen=True, eq=False)
class Scene:
    """An imported SVG: its elements and canvas.

    ``viewbox`` is ``(x, y, width, height)``; ``size`` the ``width``/``height`` attributes;
    ``warnings`` say what was skipped and why; ``source_bytes`` is the file's size; ``defs`` the
    markup of what element styles refer to by ``url(#id)`` (paint servers, clip paths, masks,
    filters); ``verbatim`` the content kept as is, with its place in the paint order.
    """

    elements: tuple[Element, ...]
    viewbox: tuple[float, float, float, float] | None = None
    size: tuple[str, str] | None = None
    warnings: tuple[str, ...] = ()
    source_bytes: int = 0
    defs: str = ""
    verbatim: tuple[Verbatim, ...] = ()
