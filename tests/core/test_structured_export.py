"""Structured SVG export: shapes once in <defs>, instances as <use>, a <g> per rule call.

The output is read back with lxml (an XML parser independent of the writer and of the
project's SVG reader) and checked against a reference expansion of the grammar written
here (plain recursion over the rules, independent of the vectorised derivation); it is
rendered by rsvg-convert (an independent renderer) and compared with the project's.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from collections import Counter
from dataclasses import dataclass, field

import numpy as np
import pytest

from lsys_core.derive.derivation import derive
from lsys_core.grammar import parse_grammar
from lsys_core.grammar.model import COND_EQ0, COND_GT0, Grammar, Pop, Push, Symbol
from lsys_core.render.raster import default_view, render
from lsys_core.render.structured import drawing_to_structured_svg
from lsys_core.render.svg import drawing_to_svg
from lsys_core.svg import parse_svg
from lsys_core.svg.head import read_head
from lsys_core.testing import assert_scenes_close, drawing_scene

from .scenes import make_drawing
from .shared import REALWORLD, ROOT, need

etree = pytest.importorskip("lxml.etree", reason="lxml is in the test extra")

SVG_NS = "http://www.w3.org/2000/svg"
XLINK_NS = "http://www.w3.org/1999/xlink"
EXAMPLES = sorted((ROOT / "resources" / "examples").glob("*.lsys"))


# ---------------------------------------------------------------------------
# A reference expansion: the call tree by plain recursion


@dataclass
class Call:
    rule: str
    draws: int = 0
    calls: list[Call] = field(default_factory=list)
    tail: bool = False  # the rule's call of itself at the end of its body: the sequence goes on


def call_tree(g: Grammar) -> Call:
    """Expand the grammar recursively; return the axiom's call with its nested calls."""
    rules = {r.name: r for r in g.rules}
    terminals = {t.name for t in g.terminals}

    def run(call: Call, body, m: int) -> None:
        depth = 0
        for i, mod in enumerate(body):
            depth += 1 if isinstance(mod, Push) else -1 if isinstance(mod, Pop) else 0
            if not isinstance(mod, Symbol):
                continue
            if mod.name in terminals:
                call.draws += 1
            else:
                k = mod.arg.k0 + mod.arg.k1 * m if mod.arg is not None else 0
                if rules[mod.name].parametric and k < 0:
                    continue
                tail = (
                    mod.name == call.rule
                    and i == len(body) - 1
                    and depth == 0
                    and rules[mod.name].parametric
                    and mod.arg is not None
                    and mod.arg.k1 == 1
                    and mod.arg.k0 <= -1
                )
                child = Call(mod.name, tail=tail)
                run(child, case_body(rules[mod.name], k), k)
                call.calls.append(child)

    def case_body(rule, m: int):
        if not rule.parametric:
            return rule.cases[0].body
        for case in rule.cases:
            if case.cond is None or (case.cond == COND_GT0 and m > 0) or (case.cond == COND_EQ0 and m == 0):
                return case.body
        return ()

    root = Call("")
    run(root, g.axiom, 0)
    return root


def groups(call: Call) -> list[tuple[str, str, int]]:
    """Expected ``(rule, parent group's rule, instances directly inside)`` of every group.

    A rule's call of itself at the end of its body continues its caller's group (a sequence
    written as recursion is one group).
    """
    out: list[tuple[str, str, int]] = []

    def visit(call: Call, parent_rule: str, record: bool) -> int:
        """Return the instances drawn directly in ``call``'s group (its continuations included)."""
        direct = call.draws
        index = len(out)
        if record:
            out.append((call.rule, parent_rule, 0))
        for child in call.calls:
            if child.tail:
                direct += visit(child, parent_rule, record=False)
            else:
                visit(child, call.rule, record=True)
        if record:
            out[index] = (call.rule, parent_rule, direct)
        return direct

    for child in call.calls:
        visit(child, "", record=True)
    return out


# ---------------------------------------------------------------------------
# Reading the output with lxml


