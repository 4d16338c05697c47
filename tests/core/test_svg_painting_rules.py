"""Painting rules of the SVG reader that conformance files exercise one at a time.

Each test states one rule of SVG 2 (or, where the specification leaves it open, what renderers
draw) and checks the scene the reader makes of a small document.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import pytest

from lsys_core.geometry import cubics_from_d
from lsys_core.svg import parse_svg

from .svg_reading import clip_box, style_of

NS = 'xmlns="http://www.w3.org/2000/svg"'


def svg(body: str, attrs: str = 'width="100" height="100" viewBox="0 0 100 100"') -> str:
    return f'<svg {NS} xmlns:xlink="http://www.w3.org/1999/xlink" {attrs}>{body}</svg>'


def test_paint_order_keywords_left_out_follow_in_default_order():
    """``markers stroke`` is markers, stroke, fill: the markers come first, the stroke under the fill."""
    text = svg(
        '<marker id="m" markerWidth="4" markerHeight="4" markerUnits="userSpaceOnUse">'
        '<rect width="4" height="4" fill="orange"/></marker>'
        '<path d="M10 10 L90 10 L90 90 Z" fill="green" stroke="blue" stroke-width="5" '
        'marker-start="url(#m)" paint-order="markers stroke"/>'
    )
    scene = parse_svg(text)
    marker, shape = scene.elements
    assert "marker" in marker.source and marker.order < shape.order
    assert style_of(shape)["paint-order"] == "stroke"
    # the default order keeps fill under stroke: no paint-order written
    (plain,) = parse_svg(svg('<path d="M0 0 L9 9" stroke="blue" paint-order="fill"/>')).elements
    assert "paint-order" not in style_of(plain)


def test_zero_length_subpath_with_caps_is_kept_as_is():
    """A round or square cap on a zero-length subpath draws a dot: the element is kept as it is."""
    dots = 'd="M 10 10 L 10 10" stroke="green" stroke-width="4"'
    scene = parse_svg(svg(f'<path {dots} stroke-linecap="round"/><rect width="5" height="5"/>'))
    (kept,) = scene.verbatim
    assert 'd="M 10 10 L 10 10"' in kept.xml and "stroke-linecap:round" in kept.xml
    # a longer path with one zero-length subpath keeps its dot too
    mixed = '<path d="M 0 0 L 50 0 M 70 70 L 70 70" stroke="green" stroke-linecap="square"/>'
    assert len(parse_svg(svg(mixed + '<rect width="5" height="5"/>')).verbatim) == 1
    # butt caps draw nothing there: skipped as before, nothing kept
    scene = parse_svg(svg(f'<path {dots}/><rect width="5" height="5"/>'))
    assert not scene.verbatim and len(scene.elements) == 1
    # a line of zero length is the same
    line = '<line x1="5" y1="5" x2="5" y2="5" stroke="red" stroke-linecap="round"/>'
    assert len(parse_svg(svg(line + '<rect width="5" height="5"/>')).verbatim) == 1


def test_kept_content_writes_its_transform_as_the_attribute():
    """A kept element's own transform stays an attribute (renderers ignore it as a CSS property)."""
    text = svg('<text x="0" y="20" transform="translate(20 60) rotate(90)" font-size="10">Hi</text>')
    (kept,) = parse_svg(text, allow_empty=True).verbatim
    got = re.search(r'<text[^>]* transform="matrix\(([^)]*)\)"', kept.xml)
    assert got is not None and "transform:" not in kept.xml
    assert [float(v) for v in got.group(1).split()] == pytest.approx([0, 1, -1, 0, 20, 60], abs=1e-9)


def test_hidden_shapes_count_in_a_group_bounding_box():
    """``visibility: hidden`` draws nothing but the shape is part of its group's bounding box."""
    text = svg(
        '<clipPath id="c" clipPathUnits="objectBoundingBox"><rect width="0.5" height="1"/></clipPath>'
        '<g clip-path="url(#c)"><rect x="0" y="0" width="100" height="100" visibility="hidden"/>'
        '<rect x="25" y="25" width="50" height="50"/></g>'
    )
    scene = parse_svg(text)
    (el,) = scene.elements
    assert clip_box(scene, el) == pytest.approx((0, 50, 0, 100))


def test_bounding_box_paint_on_a_shape_without_area_uses_the_fallback():
    """A vertical line has no box width: an ``objectBoundingBox`` server gives way to the fallback."""
    servers = (
        '<linearGradient id="g"><stop offset="0" stop-color="red"/><stop offset="1" stop-color="blue"/>'
        '</linearGradient><pattern id="p" width="1" height="1"><rect width="5" height="5" fill="red"/></pattern>'
    )
    line = '<line x1="50" y1="10" x2="50" y2="90" stroke-width="3" stroke="url(#{}) green"/>'
    for ref in ("g", "p"):
        (el,) = parse_svg(svg(servers + line.format(ref))).elements
        assert style_of(el)["stroke"] == "#008000"
    # without a fallback its stroke paints nothing
    (bare,) = parse_svg(svg(servers + line.format("g").replace(" green", ""))).elements
    assert style_of(bare)["stroke"] == "none"


def test_invalid_miter_limit_is_ignored_and_the_inherited_one_applies():
    """``stroke-miterlimit`` below 1 (or not a number) is invalid: the declaration is dropped."""
    path = '<path d="M0 0 L50 10 L0 20" fill="none" stroke="green" stroke-miterlimit="{}"/>'
    for bad in ("-10", "0.5", "5mm"):
        (el,) = parse_svg(svg(f'<g stroke-miterlimit="10">{path.format(bad)}</g>')).elements
        assert style_of(el)["stroke-miterlimit"] == "10"
        (el,) = parse_svg(svg(path.format(bad))).elements
        assert "stroke-miterlimit" not in style_of(el)  # the initial value, 4
    (el,) = parse_svg(svg(path.format("1.5"))).elements
    assert style_of(el)["stroke-miterlimit"] == "1.5"


def test_nested_clip_paths_become_one_outline():
    """A group's clip path and its child's own meet as one outline, not a clip path on a clip path.

    (A clip path on a clip path's children is valid SVG, but librsvg ignores it.)
    """
    text = svg(
        '<clipPath id="a"><rect width="50" height="100"/></clipPath>'
        '<clipPath id="b"><rect x="25" width="75" height="100"/></clipPath>'
        '<g clip-path="url(#a)"><rect width="100" height="100" clip-path="url(#b)"/></g>'
    )
    scene = parse_svg(text)
    (el,) = scene.elements
    defs = ET.fromstring(f'<defs xmlns="http://www.w3.org/2000/svg">{scene.defs}</defs>')
    (clip,) = [c for c in defs if "url(#" + c.get("id") + ")" == style_of(el)["clip-path"]]
    (piece,) = list(clip)
    assert piece.get("clip-path") is None
    c, _, _ = cubics_from_d(piece.get("d"))
    assert (c.real.min(), c.real.max(), c.imag.min(), c.imag.max()) == pytest.approx((25, 50, 0, 100))
    # clip paths that do not meet let nothing through: the element is not drawn
    apart = text.replace('x="25" width="75"', 'x="60" width="40"')
    assert style_of(parse_svg(apart).elements[0])["opacity"] == "0"
