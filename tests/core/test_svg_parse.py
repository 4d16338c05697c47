"""Tests of SVG import: corpus files, real-world files, styles, geometry, hostile input."""

from __future__ import annotations

import gzip
import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from lsys_core.errors import LimitError, LsysError, SvgError
from lsys_core.geometry import cubics_from_d, sample_cubics, sample_uniform
from lsys_core.svg import load_svg, parse_svg
from lsys_core.svg.tree import local_name

from .svg_reading import clip_box, style_of

SHARED = Path(__file__).resolve().parents[2].parent / "shared"
NS = 'xmlns="http://www.w3.org/2000/svg"'
DRAWABLE = {"path", "rect", "circle", "ellipse", "line", "polyline", "polygon"}


def _files(folder: str) -> list[Path]:
    return sorted((SHARED / folder).glob("*.svg"))


@pytest.fixture
def shared() -> Path:
    """The shared input folder beside the repository (skip when absent)."""
    if not SHARED.is_dir():
        pytest.skip("../shared is not present")
    return SHARED


def svg(body: str, attrs: str = 'width="100" height="100" viewBox="0 0 100 100"') -> str:
    return f'<svg {NS} xmlns:xlink="http://www.w3.org/1999/xlink" {attrs}>{body}</svg>'


def _count_drawables(path: Path) -> int:
    """Count drawable elements outside <defs> the plain way (no <use> in these files)."""
    root = ET.parse(path).getroot()
    count = 0
    stack = [root]
    while stack:
        el = stack.pop()
        tag = el.tag.rsplit("}", 1)[-1]
        if tag == "defs":
            continue
        count += tag in DRAWABLE
        stack.extend(el)
    return count


# ---------------------------------------------------------------------------
# Corpus and real-world files


@pytest.mark.parametrize("path", _files("corpus"), ids=lambda p: p.stem)
def test_corpus_element_counts(shared, path):
    truth = json.loads(path.with_suffix(".json").read_text())
    scene = load_svg(path)
    assert len(scene.elements) == truth["elements"]
    assert scene.warnings == ()
    assert scene.viewbox is not None
    for el in scene.elements:
        assert el.cubics.ndim == 2 and el.cubics.shape[1] == 4 and el.cubics.dtype == complex
        assert el.subpaths.shape == (len(el.cubics),)
        assert len(el.closed) == int(el.subpaths.max()) + 1
        assert np.isfinite(el.cubics).all()


def test_corpus_geometry_lies_in_viewbox(shared):
    """Shapes are in viewBox user units: they fall inside the (tight) viewBox of each corpus file."""
    for path in _files("corpus"):
        scene = load_svg(path)
        x, y, w, h = scene.viewbox
        pts = np.concatenate([sample_cubics(e.cubics, 8) for e in scene.elements])
        tol = 0.02 * max(w, h)
        assert pts.real.min() >= x - tol and pts.real.max() <= x + w + tol, path.name
        assert pts.imag.min() >= y - tol and pts.imag.max() <= y + h + tol, path.name


def test_ring_use_instances(shared):
    scene = load_svg(shared / "corpus" / "ring.svg")
    assert len(scene.elements) == 8
    assert all(e.source.startswith("use[") and e.source.endswith("path#hook") for e in scene.elements)
    # Each instance is the hook turned 45° more about its origin; instance 0 starts at (300, 300).
    starts = np.array([e.cubics[0, 0] for e in scene.elements])
    assert starts[0] == pytest.approx(300 + 300j)
    # The first segment (0,0)->(0,18) turns by 45° per instance.
    directions = np.array([e.cubics[0, 3] - e.cubics[0, 0] for e in scene.elements])
    turns = np.angle(directions[1:] / directions[:-1], deg=True)
    assert np.allclose(turns, 45, atol=0.01)
    assert style_of(scene.elements[0]) == {"fill": "none", "stroke": "#1b5e20", "stroke-width": "1"}


def test_flowers_nested_groups(shared):
    scene = load_svg(shared / "corpus" / "flowers.svg")
    assert len(scene.elements) == 18
    # First element: M0,0 L0,20 ... in translate(80 300) rotate(-90): (0, 20) -> (80 + 20, 300).
    first = scene.elements[0]
    assert first.cubics[0, 0] == pytest.approx(80 + 300j)
    assert first.cubics[0, 3] == pytest.approx(100 + 300j)


