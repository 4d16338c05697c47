"""The value a derivation produces: terminal instances with their poses."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lsys_core.geometry.transforms import frames_to_matrices
from lsys_core.grammar.model import Terminal, Verbatim

__all__ = ["Calls", "Drawing"]


@dataclass(frozen=True, eq=False)
class Calls:
    """How a drawing's instances come from rule calls: the derivation's call tree.

    A call is one use of a non-terminal in a body (``P1(7)`` in the axiom) and what its
    rewriting draws.  A rule that calls itself at the end of its body with a smaller counter
    (``P1(m): m > 0 -> A f(1) P1(m-1)``) repeats: its repetitions, and the call that ends the
    sequence (``P1(0)``), *continue* the call that started it (``continues``), so a sequence is
    one call and its groups do not nest a level per step.  Call 0 is the axiom.

    Attributes
    ----------
    call : ndarray of int64, shape (n,)
        The call whose body drew each instance (in the drawing's order).
    parent : ndarray of int64, shape (k,)
        The call each call was made from (-1 for the axiom).
    rule : tuple of str
        The rule name of every call ("" for the axiom).
    m : ndarray of int64, shape (k,)
        The counter each call was made with (0 for the axiom and plain rules).
    continues : ndarray of bool, shape (k,)
        Whether a call continues its parent's sequence (see above).
    """

    call: np.ndarray
    parent: np.ndarray
    rule: tuple[str, ...]
    m: np.ndarray
    continues: np.ndarray


@dataclass(frozen=True, eq=False)
class Drawing:
    """A derived picture: terminal instances with their poses and styles, in paint order.

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
    styles : tuple of str
        The distinct CSS styles of the instances (empty: each instance has its terminal's).
    style : ndarray of int32, shape (n,), or None
        Index of each instance's style in ``styles`` (None: its terminal's style).
    defs : str
        SVG markup the styles refer to by ``url(#id)``.
    verbatim : tuple of Verbatim
        Content drawn as is; ``order`` is the number of instances drawn before it.
    calls : Calls or None
        The rule calls the instances come from (None: not known, e.g. a drawing built by hand).
    stretch : ndarray of float, shape (n,), or None
        The stretch every instance was drawn with (``~(t)``, in its terminal's units; None: no
        instance is stretched).  A stretched instance's ``symbol`` is a terminal of its own,
        appended after the grammar's, whose path is the stretched shape (see ``bases``).
    bases : tuple of int
        For every terminal, the grammar terminal it is a stretched copy of (empty: each terminal
        is its own).

    Stroke widths and dashes in the styles are in canvas units, except for terminals whose
    ``scaled`` flag is set (they scale with the instance, see :meth:`stroke_scale`).
    """

    terminals: tuple[Terminal, ...]
    symbol: np.ndarray
    a: np.ndarray
    b: np.ndarray
    rule: np.ndarray
    viewbox: tuple[float, float, float, float] | None = None
    size: tuple[str, str] | None = None
    styles: tuple[str, ...] = ()
    style: np.ndarray | None = None
    defs: str = ""
    verbatim: tuple[Verbatim, ...] = ()
    calls: Calls | None = None
    stretch: np.ndarray | None = None
    bases: tuple[int, ...] = ()

    def __len__(self) -> int:
        return int(self.symbol.size)

    def base_symbol(self) -> np.ndarray:
        """Return every instance's grammar terminal: its own, or the one its stretched shape comes from."""
        sym = np.asarray(self.symbol, np.int64)
        if not self.bases:
            return sym
        return np.asarray(self.bases, np.int64)[sym]

    def instance_styles(self) -> tuple[tuple[str, ...], np.ndarray]:
        """Return the distinct styles and each instance's index into them."""
        if self.style is None:
            return tuple(t.style for t in self.terminals), np.asarray(self.symbol, np.int32)
        return self.styles, np.asarray(self.style, np.int32)

    def stroke_scale(self) -> np.ndarray:
        """Return, per instance, the factor from the styles' stroke widths to its local frame.

        Widths are in canvas units, so an instance drawn at scale ``|a|`` strokes
        ``width / |a|`` of its own units; a ``scaled`` terminal strokes ``width`` (factor 1).
        """
        scale = np.abs(np.asarray(self.a, complex))
        scaled = np.array([t.scaled for t in self.terminals] + [True], bool)
        sym = np.asarray(self.symbol, np.intp)
        sym = np.where((sym >= 0) & (sym < len(self.terminals)), sym, len(self.terminals))
        with np.errstate(divide="ignore"):
            return np.where(scaled[sym] | (scale == 0), 1.0, 1.0 / np.where(scale == 0, 1.0, scale))

    def matrices(self) -> np.ndarray:
        """Return the ``(n, 3, 3)`` affine pose matrices."""
        return frames_to_matrices(self.a, self.b)
