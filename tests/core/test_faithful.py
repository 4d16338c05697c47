"""Faithful output: paint order, strokes, per-instance styles, parameters, defs and verbatim content.

Pictures are compared by rendering the input's elements and the derived drawing with the
project's renderer (the paint of every pixel shows stacking order, colours and stroke widths).
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from lsys_core.derive.derivation import derive
from lsys_core.derive.model import Drawing
from lsys_core.geometry.paths import d_from_cubics
from lsys_core.grammar import format_grammar, parse_grammar
from lsys_core.grammar.model import Grammar, Terminal, Verbatim
from lsys_core.grammar.validate import NAME_RE, RESERVED
from lsys_core.hierarchy import build_hierarchy, simplify
from lsys_core.instancing.similarity import terminal_name
from lsys_core.pipeline import infer
from lsys_core.render.raster import render
from lsys_core.render.svg import drawing_to_svg
from lsys_core.svg.model import Element, Scene
from lsys_core.svg.parse import parse_svg

K = 0.5523  # cubic circle constant


def circle(center: complex, r: float) -> np.ndarray:
    """A closed circle of four cubics."""
    pts = [1, 1j, -1, -1j, 1]
    return np.array(
        [
            [center + r * p, center + r * (p + K * 1j * p), center + r * (q - K * 1j * q), center + r * q]
            for p, q in itertools.pairwise(pts)
        ]
    )


def square(center: complex, side: float, turn: float = 0.0) -> np.ndarray:
    corners = center + side / 2 * np.exp(1j * (np.pi / 4 + turn + np.arange(5) * np.pi / 2)) * np.sqrt(2)
    p, q = corners[:-1], corners[1:]
    return np.stack([p, p + (q - p) / 3, p + 2 * (q - p) / 3, q], axis=1)


def element(cubics: np.ndarray, style: str, order: int = -1) -> Element:
    return Element(cubics, np.zeros(len(cubics), int), (True,), style, "", order)


def input_drawing(scene: Scene, viewbox) -> Drawing:
    """The scene's elements as a drawing: one terminal per element at the identity pose, in document order."""
    els = sorted(enumerate(scene.elements), key=lambda p: p[1].order if p[1].order >= 0 else p[0])
    terms = tuple(
        Terminal(f"E{i}", d_from_cubics(e.cubics, e.subpaths, e.closed), e.style)
        for i, (_, e) in enumerate(els)
    )
    n = len(terms)
    return Drawing(
        terms,
        np.arange(n, dtype=np.int32),
        np.ones(n, complex),
        np.zeros(n, complex),
        np.full(n, -1, np.int32),
        viewbox,
        None,
    )


def round_trip(scene: Scene) -> tuple[Drawing, str]:
    """Infer, write the rules as text, read them back and derive."""
    text = format_grammar(infer(scene).grammar)
    return derive(parse_grammar(text)), text


def differing(a: np.ndarray, b: np.ndarray) -> float:
    """Share of inked pixels whose colour differs by more than 48 levels."""
    ink = (a[..., 3] > 0) | (b[..., 3] > 0)
    diff = np.abs(a.astype(int) - b.astype(int)).max(axis=2) > 48
    return float((diff & ink).sum()) / max(int(ink.sum()), 1)


def assert_same_picture(scene: Scene, out: Drawing, viewbox, limit: float = 0.01) -> None:
    ref = render(input_drawing(scene, viewbox), 200, 200, view=viewbox, background=(255, 255, 255, 255))
    got = render(out, 200, 200, view=viewbox, background=(255, 255, 255, 255))
    assert differing(ref, got) <= limit