@pytest.mark.parametrize("path", _files("realworld"), ids=lambda p: p.stem)
def test_realworld_files_import(shared, path):
    scene = load_svg(path)
    assert len(scene.elements) == _count_drawables(path)
    assert scene.viewbox is not None and scene.size is not None


def test_eight_dots_are_circles(shared):
    scene = load_svg(shared / "realworld" / "svg-spinners_8-dots-rotate.svg")
    assert len(scene.elements) == 8
    for el in scene.elements:
        assert el.source.startswith("circle[")
        pts = sample_uniform(el.cubics, 65)[:-1]  # closed: the last point repeats the first
        centre = pts.mean()
        assert np.allclose(np.abs(pts - centre), 2.0, atol=1e-4)
        assert style_of(el)["fill"] == "#000000"


def test_bars_rotate_about_centre(shared):
    scene = load_svg(shared / "realworld" / "svg-spinners_bars-rotate-fade.svg")
    rects = scene.elements
    assert len(rects) == _count_drawables(shared / "realworld" / "svg-spinners_bars-rotate-fade.svg")
    base = np.array([11 + 1j, 13 + 1j, 13 + 6j, 11 + 6j])
    for k, el in enumerate(rects):
        rot = np.exp(1j * math.radians(30 * k))
        expected = (base - (12 + 12j)) * rot + (12 + 12j)
        assert np.allclose(el.cubics[:, 0], expected, atol=1e-9)
        assert el.closed == (True,)
    opacities = [float(style_of(e).get("opacity", 1)) for e in rects]
    assert opacities == sorted(opacities)
    assert opacities[0] == pytest.approx(0.14)


# ---------------------------------------------------------------------------
# Styles


def test_css_classes_and_presentation_attributes():
    text = svg(
        "<style>.leaf{fill:#ff0000;stroke:blue} #special{stroke-width:3} rect{fill-opacity:.5}</style>"
        '<path class="leaf" d="M0 0 L10 0 L5 5 Z"/>'
        '<path id="special" class="leaf" d="M20 0 L30 0 L25 5 Z"/>'
        '<rect x="40" y="0" width="5" height="5"/>'
        '<g fill="green" stroke="black" stroke-width="2" stroke-linecap="round">'
        '<circle cx="70" cy="5" r="3"/></g>'
        '<path d="M80 0 L90 0 L85 5 Z"/>'
    )
    els = parse_svg(text).elements
    assert style_of(els[0]) == {"fill": "#ff0000", "stroke": "#0000ff", "stroke-width": "1"}
    assert style_of(els[1])["stroke-width"] == "3"
    assert style_of(els[2]) == {"fill": "#000000", "fill-opacity": "0.5", "stroke": "none"}
    assert style_of(els[3]) == {
        "fill": "#008000",
        "stroke": "#000000",
        "stroke-width": "2",
        "stroke-linecap": "round",
    }
    assert style_of(els[4]) == {"fill": "#000000", "stroke": "none"}  # SVG default: black fill


def test_stroke_width_scaled_by_transform_and_group_opacity_multiplies():
    text = svg(
        '<g opacity="0.5"><g opacity="0.5">'
        '<path transform="scale(3)" stroke="red" stroke-width="2" fill="none" d="M0 0 L10 0"/>'
        "</g></g>"
    )
    (el,) = parse_svg(text).elements
    st = style_of(el)
    assert float(st["stroke-width"]) == pytest.approx(6.0)
    assert float(st["opacity"]) == pytest.approx(0.25)
    assert el.cubics[0, 3] == pytest.approx(30 + 0j)


def test_viewbox_units_not_viewport_units():
    text = svg(
        '<rect x="1" y="2" width="3" height="4" stroke="red" stroke-width="2"/>',
        'width="100mm" height="50mm" viewBox="0 0 10 5"',
    )
    scene = parse_svg(text)
    (el,) = scene.elements
    assert scene.viewbox == (0.0, 0.0, 10.0, 5.0)
    assert scene.size == ("100mm", "50mm")
    assert el.cubics[0, 0] == pytest.approx(1 + 2j)
    assert el.cubics[:, 0] == pytest.approx(np.array([1 + 2j, 4 + 2j, 4 + 6j, 1 + 6j]))
    assert float(style_of(el)["stroke-width"]) == pytest.approx(2.0)


