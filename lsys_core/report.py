"""What the inference reports: its result, and how far the derived drawing is from the input.

:class:`InferenceResult` is what :func:`~lsys_core.pipeline.infer` returns.

Every input element is matched to the derived instance of its terminal nearest to its pose;
its deviation is that of its shape (the terminal at its own pose) plus how far the pose
moved, an upper bound of the outline distance, measured exactly
(:mod:`lsys_core.instancing.deviation`) where the bound exceeds the tolerance.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from lsys_core.grammar.model import Grammar
from lsys_core.instancing.model import Instancing
from lsys_core.svg.model import Scene

__all__ = [
    "InferenceResult",
    "as_instancing",
    "bounds",
    "deviation",
    "displacement",
    "element_circles",
    "matched_poses",
    "measurer",
    "reproduction_error",
]


def element_circles(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Return the centre and radius of every element's control polygon (vectorised)."""
    sizes = np.array([e.cubics.shape[0] for e in scene.elements])
    pts = np.concatenate([e.cubics.reshape(-1) for e in scene.elements])
    owner = np.repeat(np.arange(sizes.size), sizes * 4)
    cnt = np.bincount(owner, minlength=sizes.size)
    cen = (np.bincount(owner, pts.real, sizes.size) + 1j * np.bincount(owner, pts.imag, sizes.size)) / cnt
    rad = np.zeros(sizes.size)
    np.maximum.at(rad, owner, np.abs(pts - cen[owner]))
    return cen, rad


def bounds(scene: Scene) -> tuple[complex, complex]:
    """Corners of the bounding box of all control points (it holds every outline)."""
    pts = np.concatenate([e.cubics.reshape(-1) for e in scene.elements])
    return complex(pts.real.min(), pts.imag.min()), complex(pts.real.max(), pts.imag.max())


def as_instancing(drawing, inst: Instancing):
    """Return ``drawing`` with its instances numbered by the terminals of ``inst``.

    A grammar's terminals are the instancing's, but for stretched copies
    (:mod:`lsys_core.instancing.stretch`), which the grammar draws as their base with a stretch:
    every instance is given the terminal of ``inst`` its terminal's name and its stretch draw
    (the nearest stretch of that base), so it can be matched with the input elements.
    """
    from dataclasses import replace

    index = {t.name: g for g, t in enumerate(inst.terminals)}
    sym = np.asarray(drawing.symbol, np.int64)
    if drawing.bases:
        sym = np.asarray(drawing.bases, np.int64)[sym]
    names = np.array([index.get(t.name, -1) for t in drawing.terminals] + [-1], np.int64)
    out = names[np.where((sym >= 0) & (sym < len(drawing.terminals)), sym, len(drawing.terminals))]
    if inst.stretch_base is not None and inst.stretch is not None:
        stretch = np.zeros(sym.size) if drawing.stretch is None else np.asarray(drawing.stretch, float)
        for g in np.unique(inst.stretch_base[inst.stretch_base >= 0]):
            choices = np.concatenate([[g], np.flatnonzero(inst.stretch_base == g)])
            amounts = np.concatenate([[0.0], inst.stretch[choices[1:]]])
            mine = np.flatnonzero(out == g)
            pick = np.argmin(np.abs(stretch[mine, None] - amounts[None, :]), axis=1)
            out[mine] = choices[pick]
    return replace(drawing, terminals=inst.terminals, symbol=out.astype(np.int32), stretch=None, bases=())


#: Derived poses matched to the input elements (:func:`matched_poses`), or None when instances are missing.
Matched = tuple[np.ndarray, np.ndarray] | None


def matched_poses(inst: Instancing, sizes: np.ndarray, drawing) -> Matched:
    """The derived pose matched to every input element, or None when instances are missing.

    Each input element is matched to the nearest derived instance of its terminal (by
    position, and by rotation and scale at the shape's radius: copies turned about one point
    share their position).  Turns a shape's symmetry hides do not count: a line turned by
    180° is the same line.  :func:`deviation` and :func:`displacement` read it (a 50,052-leaf
    grid's drawing takes 40 ms to match: once for both).
    """
    a_out = np.zeros_like(inst.a)
    b_out = np.zeros_like(inst.b)
    order = inst.symmetry
    for g in range(len(inst.terminals)):
        mine = np.flatnonzero(inst.group == g)
        theirs = np.flatnonzero(drawing.symbol == g)
        if mine.size != theirs.size:
            return None
        if mine.size == 0:
            continue

        def poses(
            a: np.ndarray, b: np.ndarray, size: float = float(sizes[g]), k: int = int(order[g])
        ) -> np.ndarray:
            # k-fold symmetric: the turn counted modulo 2π/k (its k-th power), at the rim's speed
            turn = np.abs(a) * (np.exp(1j * k * np.angle(a)) / k if k > 0 else 1.0)
            return np.column_stack([b.real, b.imag, size * turn.real, size * turn.imag])

        ta, tb = drawing.a[theirs], drawing.b[theirs]
        _, j = cKDTree(poses(ta, tb)).query(poses(inst.a[mine], inst.b[mine]))
        a_out[mine], b_out[mine] = _same_turn(ta[j], inst.a[mine], int(order[g])), tb[j]
    return a_out, b_out


