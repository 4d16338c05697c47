"""Recognise basic shapes in path data, so exported SVG keeps ``<circle>``, ``<ellipse>``, ``<rect>``, ``<line>``.

The importer turns every shape into cubic Bézier segments (an SVG circle becomes arcs, then
cubics).  For the structured export a terminal whose path *is* a circle, an ellipse, a
rectangle or a straight line is written as that element again, so a designer sees (and can
edit) the element they drew.  :func:`primitive` decides from the geometry alone:

- a line: one open subpath of one straight segment that leaves and arrives along its chord;
- a rectangle: one closed subpath of four straight sides at right angles (rotated ones get a
  ``transform="rotate(…)"``), or of four straight sides joined by quarter circles or quarter
  ellipses (a rounded rectangle: ``rx``, ``ry``);
- an ellipse or a circle: one closed subpath of curved segments whose points all lie on one
  ellipse, going round it exactly once (the conic is fitted by least squares, then every
  sample is checked against it).

The replacement stays within :data:`TOLERANCE` of the size of the shape (cubic arcs are
themselves approximations of the true curve); anything else keeps its path data.
"""

from __future__ import annotations

import math

import numpy as np

from lsys_core.geometry.bezier import sample_cubics
from lsys_core.geometry.shapes import shape_arrays

__all__ = ["TOLERANCE", "chord_frame", "primitive", "primitive_of"]

#: Largest distance, relative to the shape's size, between the path and the element written for it.
TOLERANCE = 1e-3
#: Significant digits of the numbers written.
DIGITS = 7
#: Segments tested for straightness at once (the test's temporaries are about 200 bytes a segment).
_BLOCK = 1 << 16


def _num(v: float, unit: float = 0.0) -> str:
    """Format ``v``; values within ``unit * 1e-9`` of zero (rounding noise of the fit) are 0."""
    if abs(v) <= unit * 1e-9:
        return "0"
    text = f"{v:.{DIGITS}g}"
    return "0" if text == "-0" else text


def chord_frame(
    cubics: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, list[np.ndarray], np.ndarray, np.ndarray, np.ndarray]:
    """What the straightness test reads of each segment, measured along its chord.

    Returns the chord's ``length``, the chord itself where it has one (1 where not: ``safe``),
    the two control points relative to the chord (``rel``: 0 at the start, 1 at the end), their
    largest distance from it (``off``), and the tangents at the start and end (``start``,
    ``end``: towards the first control point that is not on that end).
    """
    p0, p1, p2, p3 = (cubics[:, k] for k in range(4))
    chord = p3 - p0
    length = np.abs(chord)
    safe = np.where(length > 0, chord, 1.0)
    rel = [(p - p0) / safe for p in (p1, p2)]
    off = np.maximum(np.abs(rel[0].imag), np.abs(rel[1].imag)) * length
    start = np.where(p1 != p0, p1 - p0, np.where(p2 != p0, p2 - p0, chord))
    end = np.where(p2 != p3, p3 - p2, np.where(p1 != p3, p3 - p1, chord))
    return length, safe, rel, off, start, end


def _straight(cubics: np.ndarray, tol: float, max_angle: float = 1e-3) -> np.ndarray:
    """Whether each segment is a straight line (control points on the chord, between its ends).

    It must also leave and arrive along its chord: a control point a hair off the chord next to
    an end turns the tangent there (and so a stroke's cap or join) far from the chord's
    direction, although the curve stays within the tolerance.
    """
    length, safe, rel, off, start, end = chord_frame(cubics)
    inside = np.all([(r.real > -tol) & (r.real < 1 + tol) for r in rel], axis=0)
    along = (np.abs(np.angle(start / safe)) <= max_angle) & (np.abs(np.angle(end / safe)) <= max_angle)
    return (length > 0) & (off <= tol) & inside & along


def primitive(d: str) -> tuple[str, dict[str, str]] | None:
    """Return ``(tag, attributes)`` of a basic SVG element drawing the same shape as path data ``d``.

    Parameters
    ----------
    d : str
        SVG path data (a terminal's, in its local frame).

    Returns
    -------
    (str, dict) or None
        ``("circle", {"cx", "cy", "r"})``, ``("ellipse", {…, "transform"?})``,
        ``("rect", {"x", "y", "width", "height", "transform"?})`` or
        ``("line", {"x1", "y1", "x2", "y2"})``; None when the path is none of these.

    Examples
    --------
    >>> primitive("M0 0 H10 V5 H0 Z")
    ('rect', {'x': '0', 'y': '0', 'width': '10', 'height': '5'})
    >>> primitive("M1 2 L4 6")
    ('line', {'x1': '1', 'y1': '2', 'x2': '4', 'y2': '6'})
    """
    try:
        cubics, _, closed = shape_arrays(d)
    except Exception:  # unreadable path data stays path data
        return None
    return primitive_of(cubics, closed)


