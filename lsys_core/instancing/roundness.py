"""Shapes that look the same however they are turned, within the tolerance: hand-drawn dots.

The similarity stage calls a shape round (continuously symmetric) when it matches itself at
any angle to a hundredth of its radius.  A dot drawn by hand — four wobbly cubics — is
round to the eye but not to that test, and the matching gives each copy whatever rotation
fits its wobble best: five stamens on a ring come out turned at random angles, and no
constant transform relates neighbours.  Here a terminal counts as round when drawing it
turned by any angle (about its origin, as a rule would) moves its outline by no more than a
share of the tolerance at the largest scale it is drawn at, and by no more than a tenth of its
own radius (a shape small against the tolerance is not round for that).  Its instances then carry no
rotation (the rules may choose one), and every instance's deviation grows by what a turn can
cost, so the derived drawing stays within the tolerance.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from lsys_core.instancing.deviation import pose_deviations
from lsys_core.instancing.merge import without_groups
from lsys_core.instancing.model import Instancing
from lsys_core.instancing.sampling import arc_fractions, sample_elements
from lsys_core.svg.model import Element

__all__ = ["ROUND_RELATIVE", "ROUND_SHARE", "merge_round", "round_within", "turn_deviation"]

#: Share of the tolerance that turning a round terminal may cost its instances.
ROUND_SHARE = 0.5
#: Largest cost of a turn relative to the shape's own RMS radius: a dot drawn by hand moves by a
#: few hundredths of its radius when turned, a leaf by about its length.  Without this bound a
#: leaf far smaller than the tolerance would count as round and lose its visible turns.
ROUND_RELATIVE = 0.1
#: Turns tried (evenly spread over a full turn, the identity excluded).
_TURNS = 36
#: Samples of the quick radial test.
_RADIAL = 64


def turn_deviation(shape: Element, turns: int = _TURNS) -> float:
    """Largest distance of ``shape`` from itself turned about its local origin (its own units).

    Turns ``k·360°/turns`` for ``k = 1 … turns-1`` are measured with the symmetric outline
    distance of :mod:`lsys_core.instancing.deviation`.
    """
    theta = 2.0 * np.pi * np.arange(1, turns) / turns
    a = np.exp(1j * theta)
    which = np.zeros(theta.size, int)
    return float(
        pose_deviations([shape] * theta.size, [shape], which, a, np.zeros(theta.size, complex)).max()
    )


def _radial_spread(shape: Element) -> float:
    """How much the distance of the outline from the origin varies (a lower bound of :func:`turn_deviation`'s scale)."""
    pts = sample_elements([shape], arc_fractions(_RADIAL)).points[0]
    r = np.abs(pts)
    return float(r.max() - r.min())


def round_within(
    shapes: list[Element], inst: Instancing, tolerance: float, share: float = ROUND_SHARE
) -> Instancing:
    """Return ``inst`` with terminals that are round within the tolerance made continuously symmetric.

    Parameters
    ----------
    shapes : list of Element
        Every terminal's shape in its local frame.
    inst : Instancing
        Groups, poses and deviations (:attr:`~lsys_core.instancing.model.Instancing.deviation` filled in).
    tolerance : float
        The tolerance (document units).
    share : float
        Share of the tolerance a turn may cost an instance; its deviation plus that cost must
        also stay within the tolerance.

    Returns
    -------
    Instancing
        Round terminals get symmetry order 0, their instances no rotation, and their
        deviations the bound of a turn's cost (:func:`turn_deviation` times the scale).
    """
    if inst.deviation is None or tolerance <= 0.0:
        return inst
    symmetry, a, dev = inst.symmetry.copy(), inst.a.copy(), inst.deviation.copy()
    for g, shape in enumerate(shapes):
        if symmetry[g] == 0 or shape.cubics.size == 0:
            continue
        members = np.flatnonzero(inst.group == g)
        if members.size == 0:
            continue
        scale = float(np.abs(a[members]).max())
        budget = min(share * tolerance, float((tolerance - dev[members]).min())) / max(scale, 1e-300)
        budget = min(budget, ROUND_RELATIVE * _rms_radius(shape))
        if budget <= 0.0 or _radial_spread(shape) > 2.0 * budget:
            continue  # cheap rejection: a turn moves some rim point by about the radial spread
        cost = turn_deviation(shape)
        if cost > budget:
            continue
        symmetry[g] = 0
        dev[members] += cost * np.abs(a[members])
        a[members] = np.abs(a[members])
    return replace(inst, a=a, symmetry=symmetry, deviation=dev)


def merge_round(
    scene_elements: Sequence[Element], shapes: list[Element], inst: Instancing, tolerance: float
) -> Instancing:
    """Return ``inst`` with round terminals that draw each other's instances within the tolerance merged.

    Two hand-drawn dots are each other's copies whatever turn the matching gave them, and a
    dot whose mirror image happens to fit a little better is still a dot: the similarity stage
    puts such dots in groups of their own (mirror images of the others).  Here every round
    terminal (order 0) tries to draw the instances of the smaller round groups, at their
    centre and at the size their outline has; a group whose every instance lies within the
    tolerance (a turn's cost included) joins it.

    Parameters
    ----------
    scene_elements : sequence of Element
        The input elements.
    shapes : list of Element
        Every terminal's shape in its local frame.
    inst : Instancing
        After :func:`round_within` (deviations filled in).
    tolerance : float
        The tolerance (document units).
    """
    if inst.deviation is None:
        return inst
    round_groups = [g for g in range(len(shapes)) if inst.symmetry[g] == 0 and shapes[g].cubics.size]
    if len(round_groups) < 2:
        return inst
    counts = np.bincount(inst.group, minlength=len(shapes))
    round_groups.sort(key=lambda g: (-counts[g], g))
    rms = {g: _rms_radius(shapes[g]) for g in round_groups}
    group, a, b, dev = inst.group.copy(), inst.a.copy(), inst.b.copy(), inst.deviation.copy()
    gone: set[int] = set()
    for i, g in enumerate(round_groups):
        if g in gone or rms[g] <= 0.0:
            continue
        cost = turn_deviation(shapes[g])
        for h in round_groups[i + 1 :]:
            if h in gone:
                continue
            members = np.flatnonzero(group == h)
            scale = np.abs(a[members]) * rms[h] / rms[g]
            d = pose_deviations(
                [scene_elements[int(j)] for j in members],
                [shapes[g]],
                np.zeros(members.size, int),
                scale,
                b[members],
            )
            d = d + cost * scale
            if (d > tolerance).any() or (d > ROUND_RELATIVE * scale * rms[g]).any():
                continue
            group[members], a[members], dev[members] = g, scale, d
            gone.add(h)
    if not gone:
        return inst
    return without_groups(replace(inst, group=group, a=a, b=b, deviation=dev), sorted(gone))


def _rms_radius(shape: Element) -> float:
    """Root mean square distance of the outline from the origin."""
    pts = sample_elements([shape], arc_fractions(_RADIAL)).points[0]
    return float(np.sqrt(np.mean(np.abs(pts) ** 2)))