def parse(svg: str):
    return etree.fromstring(svg.encode("utf-8"))


def local(el) -> str:
    return etree.QName(el).localname if isinstance(el.tag, str) else ""


def check_document(svg: str) -> list[tuple[str, str, int]]:
    """Check ids and references; return ``(rule, parent rule, instances directly inside)`` per group."""
    root = parse(svg)
    ids = [el.get("id") for el in root.iter() if el.get("id") is not None]
    assert len(ids) == len(set(ids)), [k for k, v in Counter(ids).items() if v > 1]
    defs = {el.get("id") for d in root.iter(f"{{{SVG_NS}}}defs") for el in d.iter() if el.get("id")}
    for use in root.iter(f"{{{SVG_NS}}}use"):
        href = use.get(f"{{{XLINK_NS}}}href") or use.get("href")
        assert href and href.startswith("#") and href[1:] in defs, href
    found = []
    for g in root.iter(f"{{{SVG_NS}}}g"):
        if g.get("data-rule") is None:
            continue
        parent = g.getparent()
        direct = sum(1 for el in g if local(el) in ("use", "path"))
        found.append((g.get("data-rule"), parent.get("data-rule") or "", direct))
    return found


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_one_group_per_call_ids_unique_uses_resolve(path) -> None:
    g = parse_grammar(path.read_text(encoding="utf-8"))
    drawing = derive(g)
    svg = drawing_to_structured_svg(drawing)
    found = check_document(svg)
    assert sorted(found) == sorted(groups(call_tree(g)))
    root = parse(svg)
    uses = list(root.iter(f"{{{SVG_NS}}}use"))
    assert len(uses) == len(drawing)
    shapes = [el for d in root.iter(f"{{{SVG_NS}}}defs") for el in d if el.get("id")]
    assert len(shapes) == len(set(drawing.symbol.tolist())) < len(uses)  # each shape once


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_structured_draws_what_flat_draws(path) -> None:
    drawing = derive(parse_grammar(path.read_text(encoding="utf-8")))
    structured = parse_svg(drawing_to_structured_svg(drawing))
    flat = parse_svg(drawing_to_svg(drawing))
    assert len(structured.elements) == len(flat.elements) == len(drawing)
    assert_scenes_close(structured, drawing_scene(drawing))
    for mine, theirs in zip(structured.elements, flat.elements, strict=True):
        assert same_style(mine.style, theirs.style), (mine.style, theirs.style)


def same_style(a: str, b: str) -> bool:
    """Whether two resolved styles are the same, numbers within 1e-5 (both are rounded to 7 digits)."""
    da, db = (dict(p.split(":", 1) for p in s.split(";") if p) for s in (a, b))
    if da.keys() != db.keys():
        return False
    for key, va in da.items():
        vb = db[key]
        try:
            if not np.isclose(float(va), float(vb), rtol=1e-5):
                return False
        except ValueError:
            if va != vb:
                return False
    return True


# ---------------------------------------------------------------------------
# Rendering: the project's renderer and an independent one


def inked_difference(drawing, svg: str, side: int = 1200) -> float:
    """Relative difference of inked pixels (alpha >= 128): rsvg-convert vs the project's renderer."""
    import skia

    _, _, w, h = default_view(drawing)
    scale = side / max(w, h)
    width, height = max(1, round(w * scale)), max(1, round(h * scale))
    ours = render(drawing, width, height)[..., 3] >= 128
    png = subprocess.run(
        ["rsvg-convert", "-w", str(width), "-h", str(height)],
        input=svg.encode("utf-8"),
        capture_output=True,
        check=True,
        timeout=300,
    ).stdout
    theirs = skia.Image.MakeFromEncoded(skia.Data.MakeWithCopy(png)).toarray()[..., 3] >= 128
    return abs(int(theirs.sum()) - int(ours.sum())) / max(1, int(ours.sum()))


needs_rsvg = pytest.mark.skipif(
    shutil.which("rsvg-convert") is None, reason="needs rsvg-convert (librsvg2-bin)"
)


