"""Stretched copies: the ``~(t)`` command (format version 4), its derivation and its inference."""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.derive.derivation import derive
from lsys_core.errors import GrammarSyntaxError
from lsys_core.geometry.stretch import stretch_cubics
from lsys_core.grammar import format_grammar, list_params, parse_grammar
from lsys_core.grammar.model import Grammar, Linear, Turtle
from lsys_core.grammar.semantics import describe
from lsys_core.instancing.deviation import pose_deviations
from lsys_core.pipeline import analyse, infer
from lsys_core.render.svg import export_svg
from lsys_core.svg.model import Element, Scene
from lsys_core.svg.parse import parse_svg
from lsys_core.testing import assert_scenes_close, drawing_scene
from tests.core.test_tabulated import CIRCLE

BARS = """lsys 4
terminal A "M -8 -16 L 8 -16 L 8 16 L -8 16 Z" style "fill:#000"
axiom: f(100) P(3)
P(m): m > 0 -> A ~(16) +(-90) f(8) +(90) f(22.7) P(m-1)
P(m): m == 0 -> A
Q(m) -> [ ~([4, 0.5, 30]) A ] f(20) Q(m-1)
R(m): m > 0 -> [ ~(10 + 2*m) A ] R(m-1)
"""


def _rounded(x: float, y: float, w: float, h: float, r: float) -> Element:
    """A rounded rectangle as the SVG reader makes it (path data with arcs)."""
    svg = (
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 400 400">'
        f'<rect x="{x}" y="{y}" width="{w}" height="{h}" rx="{r}" fill="#123"/></svg>'
    )
    return parse_svg(svg).elements[0]


def _stretches(g: Grammar) -> list[Linear]:
    return [
        m.value for r in g.rules for c in r.cases for m in c.body if isinstance(m, Turtle) and m.op == "~"
    ]


# -- grammar ------------------------------------------------------------------------------------


def test_stretch_values_are_read_and_written_back_in_version_4() -> None:
    g = parse_grammar(BARS)
    assert format_grammar(g) == BARS
    assert {(v.c0, v.cd, v.table) for v in _stretches(g)} == {
        (16.0, 0.0, ()),
        (4.0, 0.0, (4.0, 0.5, 30.0)),
        (10.0, 2.0, ()),
    }
    plain = BARS.split("P(m): m > 0")[0].replace("lsys 4", "lsys 3") + "P(m) -> A f(2) P(m-1)\n"
    assert format_grammar(parse_grammar(plain)).startswith("lsys 2\n")  # no stretch: an older version


@pytest.mark.parametrize(
    ("text", "where", "words"),
    [
        (BARS.replace("lsys 4", "lsys 3"), (4, 18), "needs format version 4"),
        (BARS.replace("f(100) P(3)", "f(100) ~(m) P(3)"), (3, 17), "m cannot be used in the axiom"),
        (BARS.replace("~(16)", "~ 16"), (4, 20), "expected '(' after '~'"),
        (BARS.replace("R(m-1)", "~(16"), (7, 38), "expected ')'"),
        (BARS.replace("~(16)", "~([])"), (4, 21), "expected a number"),
    ],
)
def test_bad_stretch_commands_are_reported_at_their_place(text, where, words) -> None:
    with pytest.raises(GrammarSyntaxError) as err:
        parse_grammar(text)
    assert (err.value.line, err.value.column) == where
    assert words in str(err.value)


def test_a_stretch_is_a_parameter_and_a_sequence_shows_its_stretch_per_step() -> None:
    g = parse_grammar(BARS)
    labels = [p.label for p in list_params(g)]
    assert "P (m > 0): stretch #1" in labels
    card = next(c for c in describe(g) if c.owner == "P")
    assert any(ctl.label == "stretch per step" and ctl.value == 16 for ctl in card.controls)


# -- derivation, rendering ----------------------------------------------------------------------


def test_derivation_stretches_a_rounded_rectangle_into_the_taller_one_exactly() -> None:
    short = _rounded(-6, -16, 12, 32, 2)  # centred on the origin, its local frame
    tall = _rounded(94, -40, 12, 80, 2)  # the same bar, 48 taller, at x = 100
    from lsys_core.geometry.paths import d_from_cubics

    d = d_from_cubics(short.cubics, short.subpaths, short.closed)
    g = parse_grammar(f'lsys 4\nterminal A "{d}"\naxiom: f(100) ~(48) A\n')
    drawing = derive(g)
    assert drawing.stretch is not None and drawing.stretch.tolist() == [48.0]
    term = drawing.terminals[int(drawing.symbol[0])]
    assert term.name == "A~1"
    from lsys_core.geometry.shapes import shape_arrays

    shape = Element(*shape_arrays(term.path))
    dev = pose_deviations([tall], [shape], np.zeros(1, int), drawing.a, drawing.b)
    assert dev[0] < 1e-6
    # the corners keep their radius: a scale would have made them 2.5 times taller
    assert np.allclose(stretch_cubics(short.cubics, 48)[:, 0].imag.max(), 40)


@pytest.mark.parametrize("flat", [False, True])
def test_stretched_instances_are_exported_with_their_own_shape(tmp_path, flat) -> None:
    drawing = derive(parse_grammar(BARS.split("Q(m)")[0]))
    export_svg(drawing, tmp_path / "out.svg", flat=flat)
    back = parse_svg((tmp_path / "out.svg").read_text())
    heights = [round(float(np.ptp(e.cubics.imag)), 6) for e in back.elements]
    assert heights == [32.0, 48.0, 64.0, 80.0]
    bottoms = [round(float(e.cubics.imag.max()), 6) for e in back.elements]
    assert bottoms == [16.0] * 4  # each grows upwards from one baseline: centres rise by 8 per step
    assert_scenes_close(back, drawing_scene(drawing))