def test_ignored_and_hidden_content():
    text = svg(
        '<defs><path id="d" d="M0 0 L1 1"/></defs>'
        '<symbol id="s"><circle cx="5" cy="5" r="2"/></symbol>'
        "<text x='1' y='1'>hello</text><image href='x.png' width='5' height='5'/>"
        '<rect width="4" height="4" style="display:none"/>'
        '<rect width="4" height="4" visibility="hidden"/>'
        '<rect width="4" height="4"><animate attributeName="width" values="4;8" dur="1s"/></rect>'
        '<use href="#s" x="10"/>'
    )
    els = parse_svg(text).elements
    assert [e.source for e in els] == ["rect[2]", "use[0]>circle[0]"]
    circle = els[1]
    assert sample_uniform(circle.cubics, 17)[:-1].mean() == pytest.approx(15 + 5j, abs=1e-6)


def test_element_sources():
    text = svg('<path id="leaf" d="M0 0 L5 5"/><path d="M0 0 L5 6"/><circle cx="1" cy="1" r="1"/>')
    assert [e.source for e in parse_svg(text).elements] == ["path#leaf", "path[1]", "circle[0]"]


# ---------------------------------------------------------------------------
# Geometry conversion


def test_lines_quadratics_and_arcs_become_cubics():
    c, sub, closed = cubics_from_d("M0 0 L9 0 Q12 0 12 3 A3 3 0 0 1 9 6 Z")
    assert closed == (True,)
    assert (sub == 0).all()
    # Line: control points at thirds.
    assert c[0] == pytest.approx(np.array([0, 3, 6, 9], dtype=complex))
    # Quadratic elevated exactly: the cubic equals the quadratic at every t.
    t = np.linspace(0, 1, 11)
    quad = (1 - t) ** 2 * 9 + 2 * (1 - t) * t * 12 + t**2 * (12 + 3j)
    assert sample_cubics(c[1:2], 11) == pytest.approx(quad)
    # Arc of radius 3 about (9, 3), from (12, 3) to (9, 6): every point 3 from the centre.
    arc = c[2:-1]
    pts = sample_cubics(arc, 20)
    assert np.allclose(np.abs(pts - (9 + 3j)), 3.0, atol=1e-6)
    # The closing Z adds the line back to the start.
    assert c[-1, 0] == pytest.approx(9 + 6j) and c[-1, 3] == 0


def test_relative_smooth_and_implicit_commands():
    a = cubics_from_d("m10 10 l5 0 0 5 h-5 z m20 0 c1 1 2 1 3 0 s2 -1 3 0 q1 2 2 0 t2 0")
    b = cubics_from_d(
        "M10 10 L15 10 L15 15 L10 15 Z M30 10 C31 11 32 11 33 10 C34 9 35 9 36 10 Q37 12 38 10 Q39 8 40 10"
    )
    assert np.allclose(a[0], b[0]) and (a[1] == b[1]).all() and a[2] == b[2] == (True, False)


def test_zero_radius_arc_is_a_line_and_zero_length_segments_drop():
    c, _, _ = cubics_from_d("M0 0 L0 0 A0 0 0 0 1 10 0")
    assert c.shape == (1, 4)
    assert c[0] == pytest.approx(np.array([0, 10 / 3, 20 / 3, 10], dtype=complex))


def test_invalid_path_data_is_an_svg_error():
    with pytest.raises(SvgError):
        cubics_from_d("M 0 0 L 5 nonsense")


# ---------------------------------------------------------------------------
# Skipped elements


def test_degenerate_elements_are_skipped_with_warning():
    text = svg(
        '<circle cx="5" cy="5" r="3" transform="scale(0)"/>'
        '<path d="M0 0 L10 10" transform="scale(0)"/>'
        '<path d="M1 1 L1 1"/>'
        '<rect width="0" height="5"/>'
        '<path d="M0 0 L1e400 0"/>'
        '<path d="M0 0 L5e12 0"/>'
        '<path d="M0 0 Lnan 0"/>'
        "<path/>"
        '<rect width="3" height="3"/>'
    )
    scene = parse_svg(text)
    assert [e.source for e in scene.elements] == ["rect[1]"]
    warnings = " | ".join(scene.warnings)
    assert "skipped 5 elements: degenerate (zero size)" in warnings
    assert "skipped 1 element: malformed path data" in warnings  # Lnan
    assert "skipped 2 elements: non-finite or huge coordinates" in warnings