def _same_turn(a: np.ndarray, like: np.ndarray, k: int) -> np.ndarray:
    """Poses ``a`` turned by the multiple of ``2π/k`` that brings them nearest ``like`` (they draw the same)."""
    if k == 1:
        return a
    turn = np.angle(like / a)
    if k > 1:
        turn = np.round(turn * k / (2 * np.pi)) * 2 * np.pi / k
    return a * np.exp(1j * turn)


def displacement(inst: Instancing, sizes: np.ndarray, matched: Matched) -> float:
    """Largest displacement of an input element's pose in the derived poses ``matched`` (:func:`matched_poses`).

    Translation plus turn and scale at the shape's reach, in document units; inf if an
    instance is missing.
    """
    if matched is None:
        return float("inf") if inst.a.size else 0.0
    a, b = matched
    d = np.abs(inst.b - b) + sizes[inst.group] * np.abs(inst.a - a)
    return float(d.max()) if d.size else 0.0


def reproduction_error(inst: Instancing, sizes: np.ndarray, drawing) -> float:
    """Largest displacement of an input element's pose in ``drawing`` (document units; inf if one is missing)."""
    return displacement(inst, sizes, matched_poses(inst, sizes, drawing))


def deviation(
    inst: Instancing, sizes: np.ndarray, matched: Matched, shape_dev: np.ndarray, limit: float, measure
) -> float:
    """Largest distance of a derived element from its input element (document units).

    ``matched``: the derived poses (:func:`matched_poses`).  The shape's deviation plus its
    pose's displacement bounds it; where that bound exceeds ``limit``, the derived outline
    is measured.
    """
    if matched is None:
        return float("inf")
    a, b = matched
    bound = shape_dev + np.abs(inst.b - b) + sizes[inst.group] * np.abs(inst.a - a)
    over = np.flatnonzero(bound > limit)
    if over.size:
        bound[over] = measure(over, a[over], b[over])
    return float(bound.max()) if bound.size else 0.0


def measurer(scene: Scene, inst: Instancing) -> Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]:
    """``measure(elements, a, b)``: the deviation of input elements from their terminals at poses ``a, b``."""
    from lsys_core.geometry.shapes import shape_arrays
    from lsys_core.instancing.deviation import pose_deviations
    from lsys_core.svg.model import Element

    shapes = [Element(*shape_arrays(t.path)) for t in inst.terminals]

    def measure(elements: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return pose_deviations([scene.elements[i] for i in elements], shapes, inst.group[elements], a, b)

    return measure


@dataclass(frozen=True, eq=False)
class InferenceResult:
    """What :func:`~lsys_core.pipeline.infer` returns: the grammar, the instancing, timings and how good the rules are.

    Attributes
    ----------
    grammar : Grammar
        The inferred rules.
    instancing : Instancing
        Terminals and poses of the input elements (with each element's shape deviation).
    stages : dict of str to float
        Seconds per stage (and ``reproduction_error``, the placement error over the diagonal).
    seconds : float
        Total time.
    log : tuple of str
        One line per rule written.
    tolerance : float
        The tolerance used (document units).
    max_deviation : float
        Largest distance of a derived element from its input element (document units): its
        shape's deviation plus the displacement of its pose, an upper bound.
    explained : float
        Share of the elements placed by repetition rules, not one by one.
    description_bits : tuple of float
        Description length before (every element its own shape, placed one by one) and
        after (the grammar), in bits at the precision the tolerance implies.
    """

    grammar: Grammar
    instancing: Instancing
    stages: dict[str, float]
    seconds: float
    log: tuple[str, ...] = field(default=())
    tolerance: float = 0.0
    max_deviation: float = 0.0
    explained: float = 0.0
    description_bits: tuple[float, float] = (0.0, 0.0)
