"""Stretched copies: elements that are one shape pulled longer along one axis share a terminal.

The bars of a bar chart, signal-strength bars, battery levels and keys of different widths
are one shape at several lengths: plain or rounded rectangles of one width whose heights
differ.  Similarity (§4.1) cannot say so (a stretch is not a similarity): each height became a
terminal of its own, placed one by one, or bars of nearly the same proportions were drawn as
one bar scaled, a little too wide or too narrow.  Here elements are grouped once more, as they
are drawn: element ``j`` is a *stretched copy* of element ``k`` when ``j`` is ``k`` drawn with a
stretch ``t`` (:mod:`lsys_core.geometry.stretch`: the shape cut along the line through its middle
and its halves pulled apart by ``t``), moved, along the canvas's y axis or (both turned by 90°)
its x axis.

Candidates share a key that a stretch does not change: the segment structure, and for every
segment end its offset across the axis from the middle and its distance along the axis to the
nearer end (within the tolerance).  A family needs two lengths at least.  Its shortest element
is the base (so stretches are >= 0 and no half is pulled through the cut), centred on its box;
every member is then checked geometrically, its element against the stretched base at its
place (the outline distance of :mod:`lsys_core.instancing.deviation`), and stays only within
the tolerance; its deviation is recorded like any other.  A family takes whole terminals of the
similarity groups, two at least: an element one terminal draws with its copies (a leaf of a
ring, scaled copies small enough that a stretch also fits them) stays with them.  Members of one length share a
terminal whose path is exactly the stretched base, so whatever measures terminals later
measures what the rules draw; the grammar writes them as the base with ``~(t)``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from lsys_core.geometry.paths import d_from_cubics
from lsys_core.geometry.stretch import stretch_cubics
from lsys_core.grammar.model import Terminal
from lsys_core.instancing.deviation import pose_deviations
from lsys_core.instancing.exact import structure_ids
from lsys_core.instancing.model import Instancing
from lsys_core.sorting import row_groups, stable_argsort
from lsys_core.svg.model import Element, Scene

__all__ = ["stretch_families"]

#: The turn that brings an axis of the canvas onto the local y axis: y itself, then x.
_AXES = (1 + 0j, 1j)
#: Lengths closer than this share of the tolerance are one length (one terminal).
_SAME_LENGTH = 1e-3
#: Shapes shorter than this share of the tolerance along the axis are flat: never stretched.
_FLAT = 1e-3


def _profiles(cubics: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stretch-invariant keys of elements with the same number of segments, ``cubics (m, k, 4)``.

    Returns the quantised key rows (per segment end: offset across from the middle, and the
    distance to the nearer end along y, signed by the end), the lengths along y and the centres
    of the boxes of the segment ends.
    """
    ends = cubics[:, :, [0, 3]].reshape(cubics.shape[0], -1)
    lo, hi = ends.imag.min(axis=1), ends.imag.max(axis=1)
    left, right = ends.real.min(axis=1), ends.real.max(axis=1)
    top = ends.imag - lo[:, None]
    bottom = hi[:, None] - ends.imag
    along = np.where(top <= bottom, top, -bottom)
    across = ends.real - 0.5 * (left + right)[:, None]
    key = np.round(np.concatenate([across, along], axis=1) / tol).astype(np.int64)
    return key, hi - lo, 0.5 * (left + right) + 0.5j * (lo + hi)


def _short(x: float, tol: float) -> float:
    """The decimal with the fewest digits within ``tol`` of ``x`` (a stretch as it will be written)."""
    for digits in range(12):
        y = round(x, digits)
        if abs(y - x) <= tol:
            return y + 0.0
    return x


def _runs(labels: np.ndarray) -> list[np.ndarray]:
    """Positions of equal labels, one array per label in ascending order of the labels, each ascending."""
    order = stable_argsort(labels)
    return np.split(order, np.flatnonzero(np.diff(labels[order])) + 1) if order.size else []


