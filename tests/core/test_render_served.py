"""The own renderer paints instances whose fill or stroke is a gradient, at their place in the paint order."""

from __future__ import annotations

from dataclasses import replace

from lsys_core.grammar.model import Terminal
from lsys_core.render.raster import render

from .scenes import make_drawing

SQUARE = "M0 0 L10 0 L10 10 L0 10 Z"
DEFS = (
    '<defs><linearGradient id="box"><stop offset="0" stop-color="#ff0000"/>'
    '<stop offset="1" stop-color="#0000ff"/></linearGradient>'
    '<linearGradient id="canvas" gradientUnits="userSpaceOnUse" x1="0" y1="0" x2="200" y2="0">'
    '<stop offset="0" stop-color="#ff0000"/><stop offset="1" stop-color="#0000ff"/></linearGradient></defs>'
)


def drawing(style: str, cover: bool = False):
    terminals = [Terminal("S", SQUARE, style), Terminal("K", SQUARE, "fill:#000000")]
    symbol, a, b = [0, 0], [2, 4], [10 + 10j, 100 + 20j]
    if cover:  # a black square drawn after the second one, over its left half
        symbol, a, b = [*symbol, 1], [*a, 2], [*b, 100 + 30j]
    return replace(make_drawing(terminals, symbol, a, b, (0.0, 0.0, 200.0, 100.0)), defs=DEFS)


def test_object_box_gradients_follow_each_instance():
    img = render(drawing("fill:url(#box)"), 200, 100)
    for x0, x1, y in ((10, 30, 20), (100, 140, 40)):
        left, right = img[y, x0 + 1], img[y, x1 - 2]
        assert left[0] > 200 and left[2] < 60, left  # red at the left of its own box
        assert right[2] > 200 and right[0] < 60, right  # blue at the right
    # Drawn without the gradient (as before), both would be one flat colour.
    assert abs(int(img[20, 11, 0]) - int(img[20, 28, 0])) > 150


def test_canvas_gradients_depend_on_the_canvas_position_and_keep_paint_order():
    img = render(drawing("fill:url(#canvas)", cover=True), 200, 100)
    # x = 20 is a tenth of the way: mostly red; x = 130 about two thirds: more blue than red.
    assert img[20, 20, 0] > 200 and img[20, 20, 2] < 40
    assert img[50, 130, 2] > img[50, 130, 0]
    # The black square drawn after covers the gradient-painted one.
    assert (img[35:45, 102:118, :3] == 0).all()


def test_stroke_gradients_and_opacity():
    img = render(drawing("fill:none;stroke:url(#box);stroke-width:4;opacity:0.5"), 200, 100)
    assert img[40, 100, 3] in range(120, 136)  # half-transparent stroke on the left side
    assert img[40, 100, 0] > 200 and img[40, 139, 2] > 200  # red left, blue right
    assert img[40, 120, 3] == 0  # no fill


CLIPS = (
    '<defs><clipPath id="left" clipPathUnits="userSpaceOnUse"><rect x="0" y="0" width="115" height="100"/></clipPath>'
    '<clipPath id="half" clipPathUnits="objectBoundingBox"><rect x="0" y="0" width="1" height="0.5"/></clipPath>'
    '<clipPath id="holes" clipPathUnits="userSpaceOnUse">'
    '<path d="M0 0 H200 V100 H0 Z M110 30 H130 V50 H110 Z" clip-rule="evenodd"/></clipPath></defs>'
)


def clipped(clip: str):
    return replace(drawing(f"fill:#000000;clip-path:url(#{clip})"), defs=CLIPS)


def test_clip_paths_on_instances():
    full = render(replace(drawing("fill:#000000"), defs=CLIPS), 200, 100)[..., 3] > 128
    left = render(clipped("left"), 200, 100)[..., 3] > 128
    assert full[40, 130] and not left[40, 130] and left[40, 110]  # the big square, cut at x = 115
    half = render(clipped("half"), 200, 100)[..., 3] > 128
    assert half[25, 120] and not half[50, 120]  # upper half of its own box (y 20..60) only
    assert half[12, 20] and not half[25, 20]  # and of the small square's (y 10..30)
    holes = render(clipped("holes"), 200, 100)[..., 3] > 128
    assert holes[25, 120] and not holes[40, 120] and holes[55, 120]  # evenodd hole at y 30..50


def test_clip_paths_on_kept_text():
    from lsys_core.grammar.model import Verbatim

    text = '<text x="10" y="70" style="font-size:50px;clip-path:url(#left)">MMMMMM</text>'
    d = replace(
        make_drawing([], [], [], [], (0.0, 0.0, 200.0, 100.0)), defs=CLIPS, verbatim=(Verbatim(0, text),)
    )
    ink = render(d, 200, 100)[..., 3] > 128
    assert ink[:, 20:110].any() and not ink[:, 116:].any()


def test_dashes_in_canvas_units_and_stroke_under_fill():
    line = Terminal("L", "M0 0 L10 0", "fill:none;stroke:#000000;stroke-width:4;stroke-dasharray:10 10")
    d = make_drawing([line], [0], [15], [25 + 50j], (0.0, 0.0, 200.0, 100.0))  # a line from x 25 to 175
    row = render(d, 200, 100)[50, :, 3] > 128
    # Dashes of 10 canvas units (not 150, the instance's scale): on at 25..35, off at 35..45, ...
    assert row[28:33].all() and not row[38:43].any() and row[48:53].all()
    assert not render(
        replace(d, terminals=(replace(line, style=line.style + ";stroke-dasharray:0 10"),)), 200, 100
    )[..., 3].any()  # zero-length dashes with butt caps draw nothing
    under = Terminal("U", SQUARE, "fill:#ff0000;stroke:#0000ff;stroke-width:6;paint-order:stroke")
    img = render(make_drawing([under], [0], [4], [60 + 30j], (0.0, 0.0, 200.0, 100.0)), 200, 100)
    # The fill covers the inner half of the stroke: red at 1 unit inside the edge, blue outside.
    assert img[50, 61, 0] > 200 and img[50, 61, 2] < 60
    assert img[50, 58, 2] > 200 and img[50, 58, 0] < 60