def test_nothing_drawable_is_an_svg_error():
    with pytest.raises(SvgError, match="no drawable elements in <string>"):
        parse_svg(svg('<circle r="3" transform="scale(0)"/><text>hi</text>'))
    with pytest.raises(SvgError, match="no drawable elements"):
        parse_svg(svg(""))


def test_nothing_drawable_allowed_is_an_empty_scene_with_a_warning():
    scene = parse_svg(svg('<circle r="3" transform="scale(0)"/>'), allow_empty=True, name="x.svg")
    assert scene.elements == ()
    assert "x.svg draws nothing: it has no drawable elements" in scene.warnings
    assert any("degenerate" in w for w in scene.warnings)  # the reason is said too


# ---------------------------------------------------------------------------
# Hostile and broken input: each fails fast with the right error


BILLION_LAUGHS = """<?xml version="1.0"?>
<!DOCTYPE lolz [
 <!ENTITY lol "lol">
 <!ENTITY lol1 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">
 <!ENTITY lol2 "&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;">
 <!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">
 <!ENTITY lol9 "&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;">
]>
<svg xmlns="http://www.w3.org/2000/svg"><text>&lol9;</text><rect width="1" height="1"/></svg>"""

XXE = """<?xml version="1.0"?>
<!DOCTYPE svg [<!ENTITY xxe SYSTEM "file:///etc/passwd">]>
<svg xmlns="http://www.w3.org/2000/svg"><text>&xxe;</text><rect width="1" height="1"/></svg>"""


def _fan_out(levels: int, width: int) -> str:
    defs = ['<path id="l0" d="M0 0 L1 1"/>']
    for i in range(1, levels + 1):
        uses = "".join(f'<use href="#l{i - 1}"/>' for _ in range(width))
        defs.append(f'<g id="l{i}">{uses}</g>')
    return svg(f"<defs>{''.join(defs)}</defs><use href='#l{levels}'/>")


HOSTILE = [
    ("billion laughs", BILLION_LAUGHS, SvgError, "nested entities are not allowed"),
    ("xxe", XXE, SvgError, "entities are not allowed"),
    (
        "internal subset",
        '<!DOCTYPE svg [<!ATTLIST svg foo CDATA "x">]><svg xmlns="http://www.w3.org/2000/svg"/>',
        SvgError,
        "internal subset",
    ),
    (
        "use cycle only",
        svg('<g id="a"><use href="#b"/></g><g id="b"><use xlink:href="#a"/></g>'),
        SvgError,
        "cycle",
    ),
    ("use fan-out", _fan_out(12, 10), LimitError, "more than 200,000 elements"),
    ("truncated", svg('<rect width="1" height="1"/>')[:-9], SvgError, "not an SVG"),
    ("binary junk", bytes(range(256)) * 4, SvgError, "not an SVG"),
    ("empty", b"", SvgError, "empty"),
    ("whitespace", b"  \n ", SvgError, "empty"),
    ("not svg root", '<html xmlns="http://www.w3.org/1999/xhtml"><p/></html>', SvgError, "root element"),
    (
        "deep nesting",
        svg("<g>" * 2000 + '<rect width="1" height="1"/>' + "</g>" * 2000),
        LimitError,
        "nested",
    ),
    (
        "bad encoding",
        '<?xml version="1.0" encoding="UTF-8"?><svg>\xe9</svg>'.encode("latin-1"),
        SvgError,
        "not an SVG",
    ),
    ("unknown encoding", b'<?xml version="1.0" encoding="x-nope"?><svg/>', SvgError, "not an SVG"),
]


@pytest.mark.parametrize(
    "body",
    [
        '<use id="u" href="#u"/><rect width="1" height="1"/>',
        '<g id="a"><rect width="1" height="1"/><use href="#a"/></g>',
    ],
    ids=["self use", "ancestor use"],
)
def test_use_cycles_are_skipped_with_a_warning(body):
    """A <use> closing a reference cycle is left out (as renderers do); the rest is drawn."""
    scene = parse_svg(svg(body))
    assert [e.source for e in scene.elements] == ["rect[0]"]
    assert any("reference cycle" in w for w in scene.warnings)