def _stacked(elements: tuple[Element, ...], idx: np.ndarray) -> np.ndarray:
    """The cubics of elements ``idx`` of one structure (as many segments each), ``(m, k, 4)``.

    One copy of them all, flattened (stacking them one by one took 60 ms for 50,052 leaves).
    """
    flat = np.concatenate([elements[i].cubics for i in idx.tolist()], axis=None)
    return np.asarray(flat, complex).reshape(idx.size, flat.size // max(4 * idx.size, 1), 4)


def _families(scene: Scene, free: np.ndarray, tol: float) -> list[tuple[complex, np.ndarray]]:
    """Candidate families ``(axis, elements)``: equal keys, two lengths at least, per axis.

    Elements are grouped by sorting (their structures, then their keys), never by comparing
    every group with all elements.
    """
    elements = scene.elements
    out: list[tuple[complex, np.ndarray]] = []
    taken = ~free
    structure = structure_ids(elements)
    # per structure, its elements met on the first axis and their cubics (the second axis meets
    # some of them again: stacking them again took 16 ms for 50,052 leaves)
    stacks: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    for axis in _AXES:
        avail = np.flatnonzero(~taken)
        # structures in the order they first appear among the available elements
        runs = sorted(_runs(structure[avail]), key=lambda r: int(r[0]))
        for run in runs:
            if run.size < 2:
                continue
            idx = avail[run]
            sid = int(structure[idx[0]])
            if sid not in stacks:
                stacks[sid] = (idx, _stacked(elements, idx))
            known, stack = stacks[sid]
            cubics = (stack if known is idx else stack[np.searchsorted(known, idx)]) * axis
            key, length, _ = _profiles(cubics, tol)
            for sel in _runs(row_groups(list(key.T))[1]):
                sel = sel[length[sel] > _FLAT * tol]  # a flat shape has no halves to pull apart
                members, lengths = idx[sel], length[sel]
                if members.size >= 2 and np.ptp(lengths) > tol:
                    out.append((axis, members))
                    taken[members] = True
    return out


def _family(
    scene: Scene, axis: complex, members: np.ndarray, tol: float
) -> tuple[list[np.ndarray], np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """Check one candidate family.

    Returns its shapes and their stretches, and per member its shape, pose and deviation (inf:
    not kept); None when fewer than two lengths are kept.
    """
    elements = scene.elements
    cubics = _stacked(elements, members) * axis
    _, length, centre = _profiles(cubics, tol)
    base = int(np.argmin(length))
    base_shape = cubics[base] - centre[base]
    stretch = length - length[base]
    quantum = _SAME_LENGTH * tol
    _, which = np.unique(np.round(stretch / quantum), return_inverse=True)
    which = which.ravel()
    mean = np.bincount(which, stretch) / np.bincount(which)
    amounts = np.array([_short(v, quantum) for v in mean.tolist()])
    shapes = [stretch_cubics(base_shape, float(t)) for t in amounts]
    e0 = elements[members[base]]
    local = [Element(s, e0.subpaths, e0.closed) for s in shapes]
    a = np.full(members.size, 1 / axis, complex)
    b = centre / axis
    dev = pose_deviations([elements[i] for i in members], local, which, a, b)
    ok = dev <= tol
    if np.count_nonzero(ok) < 2 or np.unique(which[ok]).size < 2:
        return None
    return shapes, amounts, which, a, b, np.where(ok, dev, np.inf)


def stretch_families(scene: Scene, inst: Instancing, tolerance: float) -> Instancing:
    """Return ``inst`` with stretched copies of a shape drawn as that shape with a stretch.

    Parameters
    ----------
    scene : Scene
        The elements.
    inst : Instancing
        Terminals and poses (after the fidelity split and the pivots).
    tolerance : float
        Largest deviation of an element from its stretched terminal (document units).

    Returns
    -------
    Instancing
        ``inst`` unchanged when no family is found; else the families' elements moved to
        terminals of their own (one per length; shapes in the family's frame, turned by 90°
        when the axis is x), with :attr:`~lsys_core.instancing.model.Instancing.stretch_base`
        and :attr:`~lsys_core.instancing.model.Instancing.stretch` filled in and every
        element's deviation.
    """
    from lsys_core.instancing.fidelity import merge_groups
    from lsys_core.instancing.similarity import terminal_name

    n = inst.a.size
    if n < 2 or tolerance <= 0:
        return inst
    free = np.array([e.cubics.size > 0 for e in scene.elements], bool)
    terms: list[Terminal] = []
    groups: list[np.ndarray] = []
    poses: list[tuple[np.ndarray, np.ndarray]] = []
    moved: list[np.ndarray] = []
    devs: list[np.ndarray] = []
    base_of: list[int] = []
    amounts: list[float] = []
    for axis, members in _families(scene, free, tolerance):
        found = _family(scene, axis, members, tolerance)
        if found is None:
            continue
        shapes, stretch, which, a, b, dev = found
        keep = np.isfinite(dev)
        # whole terminals only: an element stays with copies a terminal draws exactly (a leaf of
        # a ring that a stretch also fits), and one terminal's copies need nothing shared
        groups_in = inst.group[members]
        counts = np.bincount(inst.group, minlength=len(inst.terminals))
        inside = np.bincount(groups_in[keep], minlength=counts.size)
        keep &= inside[groups_in] == counts[groups_in]
        if np.unique(groups_in[keep]).size < 2 or np.unique(which[keep]).size < 2:
            continue
        used = np.unique(which[keep])
        first = len(terms)
        e0 = scene.elements[members[keep][0]]
        for j, u in enumerate(used):
            base_of.append(first if j else -1)
            amounts.append(float(stretch[u] - stretch[used[0]]))
            terms.append(Terminal("", d_from_cubics(shapes[u], e0.subpaths, e0.closed), e0.style))
        remap = np.full(len(shapes), -1)
        remap[used] = np.arange(used.size) + first
        groups.append(remap[which[keep]])
        poses.append((a[keep], b[keep]))
        moved.append(members[keep])
        devs.append(dev[keep])
    if not terms:
        return inst
    bad = np.concatenate(moved)
    order = np.argsort(bad, kind="stable")
    bad = bad[order]
    k = len(terms)
    part = Instancing(
        np.concatenate(groups)[order],
        np.concatenate([p[0] for p in poses])[order],
        np.concatenate([p[1] for p in poses])[order],
        tuple(terms),
        np.ones(k, np.int64),
        np.full(k, -1),
    )
    k0 = np.unique(np.delete(inst.group, bad)).size
    merged = merge_groups(inst, bad, part, terminal_name)
    dev = np.zeros(n) if inst.deviation is None else inst.deviation.copy()
    dev[bad] = np.concatenate(devs)[order]
    stretch_base = np.full(len(merged.terminals), -1)
    stretch = np.zeros(len(merged.terminals))
    base_arr = np.asarray(base_of)
    stretch_base[k0:] = np.where(base_arr >= 0, base_arr + k0, -1)
    stretch[k0:] = amounts
    return replace(merged, deviation=dev, stretch_base=stretch_base, stretch=stretch)