def test_overlapping_shapes_keep_their_stacking_order() -> None:
    # Five overlapping discs in a row, drawn right to left in the document (each partly under
    # the next): the inferred sequence runs left to right, so its derivation order is reversed.
    colours = ["#d00", "#0a0", "#00d", "#aa0", "#0aa"]
    els = [
        element(circle(complex(20 + 12 * i, 50), 10), f"fill:{colours[i]};stroke:none", order=4 - i)
        for i in range(5)
    ]
    scene = Scene(tuple(els))
    out, _ = round_trip(scene)
    vb = (0, 20, 100, 60)
    assert_same_picture(scene, out, vb)
    # the front disc is the leftmost one: at its right edge the next disc is underneath
    pixels = render(out, 100, 60, view=vb)
    assert tuple(pixels[30, 27, :3]) == (0xDD, 0, 0)


def test_stroke_width_stays_as_drawn_on_a_shape_reused_at_three_scales() -> None:
    els = [
        element(circle(complex(x, 50), r), "fill:none;stroke:#000;stroke-width:2")
        for x, r in ((20, 5), (50, 10), (90, 20))
    ]
    scene = Scene(tuple(els))
    result = infer(scene)
    assert len(result.grammar.terminals) == 1
    out = derive(parse_grammar(format_grammar(result.grammar)))
    back = parse_svg(drawing_to_svg(out))
    widths = [float(dict(p.split(":") for p in e.style.split(";"))["stroke-width"]) for e in back.elements]
    assert widths == pytest.approx([2, 2, 2], rel=1e-5)
    assert_same_picture(scene, out, (0, 20, 120, 60))


def test_strokes_scaled_with_their_copies_need_one_style() -> None:
    # one shape drawn through scaling transforms: each copy's stroke is as much wider as it is larger
    svg = (
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 160 60">'
        + "".join(
            f'<path transform="translate({x} 30) scale({k})" d="M-4 -4 L4 -4 L0 5 Z" '
            'style="fill:none;stroke:#000;stroke-width:1"/>'
            for x, k in ((15, 1), (45, 2), (100, 4.5))
        )
        + "</svg>"
    )
    scene = parse_svg(svg)
    text = format_grammar(infer(scene).grammar)
    g = parse_grammar(text)
    assert len(g.terminals) == 1 and g.terminals[0].scaled
    assert not g.styles and not g.paint and "stroke-width:1" in g.terminals[0].style
    out = derive(g)
    back = parse_svg(drawing_to_svg(out))
    widths = sorted(
        float(dict(p.split(":") for p in e.style.split(";"))["stroke-width"]) for e in back.elements
    )
    assert widths == pytest.approx([1, 2, 4.5], rel=1e-3)
    assert_same_picture(scene, out, (0, 0, 160, 60))


def test_shapes_differing_only_in_style_are_one_terminal() -> None:
    styles = ["fill:#e41a1c", "fill:#377eb8;stroke:#000;stroke-width:1.5", "fill:#4daf4a;opacity:0.5"]
    els = [element(square(complex(15 + 20 * i, 30), 12), styles[(i * 7) % 3]) for i in range(9)]
    scene = Scene(tuple(els))
    out, text = round_trip(scene)
    assert text.count("\nterminal ") == 1
    back = parse_svg(drawing_to_svg(out))
    got = sorted((round(e.cubics[0, 0].real), e.style) for e in back.elements)
    want = sorted((round(e.cubics[0, 0].real), e.style) for e in els)
    assert [g[0] for g in got] == [w[0] for w in want]
    assert_same_picture(scene, out, (0, 0, 200, 60))