def test_unreadable_transform_is_ignored_with_a_warning():
    scene = parse_svg(svg('<rect width="4" height="4" transform="rotate(foo)"/>'))
    (el,) = scene.elements
    assert el.cubics[0, 0] == 0
    assert any("unreadable transform 'rotate(foo)'" in w for w in scene.warnings)


@pytest.mark.parametrize(("label", "data", "error", "message"), HOSTILE, ids=[h[0] for h in HOSTILE])
def test_hostile_input(label, data, error, message):
    with pytest.raises(error) as info:  # a hang fails by pytest-timeout; speed: make bench
        parse_svg(data)
    text = str(info.value)
    assert message in text
    assert "\n" not in text
    assert isinstance(info.value, LsysError)


def test_long_use_chain_is_limited():
    chain = ['<path id="c0" d="M0 0 L1 1"/>'] + [f'<use id="c{i}" href="#c{i - 1}"/>' for i in range(1, 800)]
    text = svg(f"<defs>{''.join(chain)}</defs><use href='#c799'/>")
    with pytest.raises(LimitError, match="nest"):
        parse_svg(text)


def test_shared_definitions_are_not_a_limit_problem():
    """Many uses of one definition are fine when the expansion stays small."""
    scene = parse_svg(_fan_out(3, 10))
    assert len(scene.elements) == 1000


def test_size_limits(tmp_path):
    big = tmp_path / "big.svg"
    big.write_text(svg('<rect width="1" height="1"/>' * 100))
    with pytest.raises(LimitError, match="too large"):
        load_svg(big, max_bytes=1000)
    with pytest.raises(LimitError, match="more than 50 elements"):
        load_svg(big, max_elements=50)
    assert len(load_svg(big).elements) == 100


def test_public_doctype_is_accepted():
    text = (
        '<?xml version="1.0"?><!DOCTYPE svg PUBLIC "-//W3C//DTD SVG 1.1//EN" '
        '"http://www.w3.org/Graphics/SVG/1.1/DTD/svg11.dtd">' + svg('<rect width="1" height="1"/>')
    )
    assert len(parse_svg(text).elements) == 1


def test_svgz_and_gzip_bomb(tmp_path):
    f = tmp_path / "a.svgz"
    f.write_bytes(gzip.compress(svg('<rect width="2" height="2"/>').encode()))
    assert len(load_svg(f).elements) == 1
    bomb = tmp_path / "bomb.svgz"
    bomb.write_bytes(gzip.compress(b" " * 5_000_000))
    with pytest.raises(LimitError, match="decompresses"):
        load_svg(bomb, max_bytes=100_000)


def test_missing_file():
    with pytest.raises(SvgError, match="cannot read"):
        load_svg("/nonexistent/file.svg")


def test_import_of_many_paths():
    rng = np.random.default_rng(0)
    xy = rng.uniform(0, 1000, (3000, 2)).tolist()
    body = "".join(
        f'<path fill="none" stroke="#000" d="M{x:.2f},{y:.2f} c6,-6 16,-5 22,0 c-7,3 -16,6 -22,0 z"/>'
        for x, y in xy
    )
    text = svg(body, 'viewBox="0 0 1000 1000"')
    scene = parse_svg(text)  # speed: tests/bench/bench_svg.py
    assert len(scene.elements) == 3000


# ---------------------------------------------------------------------------
# What each element draws with, paint order, definitions and content kept as is


def test_css_rule_after_import_still_applies():
    text = svg('<style>@import url(other.css); path { fill: red }</style><path d="M0 0 L10 0 L5 5 Z"/>')
    scene = parse_svg(text)
    assert style_of(scene.elements[0])["fill"] == "#ff0000"
    assert any("@import" in w for w in scene.warnings)


def test_empty_stroke_is_no_stroke():
    (el,) = parse_svg(svg('<path stroke="" d="M0 0 L10 0 L5 5 Z"/>')).elements
    assert style_of(el)["stroke"] == "none"


def test_paint_order_numbers_elements_and_kept_content_together():
    text = svg(
        '<rect width="5" height="5"/><text x="1" y="9">A</text>'
        '<image href="data:," width="2" height="2"/><circle cx="5" cy="5" r="2"/>'
    )
    scene = parse_svg(text)
    assert [e.order for e in scene.elements] == [0, 3]
    assert [v.order for v in scene.verbatim] == [1, 2]
    assert scene.verbatim[0].what == "<text> 'A'"
    assert "kept as is: 1 <text>, 1 <image>" in scene.warnings


