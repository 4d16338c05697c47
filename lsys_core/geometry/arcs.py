"""Elliptical arcs (SVG path ``A``) as cubic Bézier pieces, vectorised over many arcs.

The endpoint parameterisation is converted to centre form (SVG 1.1 F.6.5, radii grown to fit as
F.6.6 says), and each arc is cut into pieces of at most 45 degrees, each approximated by one cubic
(error far below 1e-6 of the radius).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["ArcSetup", "arc_cubics", "arc_setup", "fill_arcs"]


#: Arcs converted at a time (bounds the temporary memory of the conversion).
_ARC_CHUNK = 65536


class ArcSetup(NamedTuple):
    """Centre parameterisation of arcs (SVG F.6.5) and the number of cubic pieces of each."""

    cx: np.ndarray
    cy: np.ndarray
    rx: np.ndarray
    ry: np.ndarray
    cphi: np.ndarray
    sphi: np.ndarray
    theta1: np.ndarray
    dtheta: np.ndarray
    pieces: np.ndarray


def arc_setup(p0: np.ndarray, p3: np.ndarray, arc: np.ndarray) -> ArcSetup:
    """Convert endpoint to centre parameterisation (radii grown where too small), vectorised."""
    rx, ry = np.abs(arc[:, 0]), np.abs(arc[:, 1])
    phi = np.deg2rad(np.mod(arc[:, 2], 360.0))
    large, sweep = arc[:, 3] != 0, arc[:, 4] != 0
    cphi, sphi = np.cos(phi), np.sin(phi)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        hx, hy = (p0.real - p3.real) / 2.0, (p0.imag - p3.imag) / 2.0
        x1, y1 = cphi * hx + sphi * hy, -sphi * hx + cphi * hy
        grow = np.sqrt(np.maximum((x1 / rx) ** 2 + (y1 / ry) ** 2, 1.0))
        rx, ry = rx * grow, ry * grow
        num = (rx * ry) ** 2 - (rx * y1) ** 2 - (ry * x1) ** 2
        den = (rx * y1) ** 2 + (ry * x1) ** 2
        coef = np.sqrt(np.maximum(num / den, 0.0))
        coef = np.where(large == sweep, -coef, coef)
        cxp, cyp = coef * rx * y1 / ry, -coef * ry * x1 / rx
        cx = cphi * cxp - sphi * cyp + (p0.real + p3.real) / 2.0
        cy = sphi * cxp + cphi * cyp + (p0.imag + p3.imag) / 2.0
        theta1 = np.arctan2((y1 - cyp) / ry, (x1 - cxp) / rx)
        theta2 = np.arctan2((-y1 - cyp) / ry, (-x1 - cxp) / rx)
        dtheta = np.mod(theta2 - theta1, 2 * np.pi)
        dtheta = np.where(~sweep & (dtheta > 0), dtheta - 2 * np.pi, dtheta)
        dtheta = np.where(np.isfinite(dtheta), dtheta, 0.0)
        count = np.maximum(np.ceil(np.abs(dtheta) / (np.pi / 4) - 1e-9), 1).astype(np.intp)
    return ArcSetup(cx, cy, rx, ry, cphi, sphi, theta1, dtheta, count)


def _arc_pieces(a: ArcSetup, p0: np.ndarray, p3: np.ndarray) -> np.ndarray:
    """Return the cubic pieces of arcs (all pieces of the first arc, then of the next...)."""
    count = a.pieces
    # Boundary angles: count + 1 per arc; piece j of an arc runs from boundary j to j + 1.
    nb = count + 1
    own = np.repeat(np.arange(count.size), nb)
    j = np.arange(own.size) - np.repeat(np.cumsum(nb) - nb, nb)
    delta = a.dtheta / count
    ang = a.theta1[own] + j * delta[own]
    ca, sa = np.cos(ang), np.sin(ang)
    rx, ry, c, s = a.rx[own], a.ry[own], a.cphi[own], a.sphi[own]
    with np.errstate(invalid="ignore", over="ignore"):
        ex, ey = rx * ca, ry * sa  # point on the axis-aligned ellipse
        dx, dy = -rx * sa, ry * ca  # its tangent (per radian)
        pt = (a.cx[own] + c * ex - s * ey) + 1j * (a.cy[own] + s * ex + c * ey)
        tan = (c * dx - s * dy) + 1j * (s * dx + c * dy)
        k = (4.0 / 3.0 * np.tan(delta / 4.0))[own]
    is_start = np.ones(own.size, dtype=bool)
    is_start[np.cumsum(nb) - 1] = False
    b = np.flatnonzero(is_start)  # the boundary starting each piece
    cubics = np.empty((b.size, 4), dtype=complex)
    with np.errstate(invalid="ignore", over="ignore"):
        cubics[:, 0] = pt[b]
        cubics[:, 1] = pt[b] + k[b] * tan[b]
        cubics[:, 2] = pt[b + 1] - k[b] * tan[b + 1]
        cubics[:, 3] = pt[b + 1]
    first = np.cumsum(count) - count
    cubics[first, 0] = p0  # exact end points
    cubics[first + count - 1, 3] = p3
    return cubics


def _slice_setup(a: ArcSetup, sl: slice) -> ArcSetup:
    return ArcSetup(*(f[sl] for f in a))


def arc_cubics(p0: np.ndarray, p3: np.ndarray, arc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Approximate elliptical arcs (SVG endpoint parameterisation) by cubics, vectorised.

    Parameters
    ----------
    p0, p3 : ndarray of complex, shape (n,)
        Start and end points (distinct); radii must be non-zero.
    arc : ndarray, shape (n, 5)
        ``rx ry phi(degrees) large-arc-flag sweep-flag`` per arc.

    Returns
    -------
    cubics : ndarray of complex, shape (m, 4)
        Pieces of at most 45 degrees each (error below 5e-6 of the radius).
    owner : ndarray of int, shape (m,)
        The arc each piece belongs to (pieces of one arc are consecutive, in drawing order).
    """
    setup = arc_setup(p0, p3, arc)
    cubics = np.empty((int(setup.pieces.sum()), 4), dtype=complex)
    fill_arcs(cubics, np.cumsum(setup.pieces) - setup.pieces, setup, p0, p3)
    return cubics, np.repeat(np.arange(p0.size), setup.pieces)


def fill_arcs(out: np.ndarray, slot: np.ndarray, setup: ArcSetup, p0: np.ndarray, p3: np.ndarray) -> None:
    """Write the pieces of every arc into ``out`` from row ``slot[i]`` on, a chunk of arcs at a time."""
    for i in range(0, p0.size, _ARC_CHUNK):
        sl = slice(i, i + _ARC_CHUNK)
        part = _slice_setup(setup, sl)
        pieces = _arc_pieces(part, p0[sl], p3[sl])
        within = np.arange(pieces.shape[0]) - np.repeat(np.cumsum(part.pieces) - part.pieces, part.pieces)
        out[np.repeat(slot[sl], part.pieces) + within] = pieces
