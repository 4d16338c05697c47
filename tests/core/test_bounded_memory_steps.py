"""Memory-bounded steps give the same answers as the one-pass ones they replace.

A copy drawn with the same segments as its shape is measured by its control points (no
polylines); path data is written, rounded, and shapes are placed, in blocks of segments.
"""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.geometry import paths
from lsys_core.instancing import deviation
from lsys_core.render import compact
from lsys_core.svg import parse
from lsys_core.svg.model import Element
from lsys_core.svg.parse import parse_svg

_ZIGZAG = "M0 0 " + " ".join(f"L{i} {(i % 2) * 7}" for i in range(1, 400)) + " C 410 20 420 -20 430 0 Z"


def _element(d: str) -> Element:
    svg = f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 500 500"><path d="{d}"/></svg>'
    return parse_svg(svg.encode()).elements[0]


def test_a_copy_with_the_same_segments_is_measured_without_polylines(monkeypatch):
    el = _element(_ZIGZAG)
    shape = Element(el.cubics - 5, el.subpaths, el.closed)
    monkeypatch.setattr(deviation, "_polyline", lambda *a, **k: pytest.fail("sampled a copy"))
    got = deviation.pose_deviations([el], [shape], np.array([0]), np.array([1 + 0j]), np.array([5 + 0j]))
    assert got[0] <= 1e-9


def test_the_same_segments_at_a_wrong_scale_are_still_measured():
    el = _element("M0 0 L100 0 L100 100 L0 100 Z")
    shape = Element(el.cubics * 0.8, el.subpaths, el.closed)
    got = deviation.pose_deviations([el], [shape], np.array([0]), np.array([1 + 0j]), np.array([0j]))
    assert got[0] == pytest.approx(20 * 2**0.5, rel=1e-6)  # the far corner, (100, 100) from (80, 80)


def test_a_square_traced_from_another_corner_is_an_exact_copy():
    el = _element("M0 0 L100 0 L100 100 L0 100 Z")
    other = _element("M100 100 L0 100 L0 0 L100 0 Z")  # same segments count, other order
    got = deviation.pose_deviations([other], [el], np.array([0]), np.array([1 + 0j]), np.array([0j]))
    assert got[0] <= 1e-6


def test_path_data_written_in_blocks_is_the_same(monkeypatch):
    el = _element(_ZIGZAG + " M 5 5 L 9 9 C 10 10 11 12 13 14 L 5 5 Z")
    whole = paths.d_from_cubics(el.cubics, el.subpaths, el.closed)
    monkeypatch.setattr(paths, "_WRITE_BLOCK", 3)
    assert paths.d_from_cubics(el.cubics, el.subpaths, el.closed) == whole


def test_shapes_placed_in_blocks_are_the_same(monkeypatch):
    svg = (
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 500 500">'
        f'<path d="{_ZIGZAG}" transform="rotate(30) scale(2 1)"/>'
        '<g transform="translate(10 20)"><rect width="5" height="5"/><circle r="3" cx="40"/></g>'
        '<path d="M0 0 L0 0"/><path d="M0 0 L1e300 0"/></svg>'
    ).encode()
    whole = parse_svg(svg)
    monkeypatch.setattr(parse, "_BLOCK", 5)
    blocks = parse_svg(svg)
    assert len(blocks.elements) == len(whole.elements) == 3
    assert blocks.warnings == whole.warnings
    for a, b in zip(blocks.elements, whole.elements, strict=True):
        np.testing.assert_array_equal(a.cubics, b.cubics)


def test_path_data_rounded_in_pieces_is_the_same():
    d = _ZIGZAG.replace(" L", " l0.12345 -0.5e-3 L") + " m 1.25,2.5e1 h -3.000001 v.5 Z"
    pieces = list(compact._pieces(d, 40))
    assert len(pieces) > 10 and "".join(pieces) == d
    assert all(p[0].isalpha() for p in pieces)  # cut before command letters, never in a number
    assert "".join(compact._rounded(p, 2) for p in pieces) == compact._rounded(d, 2)
    assert compact._rounded("M-0.001 10.000 L 2.50 -3e-5 100 0.105", 2) == "M0 10 L 2.5 0 100 0.1"


def test_same_segments_compared_in_blocks_are_the_same(monkeypatch):
    rng = np.random.default_rng(5)
    shapes = [_element(_ZIGZAG), _element("M0 0 L100 0 L100 100 L0 100 Z"), _element("M0 0 C 1 2 3 4 5 0")]
    elements, which, a, b = [], [], [], []
    for i in range(40):
        s = i % 3
        pose_a, pose_b = complex(*rng.normal(size=2)), complex(*rng.normal(size=2)) * 50
        noise = (1e-9, 1e-3, 0.0, 2.0)[i % 4]
        c = pose_a * shapes[s].cubics + pose_b + noise * rng.normal(size=shapes[s].cubics.shape)
        if i % 7 == 0:
            c = c[:-1]  # another number of segments: measured on polylines
        elements.append(Element(c, np.zeros(c.shape[0], np.intp), (False,)))
        which.append(s), a.append(pose_a), b.append(pose_b)
    args = (elements, shapes, np.array(which), np.array(a), np.array(b), 1e-6)
    whole, whole_todo = deviation._same_segments(*args)
    assert 0 < whole_todo.size < len(elements) and (whole > 0).any()
    for block in (1, 3, 400):
        monkeypatch.setattr(deviation, "_SAME_BLOCK", block)
        got, todo = deviation._same_segments(*args)
        np.testing.assert_array_equal(todo, whole_todo)
        assert got.tobytes() == whole.tobytes()