def primitive_of(cubics: np.ndarray, closed: tuple[bool, ...]) -> tuple[str, dict[str, str]] | None:
    """:func:`primitive` of a path given as its cubic arrays (``cubics`` and ``closed`` per subpath)."""
    if cubics.shape[0] == 0 or len(closed) != 1 or not np.isfinite(cubics).all():
        return None
    size = float(np.ptp(cubics.real) + np.ptp(cubics.imag))
    if size <= 0:
        return None
    tol = TOLERANCE * size
    if not closed[0]:
        if cubics.shape[0] == 1 and _straight(cubics, tol)[0]:
            (p, q) = cubics[0, 0], cubics[0, 3]
            return "line", {"x1": _num(p.real), "y1": _num(p.imag), "x2": _num(q.real), "y2": _num(q.imag)}
        return None
    straight = np.concatenate(
        [_straight(cubics[lo : lo + _BLOCK], tol) for lo in range(0, cubics.shape[0], _BLOCK)]
    )
    if straight.all():
        return _rect(cubics, tol)
    if not straight.any():
        return _ellipse(cubics, tol)
    return _rounded_rect(cubics, straight, tol)


def _rect(cubics: np.ndarray, tol: float) -> tuple[str, dict[str, str]] | None:
    corners = cubics[:, 0]
    # drop vertices where the outline goes straight on (a side split in two)
    turn = np.angle((np.roll(corners, -1) - corners) / (corners - np.roll(corners, 1)))
    corners = corners[np.abs(turn) > 1e-6]
    if corners.size != 4:
        return None
    sides = np.roll(corners, -1) - corners
    if np.any(np.abs(sides) <= tol):
        return None
    dots = (sides * np.conj(np.roll(sides, -1))).real / (np.abs(sides) * np.abs(np.roll(sides, -1)))
    if np.any(np.abs(dots) > 1e-6) or abs(abs(sides[0]) - abs(sides[2])) > tol:
        return None
    angle = math.degrees(math.atan2(sides[0].imag, sides[0].real))
    quarter = round(angle / 90.0)
    angle -= 90.0 * quarter
    w, h = abs(sides[0]), abs(sides[1])
    if quarter % 2:
        w, h = h, w
    centre = corners.mean()
    unit = w + h
    attrs = {"x": _num(centre.real - w / 2, unit), "y": _num(centre.imag - h / 2, unit)}
    attrs |= {"width": _num(w), "height": _num(h)}
    if abs(angle) > 1e-7:
        attrs["transform"] = f"rotate({_num(angle)} {_num(centre.real, unit)} {_num(centre.imag, unit)})"
    return "rect", attrs


def _rounded_rect(cubics: np.ndarray, straight: np.ndarray, tol: float) -> tuple[str, dict[str, str]] | None:
    """A rectangle with round (circular or elliptical) corners: straight sides joined by quarter arcs."""
    sides = cubics[straight, 3] - cubics[straight, 0]
    angle = math.atan2(sides[0].imag, sides[0].real)
    rot = np.exp(-1j * angle)
    turned = sides * rot  # every side along the x or the y axis
    along_x = np.abs(turned.imag) <= tol
    along_y = np.abs(turned.real) <= tol
    if not np.all(along_x | along_y) or along_x.sum() < 2 or along_y.sum() < 2:
        return None
    pts = sample_cubics(cubics, 8) * rot
    x0, x1, y0, y1 = pts.real.min(), pts.real.max(), pts.imag.min(), pts.imag.max()
    hw, hh = (x1 - x0) / 2, (y1 - y0) / 2
    centre = complex((x0 + x1) / 2, (y0 + y1) / 2)
    # each of the two sides along x is as long as the width minus both corners
    rx = hw - float(np.abs(turned[along_x]).sum()) / 4
    ry = hh - float(np.abs(turned[along_y]).sum()) / 4
    if not (tol < rx <= hw + tol and tol < ry <= hh + tol):
        return None
    q = pts - centre
    ax, ay = np.abs(q.real), np.abs(q.imag)
    cx, cy = np.maximum(ax - (hw - rx), 0), np.maximum(ay - (hh - ry), 0)
    corner = (cx > 0) & (cy > 0)
    on_side = np.minimum(np.abs(ax - hw), np.abs(ay - hh))
    on_corner = np.abs(np.hypot(cx / rx, cy / ry) - 1.0) * min(rx, ry)
    if np.where(corner, on_corner, on_side).max() > tol:
        return None
    turns = np.angle(np.exp(1j * np.diff(np.unwrap(np.angle(q)))))
    if abs(abs(turns.sum()) - 2 * math.pi) > 1e-3:
        return None
    deg = math.degrees(angle)
    quarter = round(deg / 90.0)
    deg -= 90.0 * quarter
    w, h, rx_, ry_ = 2 * hw, 2 * hh, rx, ry
    if quarter % 2:
        w, h, rx_, ry_ = h, w, ry, rx
    centre = centre / rot
    unit = w + h
    attrs = {"x": _num(centre.real - w / 2, unit), "y": _num(centre.imag - h / 2, unit)}
    attrs |= {"width": _num(w), "height": _num(h), "rx": _num(rx_)}
    if abs(rx_ - ry_) > tol:
        attrs["ry"] = _num(ry_)
    if abs(deg) > 1e-7:
        attrs["transform"] = f"rotate({_num(deg)} {_num(centre.real, unit)} {_num(centre.imag, unit)})"
    return "rect", attrs