@needs_rsvg
@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_renders_the_same_in_rsvg(path) -> None:
    drawing = derive(parse_grammar(path.read_text(encoding="utf-8")))
    assert inked_difference(drawing, drawing_to_structured_svg(drawing)) <= 0.01


@needs_rsvg
def test_realworld_exports_are_small_and_render_the_same() -> None:
    from lsys_core.pipeline import infer

    files = sorted(need(REALWORLD).glob("*.svg"))
    assert files
    for path in files:
        data = path.read_bytes()
        drawing = derive(infer(parse_svg(data)).grammar)
        svg = drawing_to_structured_svg(drawing, head=read_head(data))
        check_document(svg)
        assert len(svg.encode("utf-8")) <= 1.5 * len(data), path.name
        assert inked_difference(drawing, svg) <= 0.01, path.name


# ---------------------------------------------------------------------------
# Elements, styles, paint order, head


def test_basic_shapes_stay_elements_and_dashed_ones_keep_their_path() -> None:
    g = parse_grammar(
        "lsys 2\n"
        'terminal C "M2 0 C2 1.1 1.1 2 0 2 C-1.1 2 -2 1.1 -2 0 C-2 -1.1 -1.1 -2 0 -2 C1.1 -2 2 -1.1 2 0 Z"'
        ' style "fill:#c00"\n'
        'terminal R "M0 0 H4 V2 H0 Z" style "fill:none;stroke:#000;stroke-dasharray:1 1"\n'
        'terminal L "M0 0 L5 0" style "stroke:#00f"\n'
        "axiom: P(3) [ f(20) R ] L\n"
        "P(m): m > 0 -> C f(6) P(m-1)\n"
        "P(m): m == 0 -> C\n"
    )
    root = parse(drawing_to_structured_svg(derive(g)))
    defs = {el.get("id"): local(el) for d in root.iter(f"{{{SVG_NS}}}defs") for el in d}
    assert defs["L"] == "line"
    assert defs["R"] == "path"  # a dash pattern starts at the path's first point: kept as drawn
    # four cubics within 1e-3 of a circle (the usual 0.5523 control distance is 0.55 here)
    assert defs["C"] == "circle"


def test_styles_shared_by_a_shape_go_on_its_definition() -> None:
    g = parse_grammar(
        "lsys 2\n"
        'terminal A "M0 0 L4 0 L2 3 Z" style "fill:#0a0;stroke:#000;stroke-width:0.5"\n'
        "axiom: P(4)\n"
        "P(m): m > 0 -> A{opacity: 0.2*m} f(5) *(1.5) P(m-1)\n"
        "P(m): m == 0 -> A\n"
    )
    drawing = derive(g)
    root = parse(drawing_to_structured_svg(drawing))
    (shape,) = [el for d in root.iter(f"{{{SVG_NS}}}defs") for el in d]
    assert "fill:#0a0" in shape.get("style") and "stroke-width" not in shape.get("style")
    uses = list(root.iter(f"{{{SVG_NS}}}use"))
    widths = [float(u.get("style").split("stroke-width:")[1].split(";")[0]) for u in uses]
    scales = np.abs(drawing.a)
    assert np.allclose(np.asarray(widths) * scales, 0.5, rtol=1e-5)  # canvas units, whatever the scale
    assert sum("opacity" in (u.get("style") or "") for u in uses) == 4  # the last one is opaque


def test_interleaved_paint_order_splits_groups_and_keeps_ids_unique() -> None:
    g = parse_grammar(
        "lsys 2\n"
        'terminal A "M0 0 L1 0 L1 1 Z" style "fill:#f00"\n'
        'terminal B "M0 0 L1 1 L0 1 Z" style "fill:#00f"\n'
        "axiom: P(3) [ f(5) Q(3) ]\n"
        "P(m): m > 0 -> A{z: 2*m} f(2) P(m-1)\n"
        "P(m): m == 0 -> A\n"
        "Q(m): m > 0 -> B{z: 1 + 2*m} f(2) Q(m-1)\n"
        "Q(m): m == 0 -> B{z: 1}\n"
    )
    drawing = derive(g)
    svg = drawing_to_structured_svg(drawing)
    found = check_document(svg)
    assert {rule for rule, _, _ in found} == {"P", "Q"} and len(found) > 2
    order = [u.get(f"{{{XLINK_NS}}}href") for u in parse(svg).iter(f"{{{SVG_NS}}}use")]
    symbols = [drawing.terminals[s].name for s in drawing.symbol.tolist()]
    assert order == [f"#{s}" for s in symbols]  # the paint order is the drawing's