def test_cubics_placed_in_place_or_copied_are_the_same(monkeypatch):
    # Paths each drawn once are placed in their parsed array (a hidden copy shares the piece of
    # the one drawn, and is not read again); a path drawn twice is copied first.  Either way the
    # elements are the same.
    in_place = []
    joined = parse._joined

    def spy(arrays, counts):
        got = joined(arrays, counts)
        in_place.append(got is arrays[0].base)
        return got

    monkeypatch.setattr(parse, "_joined", spy)
    zigzag = f'<path d="{_ZIGZAG}" transform="rotate(30) scale(2 1)"/>'
    once = zigzag + '<path d="M 1 1 L 5 9"/>'
    head = '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 500 500">'
    bodies = (once, once + zigzag, once + f'<path d="{_ZIGZAG}" visibility="hidden"/>')
    small = [parse_svg((head + body + "</svg>").encode()) for body in bodies]
    assert in_place == [False, False, False]  # small copies are made without looking
    in_place.clear()
    monkeypatch.setattr(parse, "_SMALL_COPY", 0)
    scenes = [parse_svg((head + body + "</svg>").encode()) for body in bodies]
    assert in_place == [True, False, True]
    for copied, placed in zip(small, scenes, strict=True):
        for a, b in zip(copied.elements, placed.elements, strict=True):
            assert a.cubics.tobytes() == b.cubics.tobytes()
    assert [len(s.elements) for s in scenes] == [2, 3, 2]
    for scene in scenes[1:]:
        for a, b in zip(scene.elements, scenes[0].elements, strict=False):
            np.testing.assert_array_equal(a.cubics, b.cubics)
    np.testing.assert_array_equal(scenes[1].elements[2].cubics, scenes[0].elements[0].cubics)
    alone = paths.path_from_d(_ZIGZAG)[0].cubics
    c, s = np.cos(np.pi / 6), np.sin(np.pi / 6)
    x, y = alone.real * 2, alone.imag
    np.testing.assert_allclose(
        scenes[0].elements[0].cubics, (c * x - s * y) + 1j * (s * x + c * y), atol=1e-9
    )


def test_elements_sampled_in_their_scene_array_or_copied_are_the_same():
    from lsys_core.instancing.sampling import arc_fractions, sample_elements

    body = "".join(
        f'<path d="M{i} 0 C {i + 3} 5 {i + 6} -5 {i + 9} 0 L {i + 9} 9 Z"/><rect x="{i}" y="20" width="3" height="{i + 1}"/>'
        for i in range(0, 60, 10)
    )
    scene = parse_svg(f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 99 99">{body}</svg>'.encode())
    views = list(scene.elements)
    assert paths.consecutive([e.cubics for e in views]) is not None  # one array: sampled in place
    copies = [Element(e.cubics.copy(), e.subpaths, e.closed) for e in views]
    assert paths.consecutive([e.cubics for e in copies]) is None
    for els in (views, views[::2]):
        a = sample_elements(els, arc_fractions(16))
        b = sample_elements([copies[views.index(e)] for e in els], arc_fractions(16))
        for got, want in zip(
            (a.points, a.normals, a.curvature, a.length),
            (b.points, b.normals, b.curvature, b.length),
            strict=True,
        ):
            assert got.tobytes() == want.tobytes()


def test_primitives_recognised_in_blocks_are_the_same(monkeypatch):
    from lsys_core.render import primitives

    shapes = [
        "M0 0 H10 V5 H0 Z",
        "M0 0 H5 H10 V5 H0 Z",  # a side split in two
        "M 10 0 A 10 5 0 0 1 -10 0 A 10 5 0 0 1 10 0 Z",
        "M 2 0 H 8 A 2 2 0 0 1 10 2 V 4 A 2 2 0 0 1 8 6 H 2 A 2 2 0 0 1 0 4 V 2 A 2 2 0 0 1 2 0 Z",
        "M1 2 L4 6",
        "M0 0 L 3 3 L 5 0",
    ]
    whole = [primitives.primitive(d) for d in shapes]
    assert sum(w is not None for w in whole) >= 4
    monkeypatch.setattr(primitives, "_BLOCK", 2)
    assert [primitives.primitive(d) for d in shapes] == whole
