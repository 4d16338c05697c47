"""Basic shapes recognised in path data (the structured SVG export writes them as those elements)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lsys_core.geometry.bezier import sample_cubics
from lsys_core.geometry.shapes import shape_arrays
from lsys_core.render.primitives import TOLERANCE, primitive


def distance_to(tag: str, attrs: dict[str, str], pts: np.ndarray) -> np.ndarray:
    """Distance of points to the outline of the element ``tag`` (approximate for ellipses)."""
    f = {k: float(v) for k, v in attrs.items() if k != "transform"}
    angle = 0.0
    if "transform" in attrs:
        angle = math.radians(float(attrs["transform"].removeprefix("rotate(").split()[0]))
    if tag == "line":
        p, q = complex(f["x1"], f["y1"]), complex(f["x2"], f["y2"])
        t = np.clip(((pts - p) / (q - p)).real, 0, 1)
        return np.abs(pts - (p + t * (q - p)))
    if tag == "circle":
        return np.abs(np.abs(pts - complex(f["cx"], f["cy"])) - f["r"])
    if tag == "ellipse":
        z = (pts - complex(f["cx"], f["cy"])) * np.exp(-1j * angle)
        theta = np.angle(z.real / f["rx"] + 1j * z.imag / f["ry"])
        return np.abs(z - (f["rx"] * np.cos(theta) + 1j * f["ry"] * np.sin(theta)))
    assert tag == "rect"
    c = complex(f["x"] + f["width"] / 2, f["y"] + f["height"] / 2)
    if "transform" in attrs:
        parts = attrs["transform"].removeprefix("rotate(").rstrip(")").split()
        pivot = complex(float(parts[1]), float(parts[2]))
        c = (c - pivot) * np.exp(1j * angle) + pivot
    z = (pts - c) * np.exp(-1j * angle)
    rx = f.get("rx", 0.0)
    ry = f.get("ry", rx)
    hw, hh = f["width"] / 2, f["height"] / 2
    ax, ay = np.abs(z.real), np.abs(z.imag)
    side = np.minimum(np.abs(ax - hw), np.abs(ay - hh))
    if rx == 0:
        return side
    cx, cy = np.maximum(ax - (hw - rx), 0), np.maximum(ay - (hh - ry), 0)
    corner = (cx > 0) & (cy > 0)
    return np.where(corner, np.abs(np.hypot(cx / rx, cy / ry) - 1) * min(rx, ry), side)


def arc_path(cx, cy, rx, ry, deg, sweeps=2) -> str:
    """An ellipse drawn as ``sweeps`` arcs (as an importer writes a circle or an ellipse)."""
    rot = np.exp(1j * math.radians(deg))
    pts = [complex(cx, cy) + complex(rot) * complex(rx * math.cos(t), ry * math.sin(t)) for t in (0, math.pi)]
    d = f"M{pts[0].real!r} {pts[0].imag!r}"
    for k in range(sweeps):
        q = pts[(k + 1) % 2]
        d += f" A{rx} {ry} {deg} 0 1 {q.real!r} {q.imag!r}"
    return d + " Z"


def rounded_rect(w, h, r, deg) -> str:
    """A rectangle with round corners, centred on the origin and turned by ``deg``."""
    rot = complex(np.exp(1j * math.radians(deg)))
    corners = [(w / 2 - r, -h / 2), (w / 2, -h / 2 + r), (w / 2, h / 2 - r), (w / 2 - r, h / 2)]
    corners += [(-x, -y) for x, y in corners]
    pts = [complex(x, y) * rot for x, y in corners]
    d = f"M{pts[-1].real!r} {pts[-1].imag!r}"
    for k in range(0, 8, 2):
        d += f" L{pts[k].real!r} {pts[k].imag!r} A{r} {r} 0 0 1 {pts[k + 1].real!r} {pts[k + 1].imag!r}"
    return d + " Z"


CASES = [
    ("M0 0 H10 V5 H0 Z", "rect"),
    ("M3 4 L13 4 L13 9 L3 9 Z", "rect"),
    ("M0 0 L10 10 L5 15 L-5 5 Z", "rect"),  # rotated 45°
    ("M0 0 L5 0 L10 0 L10 5 L0 5 Z", "rect"),  # a side in two pieces
    ("M1 2 L4 6", "line"),
    ("M2 0 H8 A2 2 0 0 1 10 2 V3 A2 2 0 0 1 8 5 H2 A2 2 0 0 1 0 3 V2 A2 2 0 0 1 2 0 Z", "rect"),  # rx
    ("M3 0 H7 A3 1 0 0 1 10 1 V4 A3 1 0 0 1 7 5 H3 A3 1 0 0 1 0 4 V1 A3 1 0 0 1 3 0 Z", "rect"),  # rx, ry
    (rounded_rect(10, 5, 1.5, 30), "rect"),
    (arc_path(0, 0, 2, 2, 0), "circle"),
    (arc_path(12, 3, 1, 1, 0), "circle"),
    (arc_path(-4, 7, 5, 2, 0), "ellipse"),
    (arc_path(1, 1, 5, 2, 28.6), "ellipse"),
    (arc_path(1, 1, 2, 5, -70), "ellipse"),
    # the four-cubic circle most drawing programs write
    (
        "M13.5 10C13.5 10.8284 12.8284 11.5 12 11.5C11.1716 11.5 10.5 10.8284 10.5 10C10.5 9.17157 11.1716 8.5 12 8.5"
        "C12.8284 8.5 13.5 9.17157 13.5 10Z",
        "circle",
    ),
]


@pytest.mark.parametrize("d,tag", CASES)
def test_recognised_shapes_match_the_path(d, tag) -> None:
    found = primitive(d)
    assert found is not None and found[0] == tag, found
    cubics = shape_arrays(d)[0]
    size = np.ptp(cubics.real) + np.ptp(cubics.imag)
    pts = sample_cubics(cubics, 16)
    assert distance_to(tag, found[1], pts).max() <= TOLERANCE * size


@pytest.mark.parametrize(
    "d",
    [
        "M0 0 L10 0 L10 5 Z",  # triangle
        "M0 0 L10 0 L12 5 L2 5 Z",  # parallelogram
        "M2 0 H8 A2 2 0 0 1 10 2 V3 L8 5 H2 A2 2 0 0 1 0 3 V2 A2 2 0 0 1 2 0 Z",  # a corner cut
        "M2 0 H8 A2 2 0 0 0 10 2 V3 A2 2 0 0 1 8 5 H2 A2 2 0 0 1 0 3 V2 A2 2 0 0 1 2 0 Z",  # a corner inward
        "M0 0 L10 0 L10 5 L0 5",  # open outline
        "M2 0 A2 2 0 0 1 -2 0 Z",  # half disc
        "M0 0 C1 1 2 1 3 0 Z",  # a bump
        "M0 0 L1 0 M5 5 L6 5",  # two subpaths
        arc_path(0, 0, 2, 2, 0, sweeps=4),  # round twice
        "M0 0 H10 V5 H0 Z M2 2 H3 V3 H2 Z",  # a rectangle with a hole
        "M1 0 C1 0.6 0.6 1 0 1 C-0.6 1 -1 0.6 -1 0 C-1 -0.9 -0.5 -1.2 0 -1.2 C0.6 -1.2 1 -0.6 1 0 Z",  # egg
        "",
    ],
)
def test_other_shapes_keep_their_path(d) -> None:
    assert primitive(d) is None


def test_near_straight_curve_leaving_off_its_chord_is_not_a_line() -> None:
    """Within the tolerance of its chord, yet its ends leave sideways: a stroke's caps would turn."""
    assert primitive("M 20 160 C 20.1 160 160 20 160.1 20") is None
    assert primitive("M 20 160 C 60 120 120 60 160 20") == (
        "line",
        {"x1": "20", "y1": "160", "x2": "160", "y2": "20"},
    )
    assert primitive("M 0 0 C 0 0 3 3 3 3") is not None  # control points on the ends: along the chord


def test_rectangle_side_leaving_its_corner_askew_is_not_a_rect() -> None:
    """The same for the sides of a rectangle: the join at that corner would change."""
    assert primitive("M0 0 C0.01 0.005 10 0 10 0 L10 10 L0 10 Z") is None
    assert primitive("M0 0 C3 0 7 0 10 0 L10 10 L0 10 Z") == (
        "rect",
        {"x": "0", "y": "0", "width": "10", "height": "10"},
    )