def test_kept_content_carries_inherited_style_and_transform():
    text = svg(
        "<style>text { font-size: 7px }</style>"
        '<g fill="green" transform="translate(10 20)"><text x="1" y="2">hi</text></g><rect width="1" height="1"/>'
    )
    (v,) = parse_svg(text).verbatim
    root = ET.fromstring(v.xml)
    assert root.get("transform") == "matrix(1 0 0 1 10 20)"
    assert "fill:green" in root.get("style")
    assert "font-size:7px" in root[0].get("style")


def test_gradients_are_rewritten_in_document_coordinates():
    text = svg(
        '<linearGradient id="g"><stop offset="0" stop-color="red"/><stop offset="1" stop-color="blue"/>'
        "</linearGradient>"
        '<rect x="10" y="10" width="20" height="10" fill="url(#g)" transform="translate(5 0)"/>'
        '<rect x="0" y="0" width="10" height="10" fill="url(#g)"/>'
    )
    scene = parse_svg(text)
    refs = [style_of(e)["fill"] for e in scene.elements]
    assert refs[0] != refs[1] and all(r.startswith("url(#g-") for r in refs)
    defs = ET.fromstring(f'<defs xmlns="http://www.w3.org/2000/svg">{scene.defs}</defs>')
    ids = [g.get("id") for g in defs]
    assert len(ids) == len(set(ids)) == 2
    first = defs[0]
    assert first.get("gradientUnits") == "userSpaceOnUse"
    # objectBoundingBox of the first rect (20 x 10 at 10,10), then its translate(5 0).
    assert first.get("gradientTransform") == "matrix(20 0 0 10 15 10)"


@pytest.mark.parametrize(
    ("href", "painted"),
    [
        ("rect1", True),  # not a local reference: not followed, the gradient keeps its own attributes
        ("#nowhere", False),  # a local reference that leads nowhere: paints nothing
        ("#rect1", False),  # a local reference to another kind of element: paints nothing
    ],
)
def test_gradient_reference_into_another_document_is_ignored(href: str, painted: bool):
    text = svg(
        f'<radialGradient id="g" xlink:href="{href}"><stop offset="0" stop-color="white"/>'
        '<stop offset="1" stop-color="black"/></radialGradient>'
        '<rect id="rect1" x="10" y="10" width="80" height="80" fill="url(#g)"/>'
    )
    scene = parse_svg(text)
    fills = [style_of(e).get("fill", "none") for e in scene.elements]
    assert [f.startswith("url(#g-") for f in fills] == ([True] if painted else [False] * len(fills))


def test_clip_path_reference_closing_a_cycle_is_ignored():
    """A clip path clipped by itself: the reference closing the cycle is cut, the shape is still clipped."""
    star = "M 50 5 l 25 80 l -65 -50 l 80 0 l -65 50 z"
    text = svg(
        f'<clipPath id="c1" clip-path="url(#c1)"><path d="{star}"/></clipPath>'
        '<rect width="100" height="100" fill="green" clip-path="url(#c1)"/>'
    )
    scene = parse_svg(text)
    (rect,) = scene.elements
    ref = style_of(rect)["clip-path"]
    defs = ET.fromstring(f'<defs xmlns="http://www.w3.org/2000/svg">{scene.defs}</defs>')
    (clip,) = [c for c in defs if f"url(#{c.get('id')})" == ref]
    assert [local_name(c.tag) for c in clip] == ["path"]
    assert any("reference cycle" in n for n in scene.warnings)


def test_markers_are_expanded_into_elements():
    """A flag whose 50 stars are marker-mid instances gives 50 star elements (plus the line)."""
    points = " ".join(f"{10 + 10 * i},10" for i in range(52))
    text = svg(
        '<marker id="star" markerWidth="4" markerHeight="4" refX="2" refY="2" markerUnits="userSpaceOnUse">'
        '<path d="M2 0 L3 4 L0 1.5 L4 1.5 L1 4 Z" fill="white"/></marker>'
        f'<polyline points="{points}" fill="none" stroke="blue" marker-mid="url(#star)"/>',
        'viewBox="0 0 600 20"',
    )
    scene = parse_svg(text)
    stars = [e for e in scene.elements if "marker" in e.source]
    assert len(stars) == 50
    assert [e.order for e in scene.elements] == sorted(e.order for e in scene.elements)
    centres = sorted(float(np.mean(e.cubics[:, 0].real)) for e in stars)
    assert centres[0] == pytest.approx(20, abs=1.5) and centres[-1] == pytest.approx(510, abs=1.5)