@pytest.mark.parametrize(
    ("count", "opacity"),
    [
        (12, lambda k: f"{1 - k / 12:.6g}"),  # twelve bars round a centre, each more transparent
        (7, lambda k: f"{(k + 1) / 7:.2f}"),  # seven bars in sevenths written .14 .29 … .86 1.00
    ],
)
def test_an_opacity_progression_is_one_rule_with_a_parameter(count, opacity) -> None:
    bars = []
    for k in range(count):
        turn = k * np.pi / 6
        centre = 50 + 50j + 30 * np.exp(1j * turn)
        bar = np.array([-8 - 2j, 8 - 2j, 8 + 2j, -8 + 2j, -8 - 2j])
        pts = centre + bar * np.exp(1j * turn)
        p, q = pts[:-1], pts[1:]
        cubics = np.stack([p, p + (q - p) / 3, p + 2 * (q - p) / 3, q], axis=1)
        bars.append(element(cubics, f"fill:#333;opacity:{opacity(k)}"))
    scene = Scene(tuple(bars))
    out, text = round_trip(scene)
    g = parse_grammar(text)
    assert g.production_count <= 2
    props = [
        p
        for r in g.rules
        for c in r.cases
        for mod in c.body
        if getattr(mod, "paint", None)
        for p in mod.paint.props
    ]
    assert any(k == "opacity" and v.cd != 0 for k, v in props)
    assert "paint:" not in text
    assert_same_picture(scene, out, (0, 0, 100, 100))


