"""Stretched instances (``~(t)``) as terminals of their own, so every renderer draws them exactly.

A derivation records each instance's stretch.  Renderers, the SVG export and the comparisons
read shapes from :attr:`~lsys_core.derive.model.Drawing.terminals`; here every distinct pair
(terminal, stretch) with a non-zero stretch becomes one more terminal, its path the stretched
shape (:func:`~lsys_core.geometry.stretch.stretch_path`), named ``A~1``, ``A~2`` … and
appended after the grammar's terminals.  A stretched instance is therefore never a ``<use>`` of
its unstretched terminal: the structured export writes the stretched shape as a def of its own.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from lsys_core.derive.model import Drawing
from lsys_core.geometry.stretch import stretch_path

__all__ = ["stretched"]

#: Stretches are told apart at this many significant digits (sums along a sequence differ
#: in their last bits).
_DIGITS = 12


def stretched(drawing: Drawing, stretch: np.ndarray) -> Drawing:
    """Return ``drawing`` with its stretched instances drawn by stretched terminals of their own."""
    stretch = np.asarray(stretch, float)
    on = np.flatnonzero(stretch != 0)
    if on.size == 0:
        return drawing
    sym = np.asarray(drawing.symbol, np.int64)
    terminals = list(drawing.terminals)
    k = len(terminals)
    key = np.array([float(f"{v:.{_DIGITS}g}") for v in stretch[on].tolist()])
    pairs, inverse = np.unique(np.column_stack([sym[on], key]), axis=0, return_inverse=True)
    counts: dict[int, int] = {}
    bases = list(range(k))
    for base, t in pairs.tolist():
        base = int(base)
        term = terminals[base]
        counts[base] = counts.get(base, 0) + 1
        terminals.append(replace(term, name=f"{term.name}~{counts[base]}", path=stretch_path(term.path, t)))
        bases.append(base)
    new_sym = sym.copy()
    new_sym[on] = k + inverse.ravel()
    return replace(
        drawing,
        terminals=tuple(terminals),
        symbol=new_sym.astype(np.int32),
        stretch=stretch,
        bases=tuple(bases),
    )
