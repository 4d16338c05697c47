"""What the SVG reader remembers to read many simple elements fast changes nothing it reads.

Equal styles are shared and what is derived from them is remembered by identity
(:mod:`lsys_core.svg.style`, :mod:`lsys_core.svg.declare`, :mod:`lsys_core.svg.facts`); a
document without ``<use>`` is measured without the reference walk (:mod:`lsys_core.svg.uses`).
Each test compares against what the reader gives with memos that forget at once, or against
values worked out by hand.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest

from lsys_core.errors import LimitError
from lsys_core.svg import declare, facts, parse_svg, style, uses
from lsys_core.svg.css import StyleSheet
from lsys_core.svg.style import Cascade
from lsys_core.svg.tree import Tree

from .svg_reading import style_of

NS = 'xmlns="http://www.w3.org/2000/svg"'


def _scene_styles(text: str) -> list[tuple[str, str, str]]:
    scene = parse_svg(text)
    return [(e.style, e.source, e.cubics.tobytes().hex()) for e in scene.elements]


def _mixed_document() -> str:
    """Equal child styles under parents that differ, style texts repeated, scaled strokes."""
    parts = []
    for i in range(12):
        parent = f'fill="#{i:02x}{i:02x}00" stroke-width="{i % 3 + 1}" font-size="{10 + i % 2}"'
        parts.append(
            f'<g {parent} transform="scale({1 + i % 2})">'
            f'<rect x="{i}" width="5" height="5" stroke="black"/>'
            f'<rect x="{i}" y="9" width="5" height="5" stroke="black" paint-order="stroke"/>'
            f'<rect x="{i}" y="19" width="5" height="5" visibility="{("hidden", "visible")[i % 2]}"/>'
            f'<path d="M0 0 L{i + 1} 3" style="stroke:red;stroke-width:2em;fill:inherit !important"/>'
            f'<path class="c" d="M1 0 L{i + 1} 3" style="stroke:red;stroke-width:2em"/>'
            "</g>"
        )
    return f"<svg {NS} viewBox='0 0 100 100'><style>.c{{stroke:blue!important}}</style>{''.join(parts)}</svg>"


def test_equal_styles_share_one_computed_style_per_parent():
    root = ET.fromstring(
        f'<svg {NS}><g fill="red"><rect id="a"/><rect id="b"/></g><g fill="blue"><rect id="c"/></g></svg>'
    )
    cascade = Cascade(Tree(root), StyleSheet())
    g1, g2 = list(root)
    s1, s2 = cascade.computed(g1, {}, 12.0), cascade.computed(g2, {}, 12.0)
    a, b = list(g1)
    (c,) = list(g2)
    assert cascade.computed(a, s1, 12.0) is cascade.computed(b, s1, 12.0)
    assert cascade.computed(a, s1, 12.0)["fill"] == "red"
    assert cascade.computed(c, s2, 12.0)["fill"] == "blue"  # same specified style, other parent


def test_small_memos_read_the_same(monkeypatch):
    """Memos that start again after every second style give the same scene as the full ones."""
    text = _mixed_document()
    full = _scene_styles(text)
    fills = {style_of(e)["fill"] for e in parse_svg(text).elements if "fill" in style_of(e)}
    assert len(fills) >= 12  # each group's own fill reached its children
    monkeypatch.setattr(style, "MEMO_SIZE", 2)
    monkeypatch.setattr(declare, "MEMO_SIZE", 2)
    monkeypatch.setattr(facts, "MEMO_SIZE", 2)
    assert _scene_styles(text) == full


def test_stroke_width_follows_each_shapes_scale():
    """Siblings of one style under different scales keep their own stroke widths."""
    body = (
        '<g stroke="black" stroke-width="2"><rect width="5" height="5"/></g>'
        '<g stroke="black" stroke-width="2" transform="scale(3)"><rect width="5" height="5"/></g>'
    )
    a, b = parse_svg(f"<svg {NS}>{body}</svg>").elements
    assert float(style_of(a)["stroke-width"]) == 2.0
    assert float(style_of(b)["stroke-width"]) == 6.0


def _tree(body: str) -> Tree:
    return Tree(ET.fromstring(f"<svg {NS} xmlns:x='urn:x'>{body}</svg>"))


BODY = (
    "<defs><rect id='r' width='1' height='1'/><g><circle r='1'/></g></defs>"
    "<g><g><rect width='1' height='1'/><!-- a comment --><x:thing/></g>"
    "<symbol><rect width='1' height='1'/></symbol><text>t</text></g>"
)


def test_expansion_without_use_counts_as_the_reference_walk(monkeypatch):
    tree = _tree(BODY)
    quick = uses.check_expansion(tree, 100, 100, "doc")
    assert quick == 6  # root, g, g, rect, x:thing, text (not the defs, the symbol, their content)
    monkeypatch.setattr(uses, "has_use", lambda root: True)
    assert uses.check_expansion(tree, 100, 100, "doc") == quick


@pytest.mark.parametrize(
    ("elements", "depth", "message"),
    [(5, 100, "expands to more than 5 elements"), (100, 3, "nest more than 3 levels deep")],
)
def test_expansion_without_use_beyond_a_limit(elements, depth, message):
    with pytest.raises(LimitError, match=message):
        uses.check_expansion(_tree(BODY), elements, depth, "doc")