def test_a_hand_made_drawing_has_no_groups() -> None:
    from lsys_core.grammar.model import Terminal

    drawing = make_drawing([Terminal("A", "M0 0 L1 0 L0 1 Z", "fill:#000")], [0, 0], [1, 2j], [0, 3])
    svg = drawing_to_structured_svg(drawing)
    assert check_document(svg) == []
    assert len(list(parse(svg).iter(f"{{{SVG_NS}}}use"))) == 2


def test_title_desc_and_root_attributes_are_kept(tmp_path) -> None:
    source = (
        b'<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"'
        b' id="art" xml:lang="en" inkscape:version="1.3" data-author="me" opacity="0.5"'
        b' width="4cm" height="2cm" viewBox="0 0 40 20">'
        b"<title>Six &amp; tiles</title><desc>A row</desc>"
        + b"".join(b'<rect x="%d" y="5" width="4" height="4" fill="#c60"/>' % (6 * i + 2) for i in range(6))
        + b"</svg>"
    )
    src = tmp_path / "in.svg"
    src.write_bytes(source)
    out = tmp_path / "out.svg"
    p = subprocess.run(
        [
            sys.executable,
            "-m",
            "lsys_core.cli",
            "infer",
            str(src),
            "-o",
            str(tmp_path / "r.lsys"),
            "--svg",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
    )
    assert p.returncode == 0, p.stderr
    root = parse(out.read_text(encoding="utf-8"))
    assert root.get("id") == "art" and root.get("{http://www.w3.org/XML/1998/namespace}lang") == "en"
    assert root.get("{http://www.inkscape.org/namespaces/inkscape}version") == "1.3"
    assert root.get("data-author") == "me" and root.get("opacity") is None  # applied to the shapes already
    assert (root.get("width"), root.get("height"), root.get("viewBox")) == ("4cm", "2cm", "0 0 40 20")
    assert (
        root.findtext(f"{{{SVG_NS}}}title") == "Six & tiles" and root.findtext(f"{{{SVG_NS}}}desc") == "A row"
    )
    assert check_document(out.read_text(encoding="utf-8"))


def test_flat_option_writes_baked_paths(tmp_path) -> None:
    rules = ROOT / "tests" / "data" / "helix_truth.lsys"
    cmd = [sys.executable, "-m", "lsys_core.cli", "derive", str(rules), "-o", "-"]
    structured = subprocess.run(cmd, capture_output=True, text=True, timeout=300, cwd=ROOT).stdout
    flat = subprocess.run([*cmd, "--flat"], capture_output=True, text=True, timeout=300, cwd=ROOT).stdout
    assert structured.count("<use") == 120 and "<use" not in flat and flat.count("<path") == 120
    assert len(structured) < len(flat)


def test_defs_verbatim_and_url_styles_are_carried_through() -> None:
    g = parse_grammar(
        "lsys 2\n"
        'defs "<linearGradient id=\\"g\\"><stop offset=\\"0\\" stop-color=\\"#f00\\"/></linearGradient>"\n'
        'verbatim 2 "<text x=\\"10\\" y=\\"80\\">Hello</text>"\n'
        'terminal S "M0 0 H20 V20 H0 Z" style "fill:url(#g)"\n'
        'terminal C "M4 0 A4 4 0 0 1 -4 0 A4 4 0 0 1 4 0 Z" style "fill:#080"\n'
        "axiom: [ P(2) ] f(60) Q(5)\n"
        "P(m): m > 0 -> S f(25) P(m-1)\n"
        "P(m): m == 0 -> S\n"
        "Q(m): m > 0 -> C f(12) Q(m-1)\n"
        "Q(m): m == 0 -> C\n"
    )
    svg = drawing_to_structured_svg(derive(g))
    check_document(svg)
    root = parse(svg)
    assert root.find(f".//{{{SVG_NS}}}defs/{{{SVG_NS}}}linearGradient").get("id") == "g"
    body = svg.split("</defs>")[1]
    # the text keeps its place: after the first two squares, before the third
    assert body.index("Hello") > body.index("url(#g)", body.index("url(#g)") + 1)
    assert body.index("Hello") < body.rindex("url(#g)")
    # gradient-painted instances are baked in canvas coordinates; the circles are <use> of one <circle>
    assert body.count("url(#g)") == 3
    assert len(list(root.iter(f"{{{SVG_NS}}}use"))) == 6
    assert [local(el) for el in root.find(f"{{{SVG_NS}}}defs") if el.get("id") != "g"] == ["circle"]


def test_a_drawing_whose_every_instance_is_baked() -> None:
    g = parse_grammar(
        "lsys 2\n"
        'defs "<clipPath id=\\"c\\"><rect width=\\"30\\" height=\\"10\\"/></clipPath>"\n'
        'terminal S "M0 0 H20 V20 H0 Z" style "fill:#00f;clip-path:url(#c)"\n'
        "axiom: S f(25) S\n"
    )
    svg = drawing_to_structured_svg(derive(g))
    check_document(svg)
    body = svg.split("</defs>")[1]
    assert body.count("clip-path:url(#c)") == 2 and "<use" not in body


@pytest.mark.skipif(shutil.which("inkscape") is None, reason="needs Inkscape")
def test_inkscape_sees_the_groups_and_the_clones(tmp_path) -> None:
    g = parse_grammar((ROOT / "resources" / "examples" / "facade.lsys").read_text(encoding="utf-8"))
    drawing = derive(g)
    out = tmp_path / "facade.svg"
    out.write_text(drawing_to_structured_svg(drawing), encoding="utf-8")
    p = subprocess.run(["inkscape", "--query-all", str(out)], capture_output=True, text=True, timeout=300)
    ids = [line.split(",")[0] for line in p.stdout.splitlines()]
    found = check_document(out.read_text(encoding="utf-8"))
    assert sum(i.startswith(("P1-", "P2-", "X1-", "Z-")) for i in ids) == len(found)  # every group
    assert sum(i.startswith("use") for i in ids) == len(drawing)  # every clone, with its bounding box


def test_a_turned_circle_or_rectangle_is_defined_as_a_path() -> None:
    """Readers that turn a ``<use>`` of a ``<rect>`` into points may drop its rotation: paths are safe."""
    g = parse_grammar(
        "lsys 2\n"
        'terminal C "M2 0 C2 1.1 1.1 2 0 2 C-1.1 2 -2 1.1 -2 0 C-2 -1.1 -1.1 -2 0 -2 C1.1 -2 2 -1.1 2 0 Z"'
        ' style "fill:#c00"\n'
        'terminal R "M0 0 H4 V2 H0 Z" style "fill:#0a0"\n'
        "axiom: P(3) [ f(30) Q(5) ]\n"
        "P(m): m > 0 -> C f(6) P(m-1)\n"
        "P(m): m == 0 -> C\n"
        "Q(m): m > 0 -> R +(30) f(6) Q(m-1)\n"
        "Q(m): m == 0 -> R\n"
    )
    drawing = derive(g)
    root = parse(drawing_to_structured_svg(drawing))
    defs = {el.get("id"): local(el) for d in root.iter(f"{{{SVG_NS}}}defs") for el in d}
    assert defs["C"] == "circle"  # only moved: stays a circle
    assert defs["R"] == "path"  # turned by 30° a step
    assert_scenes_close(parse_svg(drawing_to_structured_svg(drawing)), drawing_scene(drawing))
