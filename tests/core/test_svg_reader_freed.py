"""Reading an SVG leaves no garbage in reference cycles: the reader and the document are freed at once."""

from __future__ import annotations

import gc

import pytest

from lsys_core.svg.parse import parse_svg

_DOCS = {
    "plain": '<path d="M0 0 L10 10"/><path d="M5 5 q3 -4 8 0 z" fill="red"/>',
    "effects": (
        '<defs><clipPath id="c"><rect width="50" height="50"/></clipPath>'
        '<mask id="m"><rect width="80" height="80" fill="white"/></mask>'
        '<linearGradient id="g"><stop offset="0" stop-color="red"/></linearGradient>'
        '<marker id="k" markerWidth="4" markerHeight="4"><circle r="2"/></marker>'
        '<symbol id="s" viewBox="0 0 10 10"><path d="M0 0 L10 10"/></symbol></defs>'
        '<g clip-path="url(#c)" opacity="0.5"><path d="M0 0 L40 40" stroke="black" marker-end="url(#k)"/></g>'
        '<g mask="url(#m)"><rect width="30" height="20" fill="url(#g)"/></g>'
        '<use href="#s" x="10" width="20" height="20"/><text x="5" y="5">kept</text>'
    ),
    "style sheet": "<style>.a { fill: blue } path + path { stroke: red }</style>"
    '<path class="a" d="M0 0 h10 v10 z"/><path d="M20 0 h10"/>',
}


@pytest.mark.parametrize("body", _DOCS.values(), ids=list(_DOCS))
def test_reading_leaves_no_cyclic_garbage(body):
    svg = f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">{body}</svg>'
    enabled = gc.isenabled()
    gc.collect()
    gc.disable()
    try:
        scene = parse_svg(svg)
        assert scene.elements
        assert gc.collect() == 0
    finally:
        if enabled:
            gc.enable()