# -- inference ----------------------------------------------------------------------------------


def _bars(heights, *, step=24.0, width=14.0, radius=0.0, horizontal=False, base=300.0) -> Scene:
    out = []
    for i, h in enumerate(heights):
        x = 40 + i * step
        if horizontal:
            out.append(_rounded(40, x, h, width, radius) if radius else _rect(40, x, h, width))
        else:
            out.append(_rounded(x, base - h, width, h, radius) if radius else _rect(x, base - h, width, h))
    return Scene(tuple(out), (0.0, 0.0, 400.0, 400.0))


def _rect(x: float, y: float, w: float, h: float) -> Element:
    svg = (
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 400 400">'
        f'<path d="M{x},{y}h{w}v{h}h{-w}Z" fill="#4c78a8"/></svg>'
    )
    return parse_svg(svg).elements[0]


@pytest.mark.parametrize(
    ("radius", "horizontal"), [(0.0, False), (3.0, False), (0.0, True), (3.0, True)], ids=str
)
def test_a_bar_chart_of_random_heights_is_one_row_with_a_stretch_table(radius, horizontal) -> None:
    rng = np.random.default_rng(7)
    heights = np.round(rng.uniform(20, 220, 12), 1)
    s = _bars(heights, radius=radius, horizontal=horizontal)
    result = infer(s)
    g = result.grammar
    assert len(g.terminals) == 1  # one shape, drawn at twelve lengths
    tables = [v for v in _stretches(g) if v.table]
    assert len(tables) == 1 and len(tables[0].table) == 12
    assert result.explained == 1.0
    assert result.max_deviation <= result.tolerance
    assert_scenes_close(s, drawing_scene(derive(g)))


def test_growing_bars_have_a_linear_stretch() -> None:
    s = _bars([20 + 16 * i for i in range(8)], radius=2.0)
    g = infer(s).grammar
    stretches = _stretches(g)
    assert len(stretches) == 1 and not stretches[0].table and abs(abs(stretches[0].cd) - 16) < 1e-6
    assert len(g.terminals) == 1
    assert_scenes_close(s, drawing_scene(derive(g)))


def test_ellipses_of_different_aspect_are_not_stretched_copies() -> None:
    circle = CIRCLE
    elements = []
    for i, ry in enumerate([10, 16, 22, 28, 34]):
        c = circle.real * 10 + 1j * circle.imag * ry + complex(40 + 30 * i, 100)
        elements.append(Element(c, np.zeros(4, int), (True,), "fill:#000"))
    inst = analyse(Scene(tuple(elements), (0.0, 0.0, 300.0, 200.0))).instancing
    assert inst.stretch_base is None or np.all(inst.stretch_base < 0)


def test_stretches_cost_bits_in_a_rule_that_places_shapes_one_by_one() -> None:
    from lsys_core.hierarchy.describe import grammar_bits
    from lsys_core.hierarchy.mdl import Precision

    prec = Precision.of_box(0j, 400 + 400j, 1.0)
    head = 'lsys 4\nterminal A "M -8 -16 L 8 -16 L 8 16 L -8 16 Z"\naxiom: Z\n'
    plain = parse_grammar(head + "Z -> [ A ] [ f(30) A ] [ f(60) A ]\n")
    stretched = parse_grammar(head + "Z -> [ A ] [ f(30) ~(16.5) A ] [ f(60) ~(47.25) A ]\n")
    assert grammar_bits(stretched, prec) > grammar_bits(plain, prec) + 2 * prec.length_bits


def test_a_stretched_instance_of_a_sequence_gets_the_sequence_handles() -> None:
    from lsys_core.derive.handles import find_handles

    g = parse_grammar(BARS.split("Q(m)")[0])
    drawing = derive(g)
    plain, stretched = find_handles(g, drawing, 0, 10.0), find_handles(g, drawing, 2, 10.0)
    assert plain is not None and stretched is not None
    assert stretched.rule == plain.rule == "P"


def test_bars_closer_than_the_tolerance_are_still_one_row() -> None:
    from lsys_core.settings import InferenceSettings

    rng = np.random.default_rng(11)
    s = _bars(np.round(rng.uniform(3, 250, 30), 1), step=12.0, width=10.0)
    result = infer(s, InferenceSettings(deviation=15.0))  # a wide chart: 0.5 % of its diagonal
    assert result.log == ("P1: a row with offsets of 30 nodes (table)",)
    assert result.max_deviation <= 15.0
    assert_scenes_close(s, drawing_scene(derive(result.grammar)))


def test_keys_are_labelled_like_unique_rows():
    from lsys_core.instancing.stretch import _runs
    from lsys_core.sorting import row_groups

    rng = np.random.default_rng(5)
    for _ in range(50):
        key = rng.integers(-3, 3, size=(int(rng.integers(1, 40)), int(rng.integers(1, 5)))) * 10**12
        _, inv = np.unique(key, axis=0, return_inverse=True)
        labels = row_groups(list(key.T))[1]  # as the stretch families label their keys
        assert np.array_equal(labels, inv.ravel())
        runs = _runs(labels)
        assert [r.tolist() for r in runs] == [np.flatnonzero(labels == g).tolist() for g in np.unique(labels)]
