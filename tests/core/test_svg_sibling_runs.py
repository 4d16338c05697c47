"""Like sibling shapes share their walk (:mod:`lsys_core.svg.siblings`) and nothing they read changes.

Each document is read twice: as the reader does, and with no two siblings ever taken for alike
(every element walked the full way); the scenes must be equal.  The documents put siblings with
equal attributes under parents whose inherited style differs, behind style sheets that tell
siblings apart, in groups whose effects change their records, and next to empty path data.
"""

from __future__ import annotations

import pytest

from lsys_core.svg import parse_svg, walk
from lsys_core.svg.model import Element

NS = 'xmlns="http://www.w3.org/2000/svg"'
LEAF = 'd="M{x},0 q5,-8 14,-2 q-5,4 -14,2 z"'


def _leaves(attrs: str, n: int = 4, dx: int = 20) -> str:
    return "".join(f"<path {attrs} {LEAF.format(x=i * dx)}/>" for i in range(n))


def _scene(text: str):
    s = parse_svg(text, allow_empty=True)
    return (
        [
            (e.style, e.source, e.order, e.closed, e.cubics.tobytes(), e.subpaths.tobytes())
            for e in s.elements
        ],
        s.warnings,
        s.defs,
        [(v.order, v.xml, v.what) for v in s.verbatim],
    )


def _both(text: str, monkeypatch) -> tuple:
    fast = _scene(text)
    with monkeypatch.context() as m:
        m.setattr(walk, "same_run", lambda run, el: False)
        full = _scene(text)
    return fast, full


RED2 = _leaves('fill="red"', 2)
DOCUMENTS = {
    "parents differ": (
        f'<svg {NS}><g fill="red" stroke="blue">{_leaves("")}</g>'
        '<g fill="green" color="orange" stroke-width="3">' + _leaves('stroke="currentColor"') + "</g>"
        '<g transform="scale(2)">' + _leaves('fill="inherit"') + "</g></svg>"
    ),
    "one attribute differs": (
        f'<svg {NS}>{RED2}<path fill="blue" {LEAF.format(x=50)}/>'
        f'<path fill="red" id="x" {LEAF.format(x=60)}/><path fill="red" transform="rotate(30)" {LEAF.format(x=70)}/>'
        f'<path fill="red" style="fill:none;stroke:red" {LEAF.format(x=80)}/>{RED2}</svg>'
    ),
    "style sheet tells siblings apart": (
        f"<svg {NS}><style>path:first-child {{ fill: red }} #b {{ stroke: blue }} path + path {{ opacity: .5 }}</style>"
        f'<g><path fill="green" {LEAF.format(x=0)}/><path fill="green" {LEAF.format(x=20)}/>'
        f'<path fill="green" id="b" {LEAF.format(x=40)}/></g></svg>'
    ),
    "group effects change records": (
        f'<svg {NS}><defs><clipPath id="c"><rect width="30" height="30"/></clipPath></defs>'
        f'<g opacity="0.5">{RED2}</g>{RED2}<g clip-path="url(#c)">{RED2}</g>{RED2}</svg>'
    ),
    "empty, broken and hidden path data": (
        f'<svg {NS}>{RED2}<path fill="red" d="M5,5"/><path fill="red" d=""/>'
        f'<path fill="red" d="M0,0 L10,10 L x"/><path fill="red"/>{RED2}'
        f'<g visibility="hidden" opacity=".5">{RED2}</g></svg>'
    ),
    "markers, caps, paint servers": (
        f'<svg {NS}><defs><marker id="m"><circle r="1"/></marker>'
        '<linearGradient id="g"><stop offset="0" stop-color="red"/></linearGradient></defs>'
        + _leaves('fill="none" stroke="black" marker-end="url(#m)"', 3)
        + _leaves('stroke="black" stroke-linecap="round"', 2)
        + '<path stroke="black" stroke-linecap="round" d="M9,9 z"/>'
        + _leaves('fill="url(#g)"', 3, 40)
        + "</svg>"
    ),
    "basic shapes and symbols": (
        f'<svg {NS}><symbol id="s"><rect width="3" height="2" fill="red"/><rect x="5" width="3" height="2" fill="red"/>'
        '<rect x="9" width="0" height="2" fill="red"/></symbol>'
        '<use href="#s" fill="blue"/><use href="#s" x="20" width="40" height="40"/>'
        '<circle r="2" cx="1"/><circle r="2" cx="5"/><circle r="-1" cx="5"/>'
        '<polygon points="0,0 5,0 5,5" fill="red"/><polygon points="9,0 15,0 15,5" fill="red"/></svg>'
    ),
}


@pytest.mark.parametrize("name", sorted(DOCUMENTS))
def test_siblings_read_alike_give_the_scene_of_the_full_walk(name, monkeypatch):
    fast, full = _both(DOCUMENTS[name], monkeypatch)
    assert fast == full


