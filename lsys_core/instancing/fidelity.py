"""Keep every element's shape within the tolerance of the terminal drawn in its place.

The similarity φ of §4.1 measures how much of two outlines overlap, so at the paper's
threshold 0.6 a bar of height 140 joins a group of bars of height 120.  Drawing the
group's representative in its place would change the art.  Here every element is compared
with its posed terminal (the symmetric outline distance of
:mod:`lsys_core.instancing.deviation`); elements farther than the tolerance — a length in
document units, the user's — are grouped again among themselves, so repeated variants still
share a terminal of their own, and near-identical (hand-drawn) copies within it share one.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from lsys_core.cancel import CancelToken, check
from lsys_core.instancing.deviation import pose_deviations
from lsys_core.instancing.model import Instancing, terminal_shapes
from lsys_core.svg.model import Scene

__all__ = ["deviations", "merge_groups", "split_unfaithful"]


def deviations(scene: Scene, inst: Instancing, *, exact: float = 0.0) -> np.ndarray:
    """Distance of every element from its terminal drawn at its pose (document units)."""
    return pose_deviations(scene.elements, terminal_shapes(inst), inst.group, inst.a, inst.b, exact=exact)


def split_unfaithful(
    scene: Scene,
    inst: Instancing,
    *,
    tolerance: float,
    threshold: float = 0.6,
    cancel: CancelToken | None = None,
    rounds: int = 3,
) -> Instancing:
    """Return ``inst`` with elements farther than ``tolerance`` from their terminal moved to new terminals.

    Parameters
    ----------
    scene : Scene
        The imported elements.
    inst : Instancing
        Result of :func:`~lsys_core.instancing.similarity.detect_similarity` on ``scene``.
    tolerance : float
        Largest deviation of an element from its posed terminal, in document units.
    threshold : float
        The similarity threshold used to group the deviating elements again.
    rounds : int
        Regrouping rounds; what still deviates afterwards becomes a terminal of its own.

    Returns
    -------
    Instancing
        With :attr:`~lsys_core.instancing.model.Instancing.deviation` filled in.
    """
    from lsys_core.instancing.similarity import detect_similarity, terminal_name

    exact = 1e-3 * tolerance
    for r in range(rounds + 1):
        check(cancel)
        dev = deviations(scene, inst, exact=exact)
        bad = np.flatnonzero(dev > tolerance)
        if bad.size == 0:
            return replace(inst, deviation=dev)
        sub = Scene(tuple(scene.elements[i] for i in bad), scene.viewbox, scene.size)
        if r < rounds:
            part = detect_similarity(sub, threshold=threshold, cancel=cancel)
        else:
            part = _singletons(sub)
        inst = merge_groups(inst, bad, part, terminal_name)
    return replace(inst, deviation=deviations(scene, inst, exact=exact))


def _singletons(sub: Scene) -> Instancing:
    from lsys_core.geometry.paths import d_from_cubics
    from lsys_core.grammar.model import Terminal
    from lsys_core.instancing.similarity import terminal_name

    terms, bs = [], []
    for k, e in enumerate(sub.elements):
        c = complex(np.mean(e.cubics))
        terms.append(Terminal(terminal_name(k), d_from_cubics(e.cubics - c, e.subpaths, e.closed), e.style))
        bs.append(c)
    n = len(sub.elements)
    return Instancing(
        np.arange(n),
        np.ones(n, complex),
        np.array(bs, complex),
        tuple(terms),
        np.ones(n, np.int64),
        np.full(n, -1),
    )


def merge_groups(inst: Instancing, bad: np.ndarray, part: Instancing, terminal_name) -> Instancing:
    """Replace the groups of elements ``bad`` by the groups of ``part`` (new terminals)."""
    used = np.unique(np.delete(inst.group, bad))
    remap = np.full(len(inst.terminals), -1)
    remap[used] = np.arange(used.size)
    k0 = used.size
    terminals = [inst.terminals[g] for g in used]
    names = {t.name: terminal_name(i) for i, t in enumerate(terminals)}
    for j, t in enumerate(part.terminals):
        names_new = terminal_name(k0 + j)
        terminals.append(replace(t, name=names_new))
    terminals = [replace(t, name=terminal_name(i)) for i, t in enumerate(terminals)]
    old_mirror = [inst.terminals[g].mirror_of for g in used]
    for i, m in enumerate(old_mirror):
        terminals[i] = replace(terminals[i], mirror_of=names.get(m) if m else None)
    for j in range(len(part.terminals)):
        m = part.mirrored_of[j]
        terminals[k0 + j] = replace(terminals[k0 + j], mirror_of=terminal_name(k0 + m) if m >= 0 else None)
    group = remap[inst.group]
    group[bad] = k0 + part.group
    a = inst.a.copy()
    b = inst.b.copy()
    a[bad] = part.a
    b[bad] = part.b
    mirrored = np.concatenate(
        [
            np.where(inst.mirrored_of[used] >= 0, remap[np.maximum(inst.mirrored_of[used], 0)], -1),
            np.where(part.mirrored_of >= 0, part.mirrored_of + k0, -1),
        ]
    )
    symmetry = np.concatenate([inst.symmetry[used], part.symmetry])
    return Instancing(group, a, b, tuple(terminals), symmetry, mirrored)