def test_colours_without_a_pattern_keep_one_terminal_and_a_paint_table() -> None:
    rng = np.random.default_rng(3)
    cols = [f"fill:#{int(v):06x}" for v in rng.integers(0, 0xFFFFFF, 40)]
    els = [element(square(complex(10 + 12 * (i % 8), 10 + 12 * (i // 8)), 10), cols[i]) for i in range(40)]
    scene = Scene(tuple(els))
    out, text = round_trip(scene)
    assert text.count("\nterminal ") == 1
    assert_same_picture(scene, out, (0, 0, 110, 70))


def test_defs_and_verbatim_content_are_carried_through() -> None:
    els = [
        element(square(complex(20 + 25 * i, 30), 20), "fill:url(#g);stroke:none", order=2 * i)
        for i in range(3)
    ]
    text_xml = '<text x="10" y="80" font-size="12">Hello %s</text>'
    scene = Scene(
        tuple(els),
        viewbox=(0, 0, 100, 100),
        defs='<linearGradient id="g"><stop offset="0" stop-color="#f00"/><stop offset="1" stop-color="#00f"/></linearGradient>',
        verbatim=(Verbatim(3, text_xml, "<text> 'Hello %s'"),),
    )
    g = parse_grammar(format_grammar(infer(scene).grammar))
    assert g.verbatim == (Verbatim(2, text_xml, "<text> 'Hello %s'"),)
    svg = drawing_to_svg(derive(g))
    assert '<linearGradient id="g">' in svg.split("</defs>")[0]
    body = svg.split("</defs>")[1]
    # the text is drawn after the first two squares and before the third
    assert body.index(text_xml) > body.index("<path", body.index("<path") + 1)
    assert body.index(text_xml) < body.rindex("<path")
    # instances painted with a gradient are written in canvas coordinates
    assert body.count("url(#g)") == 3 and "transform" not in body


def test_a_thousand_terminals_and_the_rules_over_them_never_share_a_name() -> None:
    """Names from the similarity stage, rules from the hierarchy, through the text and derivation.

    The whole inference on 1,000 distinct shapes is the slow test below; here the 1,000
    terminals enter at the hierarchy, which names the rules (its catch-all ``Z`` included).
    """
    n = 1000
    names = [terminal_name(i) for i in range(n)]
    assert len(set(names)) == n and "Z" in names
    assert all(NAME_RE.fullmatch(nm) and nm not in RESERVED for nm in names)
    terminals = tuple(Terminal(nm, f"M 0 0 L {1 + i / n:.4f} 0 L 0 1 Z") for i, nm in enumerate(names))
    rng = np.random.default_rng(3)
    # every shape once at a random pose, and shape Z again in a row of ten (a sequence rule)
    group = np.concatenate([np.arange(n), np.full(10, 25)])
    b = np.concatenate([rng.uniform(0, 600, n) + 1j * rng.uniform(0, 600, n), 700 + 3j * np.arange(10)])
    a = np.concatenate([np.exp(1j * rng.uniform(0, 2 * np.pi, n)), np.ones(10)])
    radius = np.full(group.size, 0.6)
    hier = build_hierarchy(names, np.full(n, 0.6), group, a, b, b, radius)
    text = format_grammar(simplify(Grammar(terminals, tuple(hier.rules), hier.axiom)))
    g = parse_grammar(text)
    assert not {t.name for t in g.terminals} & {r.name for r in g.rules}
    assert g.terminal("Z") is not None and g.rules  # a terminal Z, and rules named otherwise
    out = derive(g)
    assert len(out) == group.size
    drawn = np.array([g.terminals[i].name for i in out.symbol])
    for name in set(names):  # every shape where it was (positions are written to 7 digits)
        here, there = out.b[drawn == name], b[group == names.index(name)]
        assert here.size == there.size and np.abs(here[:, None] - there[None, :]).min(axis=1).max() < 1e-3


def test_more_distinct_shapes_than_letters_infer_to_rules_that_derive() -> None:
    """The whole inference past ``Z``: 30 distinct shapes give terminals ``A`` … ``AD``.

    (The same on 1,000 shapes costs minutes in the similarity stage; the names of 1,000
    terminals are checked from the hierarchy on, above.)
    """
    rng = np.random.default_rng(1)
    els = []
    for i in range(30):
        ang = np.sort(rng.uniform(0, 2 * np.pi, 5))
        pts = rng.uniform(3, 8, 5) * np.exp(1j * ang) + complex(30 * (i % 10), 30 * (i // 10))
        q = np.roll(pts, -1)
        els.append(
            element(np.stack([pts, pts + (q - pts) / 3, pts + 2 * (q - pts) / 3, q], axis=1), "fill:#000")
        )
    text = format_grammar(infer(Scene(tuple(els))).grammar)
    g = parse_grammar(text)
    assert len(g.terminals) > 26 and g.terminal("Z") is not None
    assert len(derive(g)) == 30
    assert not {t.name for t in g.terminals} & {r.name for r in g.rules}


def test_paint_order_moves_are_not_geometry_for_sliders_and_rule_cards() -> None:
    from lsys_core.grammar import list_params
    from lsys_core.grammar.semantics import describe

    text = (
        'lsys 2\nterminal A "M0 0 L1 0"\naxiom: P(5)\n'
        "P(m): m > 0 -> A{opacity: 0.1*m} z(1) +(30) f(10) z(m) P(m-1)\nP(m): m == 0 -> A\n"
    )
    g = parse_grammar(text)
    assert [(p.key, p.kind) for p in list_params(g)] == [
        ("axiom.0.0.m", "count"),
        ("P.0.2.v", "angle"),
        ("P.0.3.v", "distance"),
    ]
    card = next(c for c in describe(g) if c.owner == "P")
    assert card.kind == "arc" and card.count == 6
    assert {w.key for c in card.controls for w in c.writes} == {"axiom.0.0.m", "P.0.2.v", "P.0.3.v"}


def test_matching_without_the_optimiser_is_the_optimisers_matching() -> None:
    from scipy.optimize import linear_sum_assignment

    from lsys_core.derive.faithful import _assignment

    rng = np.random.default_rng(11)
    for n in (1, 2, 5, 40):
        for jitter in (0.0, 0.01, 0.6):  # clear matches, near ones, a muddle where the optimiser decides
            points = rng.uniform(0, 10, n) + 1j * rng.uniform(0, 10, n)
            moved = rng.permutation(points) + jitter * (rng.normal(size=n) + 1j * rng.normal(size=n))
            cost = np.abs(points[:, None] - moved[None, :])
            rows, cols = _assignment(cost, 10.0)
            want_rows, want_cols = linear_sum_assignment(cost)
            assert rows.tolist() == want_rows.tolist() and cols.tolist() == want_cols.tolist()
    tie = np.zeros((3, 3))  # every matching is optimal: the optimiser's choice is kept
    assert [c.tolist() for c in _assignment(tie, 1.0)] == [c.tolist() for c in linear_sum_assignment(tie)]


def test_matching_from_the_nearest_instances_is_the_whole_matrix_matching() -> None:
    from lsys_core.derive.faithful import _assignment, _clear_nearest

    rng = np.random.default_rng(5)
    shortcuts = 0
    for n in (20, 300):
        for jitter in (0.0, 0.001, 0.05, 2.0):  # exact, near, neighbours' turns close, a muddle
            points = rng.uniform(0, 100, n) + 1j * rng.uniform(0, 100, n)
            turns = np.exp(1j * rng.uniform(0, 6.3, n))
            if n == 300:
                points[:50] = points[50:100]  # stacked copies told apart by their turns only
            perm = rng.permutation(n)
            moved = points[perm] + jitter * (rng.normal(size=n) + 1j * rng.normal(size=n))
            moved_turns = turns[perm] * np.exp(1j * jitter * rng.normal(size=n))
            scale = float(np.ptp(np.concatenate([points.real, points.imag])))
            found = _clear_nearest(points, turns, moved, moved_turns, scale)
            if found is None:
                continue
            shortcuts += 1
            cost = np.abs(points[:, None] - moved[None, :]) + scale * 1e-3 * np.abs(
                turns[:, None] - moved_turns[None, :]
            )
            want = _assignment(cost, scale)
            assert [x.tolist() for x in found] == [x.tolist() for x in want]
    assert shortcuts >= 4  # the shortcut is taken where the match is clear


@pytest.mark.parametrize("case", ["jitter", "ties", "exact", "close", "few"])
def test_greedy_matching_takes_the_nearest_pairs_first(case: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The greedy matching of many instances: every pair of a point and one of its 8 nearest
    targets, in order of distance (ties in order of point, then neighbour rank), as the plain loop takes them.
    Points each nearest a different target (exact or close copies) are matched without the loop."""
    from scipy.spatial import cKDTree

    from lsys_core.derive import faithful
    from lsys_core.derive.faithful import _greedy

    pairs = []
    loop = faithful._greedy_pairs
    monkeypatch.setattr(faithful, "_greedy_pairs", lambda *a: pairs.append(1) or loop(*a))

    rng = np.random.default_rng(len(case))
    n = 5 if case == "few" else 3_000
    target = rng.uniform(0, 100, n) + 1j * rng.uniform(0, 100, n)
    if case == "ties":
        target = np.round(target / 10) * 10  # many points at one place: equal distances
    noise = {"exact": 0.0, "close": 1e-3}.get(case, 2.0)
    found = target[rng.permutation(n)] + rng.normal(0, noise, n) * (1 + 1j)
    ids = np.arange(n) + 7
    k = min(8, n)
    dist, near = cKDTree(np.column_stack([target.real, target.imag])).query(
        np.column_stack([found.real, found.imag]), k=k
    )
    want = np.full(n, -1)
    taken = np.zeros(n, bool)
    for flat in np.argsort(dist, axis=None, kind="stable").tolist():
        i, j = divmod(flat, k)
        if want[i] < 0 and not taken[near[i, j]]:
            want[i], taken[near[i, j]] = near[i, j], True
    want[want < 0] = np.flatnonzero(~taken)[: int((want < 0).sum())]
    assert np.array_equal(_greedy(target, found, ids), ids[want])
    assert bool(pairs) == (case in ("jitter", "ties")), pairs


def test_most_common_style_is_what_unique_counts_give() -> None:
    from lsys_core.derive.faithful import _most_common

    rng = np.random.default_rng(9)
    pool = ["fill:red", "fill:blue", "stroke:#000", "", "fill:red;opacity:0.5", "é"]
    for n in (1, 2, 3, 7, 50):
        for _ in range(20):
            styles = [pool[i] for i in rng.integers(0, len(pool), n)]
            vals, counts = np.unique(np.array(styles, object).astype(str), return_counts=True)
            assert _most_common(styles) == str(vals[np.argmax(counts)])