def test_equal_attributes_under_different_parents_get_their_parents_styles():
    elements, *_ = _scene(DOCUMENTS["parents differ"])
    styles = [e[0] for e in elements]
    assert len(styles) == 12
    assert len(set(styles[0:4])) == len(set(styles[4:8])) == len(set(styles[8:12])) == 1
    assert "fill:#ff0000" in styles[0] and "stroke:#0000ff" in styles[0]
    assert "fill:#008000" in styles[4] and "stroke:#ffa500" in styles[4]
    assert "stroke" not in styles[8] or "stroke:none" in styles[8]
    assert styles[0] != styles[4] != styles[8]


def test_a_style_sheet_can_tell_equal_siblings_apart():
    elements, *_ = _scene(DOCUMENTS["style sheet tells siblings apart"])
    first, second, third = (e[0] for e in elements)
    assert "fill:#ff0000" in first and "opacity" not in first
    assert "fill:#008000" in second and "opacity:0.5" in second
    assert "stroke:#0000ff" in third and "opacity:0.5" in third


def test_group_opacity_stays_with_the_group():
    elements, *_ = _scene(DOCUMENTS["group effects change records"])
    styles = [e[0] for e in elements]
    assert all("opacity:0.5" in s for s in styles[:2])
    assert not any("opacity" in s for s in styles[2:4])
    assert all("clip-path" in s for s in styles[4:6])
    assert not any("clip-path" in s or "opacity" in s for s in styles[6:])


def test_elements_equal_those_the_dataclass_makes():
    scene = parse_svg(DOCUMENTS["parents differ"])
    assert not hasattr(Element, "__post_init__") and not hasattr(Element, "__slots__")
    for e in scene.elements:
        made = Element(**vars(e))
        assert type(e) is Element and vars(e).keys() == vars(made).keys()
        assert all(vars(e)[k] is vars(made)[k] for k in vars(e))
        assert not e.cubics.flags.writeable and not e.subpaths.flags.writeable
        with pytest.raises(AttributeError):
            e.order = 0  # type: ignore[misc]


def test_elements_of_a_kind_in_document_order_with_and_without_the_namespace():
    import xml.etree.ElementTree as ET

    from lsys_core.svg.records import source_names
    from lsys_core.svg.tree import Tree

    text = (
        '<svg xmlns:s="http://www.w3.org/2000/svg"><path id="a"/><s:path/><g><path/><s:style/></g>'
        "<s:path/><style/><path/></svg>"
    )
    tree = Tree(ET.fromstring(text))
    order = [el for el in tree.root.iter() if el.tag.rpartition("}")[2] == "path"]
    assert tree.of_kind("path") == order and len(order) == 5
    assert len(tree.of_kind("style")) == 2 and tree.of_kind("rect") == []
    assert [source_names(tree)[id(el)] for el in order] == [
        "path#a",
        "path[1]",
        "path[2]",
        "path[3]",
        "path[4]",
    ]


def _names_one_by_one(tree) -> dict[int, str]:
    """The names as the walk gave them element by element (the reference of ``source_names``)."""
    from lsys_core.svg.records import SHAPES
    from lsys_core.svg.tree import SVG_NS, shown

    named = {tag: tag for tag in (*SHAPES, "use")}
    named.update({SVG_NS + tag: tag for tag in named})
    counts = dict.fromkeys(named.values(), 0)
    names: dict[int, str] = {}
    for el in tree.root.iter():
        tag = named.get(el.tag)
        if tag is None:
            continue
        el_id = el.get("id")
        if el_id:
            names[id(el)] = (
                f"{tag}#{el_id}" if el_id.isprintable() and ">" not in el_id else f"{tag}#{shown(el_id)}"
            )
        else:
            names[id(el)] = f"{tag}[{counts[tag]}]"
        counts[tag] += 1
    return names


def test_source_names_kind_by_kind_are_those_named_one_by_one():
    import xml.etree.ElementTree as ET

    from lsys_core.svg.records import source_names
    from lsys_core.svg.tree import Tree

    text = (
        '<svg xmlns="http://www.w3.org/2000/svg" xmlns:s="http://www.w3.org/2000/svg">'
        '<path/><rect id="r"/><g><path id="a&gt;b"/><s:path/><rect/><use id="u&#10;x"/></g>'
        '<circle/><circle id=""/><path xmlns="" id="plain"/><path xmlns=""/>'
        '<defs><polygon/><ellipse id="e"/></defs><line/><polyline/><use/></svg>'
    )
    tree = Tree(ET.fromstring(text))
    assert source_names(tree) == _names_one_by_one(tree)
    many = Tree(ET.fromstring("<svg>" + "<path/>" * 50 + '<path id="x"/>' + "<rect/>" * 3 + "</svg>"))
    assert source_names(many) == _names_one_by_one(many)
