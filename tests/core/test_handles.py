"""Handles of a repetition: where they are, and what dragging them does to the drawing."""

from __future__ import annotations

import cmath
import math
from pathlib import Path

import numpy as np
import pytest

from lsys_core.derive.derivation import derive
from lsys_core.derive.handles import drag_values, find_handles
from lsys_core.grammar import parse_grammar, set_params
from lsys_core.grammar.semantics import describe

EXAMPLES = Path(__file__).resolve().parents[2] / "resources" / "examples"
HELIX = (
    'lsys 1\nterminal A "M 0 0 L 8 0 L 8 3 Z"\naxiom: +(20) f(300) +(-20) P(40)\n'
    "P(m): m > 0 -> A +(-80) f(-24) *(0.99) +(91) P(m-1)\nP(m): m == 0 -> A\n"
)


def drag(g, h, which, point):
    controls = {c.label: c for c in next(c for c in describe(g) if c.owner == h.rule).controls}
    values = {}
    for label, v in drag_values(h, which, point).items():
        values.update(controls[label].values(v))
    return set_params(g, values)


def test_handles_sit_on_the_next_repetition():
    g = parse_grammar(HELIX)
    d = derive(g)
    h = find_handles(g, d, 5, knob=10.0)
    assert h.rule == "P" and h.b0 == pytest.approx(d.b[5]) and h.b1 == pytest.approx(d.b[6])
    pts = h.points()
    assert set(pts) == {"move", "turn", "scale"}
    assert abs(pts["turn"] - h.b1) == pytest.approx(10.0)
    last = find_handles(g, d, len(d) - 1, knob=10.0)  # the end of the chain steps back
    assert last.b1 == pytest.approx(d.b[-1]) and last.b0 == pytest.approx(d.b[-2])


def test_dragging_the_next_repetition_moves_it_there_and_keeps_the_turn():
    g = parse_grammar(HELIX)
    d = derive(g)
    h = find_handles(g, d, 0, knob=10.0)
    target = h.b1 + (3 - 4j)
    g2 = drag(g, h, "move", target)
    d2 = derive(g2)
    assert d2.b[1] == pytest.approx(target)
    np.testing.assert_allclose(d2.a[1] / d2.a[0], d.a[1] / d.a[0])  # same turn and scale per step


def test_dragging_the_turn_knob_turns_the_next_repetition_towards_it():
    g = parse_grammar(HELIX)
    d = derive(g)
    h = find_handles(g, d, 0, knob=10.0)
    point = h.b1 + 10 * cmath.exp(1j * (cmath.phase(h.a1) + math.radians(25)))
    d2 = derive(drag(g, h, "turn", point))
    assert math.degrees(cmath.phase(d2.a[1] / d2.a[0])) == pytest.approx(
        math.degrees(cmath.phase(d.a[1] / d.a[0])) + 25
    )
    assert d2.b[1] == pytest.approx(d.b[1])  # the next repetition stays where it was


def test_dragging_the_scale_knob_sets_the_scale_per_step():
    g = parse_grammar(HELIX)
    d = derive(g)
    h = find_handles(g, d, 0, knob=10.0)
    d2 = derive(drag(g, h, "scale", h.b1 + 12.5j))
    assert abs(d2.a[1] / d2.a[0]) == pytest.approx(1.25)


def test_a_ring_has_a_centre_and_its_radius_handle_resizes_it():
    g = parse_grammar((EXAMPLES / "flower-ring.lsys").read_text(encoding="utf-8"))
    d = derive(g)
    petal = int(np.flatnonzero(d.rule == [r.name for r in g.rules].index("P1"))[3])
    h = find_handles(g, d, petal, knob=5.0)
    assert h.rule == "P1" and h.center is not None
    petals = d.b[d.rule == d.rule[petal]]
    radius = abs(h.b0 - h.center)
    ring = petals[np.abs(petals - h.center) < 1.5 * radius]
    assert ring.size == 8 and np.abs(ring - h.center).std() < 1e-6  # the 8 petals around the centre
    d2 = derive(drag(g, h, "radius", h.center + 2 * (h.b0 - h.center)))
    petals2 = d2.b[d2.rule == d2.rule[petal]]
    ring2 = petals2[np.abs(petals2 - h.center) < 3 * radius]
    assert ring2.size == 8 and np.abs(ring2 - ring2.mean()) == pytest.approx(np.full(8, 2 * radius), rel=1e-6)


def test_a_window_of_a_facade_is_repeated_by_its_row_and_groups_have_no_handles():
    g = parse_grammar((EXAMPLES / "facade.lsys").read_text(encoding="utf-8"))
    d = derive(g)
    names = [t.name for t in g.terminals]
    window = int(np.flatnonzero(d.symbol == names.index("C"))[2])
    h = find_handles(g, d, window, knob=5.0)
    assert h.rule == "P1" and abs(h.b1 - h.b0) == pytest.approx(60)
    door = int(np.flatnonzero(d.symbol == names.index("B"))[0])
    assert find_handles(g, d, door, knob=5.0) is None


def test_drag_writes_the_simplest_value_half_a_pixel_can_tell():
    g = parse_grammar(HELIX)
    h = find_handles(g, derive(g), 5, knob=10.0)
    nudge = (h.b1 - h.b0) * 1.0003  # the next repetition dragged a hair past where it was
    raw = drag_values(h, "move", h.b0 + nudge)
    snapped = drag_values(h, "move", h.b0 + nudge, pixel=1.0)
    assert raw["step distance"] != pytest.approx(24.0, abs=1e-6)  # the raw drag carries the noise
    assert snapped["step distance"] == 24.0
    fine = drag_values(h, "move", h.b0 + nudge, pixel=1e-6)  # zoomed far in: every digit counts
    assert fine["step distance"] == pytest.approx(raw["step distance"], abs=1e-6)
