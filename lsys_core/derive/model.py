"""The value a derivation produces: terminal instances with their poses."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lsys_core.geometry.transforms import frames_to_matrices
from lsys_core.grammar.model import Terminal

__all__ = ["Drawing"]


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

    def __len__(self) -> int:
        return int(self.symbol.size)

    def matrices(self) -> np.ndarray:
        """Return the ``(n, 3, 3)`` affine pose matrices."""
        return frames_to_matrices(self.a, self.b)
