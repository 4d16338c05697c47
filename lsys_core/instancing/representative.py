"""One representative per group of near-identical shapes, and poses as regular as the tolerance allows.

Hand-drawn copies differ a little from each other.  The group's terminal is drawn in place of
every member, so it should be the member that deviates least from all the others: the
*medoid* (the member whose largest deviation from the rest is smallest), not the first one
found.  Members drawn a little larger or smaller than the representative (a ray of 4.1 among
rays of 4) keep the representative's size when all members of the group stay within the
tolerance at that size, so that the arrangement reads as regular.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from lsys_core.instancing.deviation import pose_deviations
from lsys_core.instancing.model import Instancing, terminal_shapes
from lsys_core.svg.model import Element, Scene

__all__ = ["medoids", "regular_scales"]

#: Members tried as the representative of a group (those nearest the current one).
_CANDIDATES = 8
#: Share of the tolerance a regularised pose may use, leaving the rest to the rules' placement.
_POSE_SHARE = 0.5
#: Groups whose members deviate less than this share of the tolerance keep their representative.
_MEDOID_FROM = 0.05
#: Deviations below this share of the tolerance are rounding: exact copies.
_EXACT = 1e-3


def _pulled_back(element: Element, a: complex, b: complex) -> Element:
    """The element in its terminal's local frame (its pose undone)."""
    return replace(element, cubics=(np.asarray(element.cubics) - b) / a)


def medoids(scene: Scene, inst: Instancing, tolerance: float) -> Instancing:
    """Return ``inst`` with each group's terminal replaced by the member closest to all the others.

    Only groups whose members deviate from their terminal (by more than
    :data:`_MEDOID_FROM` of the tolerance) are examined; the poses are kept (they are relative to the group's frame, in
    which the new representative lies where its member is).
    """
    from lsys_core.geometry.paths import d_from_cubics

    dev = inst.deviation
    if dev is None:
        return inst
    terminals = list(inst.terminals)
    new_dev = dev.copy()
    for g in range(len(terminals)):
        members = np.flatnonzero(inst.group == g)
        if members.size < 3 or dev[members].max() <= _MEDOID_FROM * tolerance:
            continue
        order = members[np.argsort(dev[members], kind="stable")]
        tried = order[:_CANDIDATES]
        shapes = [_pulled_back(scene.elements[c], inst.a[c], inst.b[c]) for c in tried]
        els = [scene.elements[j] for j in members]
        worst = np.empty(tried.size)
        devs = []
        for k in range(tried.size):
            d = pose_deviations(
                els,
                shapes,
                np.full(members.size, k),
                inst.a[members],
                inst.b[members],
                exact=_EXACT * tolerance,
            )
            devs.append(d)
            worst[k] = d.max() + 1e-9 * d.mean()
        best = int(np.argmin(worst))
        if worst[best] >= dev[members].max():
            continue
        shape = shapes[best]
        c = int(tried[best])
        path = d_from_cubics(shape.cubics, shape.subpaths, shape.closed)
        terminals[g] = replace(terminals[g], path=path, style=scene.elements[c].style)
        new_dev[members] = devs[best]
    return replace(inst, terminals=tuple(terminals), deviation=new_dev)


def regular_scales(scene: Scene, inst: Instancing, tolerance: float) -> Instancing:
    """Return ``inst`` with the poses of one-size groups scaled exactly to their terminal's size.

    A group is of one size when every member would deviate at most :data:`_POSE_SHARE` of
    ``tolerance`` drawn at scale 1 (about its centroid); groups whose sizes really differ (a
    shrinking spiral) keep their scales.
    """
    if inst.deviation is None:
        return inst
    off = np.flatnonzero(np.abs(np.abs(inst.a) - 1.0) > 1e-9)
    if off.size == 0:
        return inst
    shapes = terminal_shapes(inst)
    a1 = inst.a[off] / np.abs(inst.a[off])
    # keep the centroid of the terminal's outline where it was
    groups, where = np.unique(inst.group[off], return_inverse=True)
    cen = np.array([np.mean(shapes[g].cubics) for g in groups.tolist()])[where.ravel()]
    b1 = inst.b[off] + (inst.a[off] - a1) * cen
    d = pose_deviations(
        [scene.elements[i] for i in off], shapes, inst.group[off], a1, b1, exact=_EXACT * tolerance
    )
    fail = np.zeros(len(shapes), bool)
    fail[inst.group[off][d > _POSE_SHARE * tolerance]] = True
    ok = ~fail[inst.group[off]]
    a, b, dev = inst.a.copy(), inst.b.copy(), inst.deviation.copy()
    a[off[ok]], b[off[ok]], dev[off[ok]] = a1[ok], b1[ok], d[ok]
    return replace(inst, a=a, b=b, deviation=dev)
