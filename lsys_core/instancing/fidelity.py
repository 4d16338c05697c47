"""Keep every element's shape: split off elements their terminal does not reproduce.

The similarity φ of §4.1 measures how much of two outlines overlap, so at the paper's
threshold 0.6 a bar of height 140 joins a group of bars of height 120.  Drawing the
group's representative in its place would change the art.  Here every element is
compared with its posed terminal (largest distance from the element's samples to the
terminal's outline, and the outline lengths); elements that deviate by more than a
tolerance tied to the similarity threshold are grouped again among themselves, so
repeated variants still share a terminal of their own.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.spatial import cKDTree

from lsys_core.cancel import CancelToken
from lsys_core.instancing.model import Instancing
from lsys_core.svg.model import Element, Scene

__all__ = ["deviation_tolerance", "split_unfaithful"]


def deviation_tolerance(threshold: float) -> float:
    """Allowed deviation, as a fraction of the element's radius, for a similarity threshold."""
    return 0.05 * (1.0 - threshold) + 0.002


def _deviations(
    scene: Scene, inst: Instancing, radius: np.ndarray, tol: float, absolute: float
) -> np.ndarray:
    """Deviation of every element from its posed terminal, in units of its allowance (> 1: too far)."""
    from lsys_core.geometry.shapes import shape_arrays
    from lsys_core.instancing.sampling import arc_fractions, sample_elements

    els = sample_elements(scene.elements, arc_fractions(48))
    terms = tuple(Element(*shape_arrays(t.path)) for t in inst.terminals)
    reps = sample_elements(terms, arc_fractions(512))
    dev = np.zeros(len(scene.elements))
    for g in range(len(inst.terminals)):
        idx = np.flatnonzero(inst.group == g)
        if idx.size == 0:
            continue
        rep = reps.points[g]
        tree = cKDTree(np.column_stack([rep.real, rep.imag]))
        local = (els.points[idx] - inst.b[idx, None]) / inst.a[idx, None]
        d, _ = tree.query(np.column_stack([local.real.ravel(), local.imag.ravel()]))
        far = d.reshape(idx.size, -1).max(axis=1) * np.abs(inst.a[idx])
        length_rep = reps.length[g] * np.abs(inst.a[idx])
        rel_len = np.abs(els.length[idx] - length_rep) / np.maximum(length_rep, 1e-300)
        allowed = np.minimum(tol * radius[idx], absolute)
        dev[idx] = np.maximum(far / np.maximum(allowed, 1e-300), rel_len / tol)
    return dev


def split_unfaithful(
    scene: Scene,
    inst: Instancing,
    radius: np.ndarray,
    *,
    threshold: float = 0.6,
    absolute: float = np.inf,
    cancel: CancelToken | None = None,
    rounds: int = 3,
) -> Instancing:
    """Return ``inst`` with elements that deviate from their terminal moved to new terminals.

    Parameters
    ----------
    scene : Scene
        The imported elements.
    inst : Instancing
        Result of :func:`~lsys_core.instancing.similarity.detect_similarity` on ``scene``.
    radius : ndarray
        Radius of every element (its size for the relative deviation).
    threshold : float
        The similarity threshold used; lower thresholds tolerate larger deviations.
    absolute : float
        Largest deviation in document units, whatever the element's size.
    rounds : int
        Regrouping rounds; what still deviates afterwards becomes a terminal of its own.
    """
    from lsys_core.instancing.similarity import detect_similarity, terminal_name

    tol = deviation_tolerance(threshold)
    for r in range(rounds + 1):
        bad = np.flatnonzero(_deviations(scene, inst, radius, tol, absolute) > 1.0)
        if bad.size == 0:
            return inst
        sub = Scene(tuple(scene.elements[i] for i in bad), scene.viewbox, scene.size)
        if r < rounds:
            part = detect_similarity(sub, threshold=threshold, cancel=cancel)
        else:
            part = _singletons(sub)
        inst = _merge(inst, bad, part, terminal_name)
    return inst


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


def _merge(inst: Instancing, bad: np.ndarray, part: Instancing, terminal_name) -> Instancing:
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
