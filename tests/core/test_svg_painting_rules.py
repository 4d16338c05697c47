"""Painting rules of the SVG reader that conformance files exercise one at a time.

Each test states one rule of SVG 2 (or, where the specification leaves it open, what renderers
draw) and checks the scene the reader makes of a small document.
"""

from __future__ import annotations

from lsys_core.svg import parse_svg

NS = 'xmlns="http://www.w3.org/2000/svg"'


def svg(body: str, attrs: str = 'width="100" height="100" viewBox="0 0 100 100"') -> str:
    return f'<svg {NS} xmlns:xlink="http://www.w3.org/1999/xlink" {attrs}>{body}</svg>'


def style_of(element) -> dict[str, str]:
    return dict(p.split(":", 1) for p in element.style.split(";") if p)


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