def test_nested_svg_viewport_maps_and_clips():
    text = svg(
        '<svg x="10" y="10" width="20" height="20" viewBox="0 0 10 10">'
        '<rect x="0" y="0" width="10" height="10"/></svg>'
    )
    scene = parse_svg(text)
    (el,) = scene.elements
    assert el.cubics[:, 0] == pytest.approx(np.array([10 + 10j, 30 + 10j, 30 + 30j, 10 + 30j]))
    assert style_of(el)["clip-path"].startswith("url(#viewport-")


def test_rect_rounded_corners_and_font_relative_units():
    text = svg('<g font-size="10"><rect x="1em" y="0" width="4em" height="2em" rx="0.5em"/></g>')
    (el,) = parse_svg(text).elements
    x0, y0, x1, y1 = (
        el.cubics.real.min(),
        el.cubics.imag.min(),
        el.cubics.real.max(),
        el.cubics.imag.max(),
    )
    assert (x0, y0, x1, y1) == pytest.approx((10, 0, 50, 20))
    assert len(el.cubics) > 4  # rounded corners are curves
    assert not any(np.isclose(el.cubics[:, 0], 10 + 0j))  # no sharp corner at (x, y)


def test_stroke_widths_and_dashes_are_in_document_units():
    text = svg(
        '<path transform="scale(2)" d="M0 0 L10 0" stroke="black" stroke-width="3" '
        'stroke-dasharray="1 2 3" stroke-dashoffset="1" stroke-linecap="round" stroke-linejoin="bevel"/>'
    )
    (el,) = parse_svg(text).elements
    st = style_of(el)
    assert st["stroke-width"] == "6"
    assert st["stroke-dasharray"] == "2,4,6,2,4,6"
    assert st["stroke-dashoffset"] == "2"
    assert st["stroke-linecap"] == "round" and st["stroke-linejoin"] == "bevel"


def test_clip_paths_are_rewritten_in_document_coordinates():
    text = svg(
        '<clipPath id="c" clipPathUnits="objectBoundingBox"><rect width="0.5" height="1"/></clipPath>'
        '<rect x="10" y="0" width="20" height="10" clip-path="url(#c)"/>'
    )
    scene = parse_svg(text)
    assert clip_box(scene, scene.elements[0]) == pytest.approx((10, 20, 0, 10))


def test_illustrator_entities_are_accepted():
    text = (
        '<?xml version="1.0"?><!DOCTYPE svg PUBLIC "-//W3C//DTD SVG 1.1//EN" '
        '"http://www.w3.org/Graphics/SVG/1.1/DTD/svg11.dtd" [\n'
        '<!ENTITY ns_svg "http://www.w3.org/2000/svg">\n<!ENTITY st0 "fill:#ff0000">\n]>'
        '<svg xmlns="&ns_svg;" viewBox="0 0 10 10"><rect style="&st0;" width="5" height="5"/></svg>'
    )
    (el,) = parse_svg(text).elements
    assert style_of(el)["fill"] == "#ff0000"


def test_internal_subset_after_64_kib_is_still_checked():
    text = '<?xml version="1.0"?>' + "<!-- " + "x" * 70_000 + " -->"
    text += '<!DOCTYPE svg [<!ENTITY % p "x">]><svg xmlns="http://www.w3.org/2000/svg"/>'
    with pytest.raises(SvgError, match="parameter entities"):
        parse_svg(text)


def test_names_and_ids_are_escaped_in_messages():
    with pytest.raises(SvgError) as info:
        parse_svg(svg(""), name="evil\nname\x1b[31m.svg")
    assert "\n" not in str(info.value) and "\x1b" not in str(info.value)
    scene = parse_svg(svg('<rect id="a&#10;b" width="1" height="1" transform="bad"/>'))
    assert all("\n" not in w for w in scene.warnings)