def _radii(pu: np.ndarray, pv: np.ndarray) -> tuple[float | None, float | None]:
    """Least-squares radii of an axis-aligned ellipse through points: ``pu²/ru² + pv²/rv² = 1``."""
    design = np.column_stack([pu * pu, pv * pv])
    if np.linalg.matrix_rank(design) < 2:
        return None, None
    (iu, iv), *_ = np.linalg.lstsq(design, np.ones_like(pu), rcond=None)
    if not (iu > 0 and iv > 0):
        return None, None
    return 1.0 / math.sqrt(iu), 1.0 / math.sqrt(iv)


def _ellipse(cubics: np.ndarray, tol: float) -> tuple[str, dict[str, str]] | None:
    pts = sample_cubics(cubics, 8)
    x, y = pts.real, pts.imag
    mx, my = x.mean(), y.mean()
    scale = max(np.ptp(x), np.ptp(y))
    u, v = (x - mx) / scale, (y - my) / scale
    design = np.column_stack([u * u, u * v, v * v, u, v, np.ones_like(u)])
    coef = np.linalg.svd(design, full_matrices=False)[2][-1]
    A, B, C, D, E, _ = coef
    det = 4 * A * C - B * B
    if det <= 0:
        return None
    uc = (B * E - 2 * C * D) / det
    vc = (B * D - 2 * A * E) / det
    theta = 0.5 * math.atan2(B, A - C)
    ct, st = math.cos(theta), math.sin(theta)
    # principal frame: rotate (u - uc, v - vc) by -theta
    pu = (u - uc) * ct + (v - vc) * st
    pv = -(u - uc) * st + (v - vc) * ct
    ru, rv = _radii(pu, pv)
    if ru is None or rv is None:
        return None
    radial = np.hypot(pu / ru, pv / rv)
    if np.abs(radial - 1.0).max() * max(ru, rv) * scale > tol:
        return None
    turns = np.angle(np.exp(1j * np.diff(np.unwrap(np.arctan2(pv / rv, pu / ru)))))
    if abs(abs(turns.sum()) - 2 * math.pi) > 1e-3:  # round the ellipse exactly once
        return None
    cx, cy = mx + uc * scale, my + vc * scale
    # The segments' end points lie on the drawn curve (the cubics between them only approximate
    # it): the radii are fitted to them.
    ends = cubics[:, 0]
    rx, ry = ru * scale, rv * scale
    if abs(rx - ry) <= tol:
        r = float(np.abs(ends - complex(cx, cy)).mean())
        return "circle", {"cx": _num(cx, scale), "cy": _num(cy, scale), "r": _num(r)}
    eu, ev = (ends.real - mx) / scale - uc, (ends.imag - my) / scale - vc
    fu, fv = _radii(eu * ct + ev * st, -eu * st + ev * ct)
    if fu is not None and fv is not None:
        rx, ry = fu * scale, fv * scale
    deg = math.degrees(theta)
    if rx < ry:  # prefer rx as the larger radius along the rotated x axis
        rx, ry, deg = ry, rx, deg + 90.0
    deg = (deg + 90.0) % 180.0 - 90.0
    attrs = {"cx": _num(cx, scale), "cy": _num(cy, scale), "rx": _num(rx), "ry": _num(ry)}
    if abs(deg) > 1e-7:
        attrs["transform"] = f"rotate({_num(deg)} {attrs['cx']} {attrs['cy']})"
    return "ellipse", attrs
