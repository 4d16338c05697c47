"""Round a candidate's numbers to the simplest values the tolerance allows.

A measured transform carries the noise of the drawing: ``+(89.59842) f(-0.0000992)
*(0.9999986) +(-134.59842)`` is a turn by -45° about the shape's origin.  Every number is
replaced by the decimal with the fewest digits within the precision its place in the rule
needs, so that the derivation of the whole candidate moves no node by more than a tenth of
the tolerance (angles and scales act at the candidate's reach, and every step compounds
over the longest application).  Offsets shorter than that precision vanish, and with them
the heading of the offset: what is left is written as the designer would write it.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import replace

import numpy as np

from lsys_core.geometry.transforms import rel_from_t4, t4_from_rel
from lsys_core.hierarchy.candidates import (
    BranchCandidate,
    Candidate,
    LinearCandidate,
    PairCandidate,
    SeqCandidate,
)
from lsys_core.hierarchy.emit import nice
from lsys_core.hierarchy.gain import group_reach
from lsys_core.hierarchy.nodes import Nodes

__all__ = ["PLAIN_SCALE", "PLAIN_TURN", "SHARE", "plainer", "snapped"]

#: Share of the tolerance the rounding of one candidate may spend (:func:`symmetrize
#: <lsys_core.pipeline.symmetrize>`, whose purpose is regularity, lets it spend more).
SHARE = 0.1


def _snap_transform(
    A: complex, B: complex, length: float, angle: float, scale: float
) -> tuple[complex, complex]:
    al, d, s, be = (float(v) for v in t4_from_rel(A, B))
    turn = nice(float((al + be + 180.0) % 360.0 - 180.0), abs_tol=angle)  # the shape's own turn first
    al = 0.0 if d <= length else nice(al, abs_tol=angle)
    d = 0.0 if d <= length else nice(d, abs_tol=length)
    s = nice(s, abs_tol=scale)
    A2, B2 = rel_from_t4(al, d, s, turn - al)
    return complex(A2), complex(B2)


def snapped(c: Candidate, nodes: Nodes, eps: float, share: float = SHARE) -> Candidate:
    """Return ``c`` with its numbers rounded within ``share`` of the tolerance ``eps`` (see the module docstring)."""
    steps = max(int(c.groups.lengths.max()) - 1, 1)
    if isinstance(c, BranchCandidate):
        steps = max(c.depths) + 1
    budget = share * eps / steps
    reach = max(float(group_reach(nodes, c.groups).max()), 1e-12)
    length = budget
    angle = math.degrees(budget / reach)
    scale = budget / reach
    if isinstance(c, (SeqCandidate, PairCandidate)):
        A, B = _snap_transform(c.A, c.B, length, angle, scale)
        return replace(c, A=A, B=B)
    if isinstance(c, BranchCandidate):
        return replace(
            c,
            first=_snap_transform(*c.first, length, angle, scale),
            second=_snap_transform(*c.second, length, angle, scale),
        )
    if isinstance(c, LinearCandidate):
        slope = angle / steps
        return replace(
            c,
            alpha0=nice(c.alpha0, abs_tol=angle),
            d=nice(c.d, abs_tol=length),
            s=nice(c.s, abs_tol=scale),
            beta0=nice(c.beta0, abs_tol=angle),
            d_alpha=nice(c.d_alpha, abs_tol=slope),
            d_beta=nice(c.d_beta, abs_tol=slope),
        )
    return c


#: Turns (degrees) and scale changes (relative) up to these may be dropped by :func:`plainer`.
PLAIN_TURN = 2.0
PLAIN_SCALE = 0.02


def plainer(c: Candidate) -> Candidate | None:
    """``c`` with a small turn and scale change dropped and its step along an axis, or None.

    A row of hand-placed copies measures a turn of a fraction of a degree per step, and a
    step a degree or so off the row's axis (a copy drawn 0.08 units low moves the measured
    direction of a 4.7-unit step by 1°).  The designer meant a pure step along the axis:
    when that still places every copy within the tolerance it is the simpler rule (one
    number fewer).  The axis is that of the shape's own frame (a multiple of 90°).
    """
    if not isinstance(c, (SeqCandidate, PairCandidate)):
        return None
    if not (0.0 < abs(c.A) < math.inf) or not cmath.isfinite(c.B):
        return None  # a degenerate (collapsing or non-finite) transform has no plain step to try
    A, B = c.A, c.B
    turn = math.degrees(float(np.angle(A)))
    if abs(turn) <= PLAIN_TURN and abs(math.log(abs(A))) <= PLAIN_SCALE:
        A = 1.0 + 0j
    d = abs(B)
    if d > 0.0:
        heading = math.degrees(cmath.phase(B))
        quarter = round(heading / 90.0)
        if abs(heading - 90.0 * quarter) <= PLAIN_TURN:
            B = d * (1.0 + 0j, 1j, -1.0 + 0j, -1j)[quarter % 4]
    if A == c.A and B == c.B:
        return None
    return replace(c, A=A, B=B)
