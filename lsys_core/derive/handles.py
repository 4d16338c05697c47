"""Handles on the canvas, as in Illustrator's Repeat: the geometry of a selected repetition.

Select an instance: :func:`find_handles` finds the sequence rule that repeats it (its own rule,
or a sequence that places the group it belongs to) and the step from this repetition to the
next one, in drawing coordinates.  The handles are points a user drags:

``move``
    the next repetition's position: step distance and direction;
``turn``
    a knob on the next repetition's heading: turn per step;
``scale``
    a knob beside the next repetition, as far from it as its scale: scale per step;
``radius``
    (rings) the selected instance, dragged away from or towards the ring's centre.

:func:`drag_values` turns a dragged point into new values of the rule's semantic controls
(:mod:`lsys_core.grammar.semantics`), which write the grammar.  No Qt here.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

import numpy as np

from lsys_core.derive.model import Drawing
from lsys_core.grammar.model import Grammar, Symbol, Turtle
from lsys_core.grammar.semantics import Card, describe
from lsys_core.grammar.snap import snap

__all__ = ["Handles", "drag_values", "find_handles"]

_MATCH = 1e-6  # relative distance under which a predicted position is an instance's


@dataclass(frozen=True)
class Handles:
    """The handles of one repetition.

    Attributes
    ----------
    rule : str
        The sequence rule whose step the handles edit.
    summary : str
        Its kind in words.
    a0, b0 : complex
        Frame of the repetition the step starts from (``z → a0·z + b0``).
    a1, b1 : complex
        Frame of the next repetition.
    knob : float
        Length of the turn and scale knobs in drawing units.
    center : complex or None
        Centre of a ring (None for other sequences).
    controls : tuple of str
        Labels of the rule's controls the handles can set.
    """

    rule: str
    summary: str
    a0: complex
    b0: complex
    a1: complex
    b1: complex
    knob: float
    center: complex | None
    controls: tuple[str, ...]

    @property
    def step_scale(self) -> float:
        """Scale per step."""
        return abs(self.a1) / abs(self.a0) if self.a0 else 1.0

    def points(self) -> dict[str, complex]:
        """Return every handle's position in drawing coordinates (only the usable ones)."""
        heading = self.a1 / abs(self.a1) if self.a1 else 1.0
        out: dict[str, complex] = {}
        if "step distance" in self.controls:
            out["move"] = self.b1
        if "step turn" in self.controls or "step direction" in self.controls:
            out["turn"] = self.b1 + heading * self.knob
        if "step scale" in self.controls:
            out["scale"] = self.b1 - 1j * heading * self.knob * self.step_scale
        if self.center is not None and "step distance" in self.controls:
            out["radius"] = self.b0
        return out


def _step(g: Grammar, card: Card) -> tuple[complex, complex] | None:
    """Return the step transform ``(a, b)`` of a sequence rule (None when it changes with m)."""
    rule = g.rule(card.owner)
    if rule is None or not rule.cases:
        return None
    body = rule.cases[0].body
    if not body or not (isinstance(body[-1], Symbol) and body[-1].name == rule.name):
        return None
    run = []
    for mod in reversed(body[:-1]):  # the run of turtle moves just before the tail call
        if not isinstance(mod, Turtle):
            break
        if mod.op in ("z", "~"):
            continue  # paint order and stretch do not move the turtle
        if mod.value.cd or mod.value.table:
            return None
        run.append(mod)
    a, b = 1 + 0j, 0j
    for mod in reversed(run):
        v = float(mod.value.c0)
        if mod.op == "f":
            b += a * v
        elif mod.op == "*":
            a *= v
        else:
            a *= cmath.exp(1j * math.radians(v if mod.op == "+" else -v))
    return a, b


def find_handles(g: Grammar, drawing: Drawing, index: int, knob: float) -> Handles | None:
    """Return the handles of the repetition instance ``index`` belongs to (None: not a repetition).

    Parameters
    ----------
    g : Grammar
        The grammar ``drawing`` was derived from (without randomization).
    drawing : Drawing
    index : int
        The selected instance.
    knob : float
        Length of the turn and scale knobs, in drawing units.
    """
    if not 0 <= index < len(drawing):
        return None
    rule_idx = int(drawing.rule[index])
    if rule_idx < 0:
        return None
    cards = {c.owner: c for c in describe(g)}
    own = g.rules[rule_idx].name
    candidates = [own] if cards[own].kind not in ("group", "branching") else []
    candidates += [
        c.owner for c in cards.values() if own in c.calls and c.kind not in ("group", "branching", "start")
    ]
    rules = np.asarray(drawing.rule)
    symbols = drawing.base_symbol()  # stretched instances are their terminal's
    same = np.flatnonzero((rules == rule_idx) & (symbols == symbols[index]))
    positions = np.asarray(drawing.b)[same]
    size = float(np.ptp(positions.real) + np.ptp(positions.imag)) if positions.size else 0.0
    tol = _MATCH * max(size, 1.0)
    b_i = complex(drawing.b[index])
    anchor = _anchor(g, drawing, index, own)
    if anchor is None:
        return None
    a_c, b_c = anchor  # the frame the group was placed with (the sequence's frame)
    for name in candidates:
        step = _step(g, cards[name])
        if step is None:
            continue
        a_s, b_s = step
        nxt_a, nxt_b = a_c * a_s, a_c * b_s + b_c
        prv_a = a_c / a_s if a_s else None
        # the same shape one step further (or back, at the end of a chain) is an instance too
        offset_b = (b_i - b_c) / a_c  # where the instance sits in the frame
        ahead = nxt_a * offset_b + nxt_b
        if positions.size and np.abs(positions - ahead).min() <= tol:
            base = (a_c, b_c)
        elif prv_a is not None and positions.size:
            prv_b = b_c - prv_a * b_s
            behind = prv_a * offset_b + prv_b
            if np.abs(positions - behind).min() > tol:
                continue
            base = (prv_a, prv_b)
        else:
            continue
        a0, b0 = base
        a1, b1 = a0 * a_s, a0 * b_s + b0
        card = cards[name]
        center = None
        if card.kind == "ring" and abs(1 - a_s) > 1e-12:
            center = a0 * (b_s / (1 - a_s)) + b0
        labels = tuple(c.label for c in card.controls)
        return Handles(name, card.summary, a0, b0, a1, b1, knob, center, labels)
    return None


def _anchor(g: Grammar, drawing: Drawing, index: int, own: str) -> tuple[complex, complex] | None:
    """Return the frame the rule application that drew instance ``index`` started from.

    For a rule whose body starts by drawing a terminal, that terminal's instance of the same
    application has the application's frame: the k-th instance of that terminal by the rule,
    where ``index`` is the k-th of its own terminal.
    """
    rule = g.rule(own)
    if rule is None or not rule.cases or not rule.cases[0].body:
        return None
    first = rule.cases[0].body[0]
    names = [t.name for t in drawing.terminals]
    if not isinstance(first, Symbol) or first.name not in names:
        return None
    rules, symbols = np.asarray(drawing.rule), drawing.base_symbol()
    mine = np.flatnonzero((rules == drawing.rule[index]) & (symbols == symbols[index]))
    k = int(np.searchsorted(mine, index))
    firsts = np.flatnonzero((rules == drawing.rule[index]) & (symbols == names.index(first.name)))
    if k >= firsts.size:
        return None
    j = int(firsts[k])
    return complex(drawing.a[j]), complex(drawing.b[j])


def drag_values(h: Handles, which: str, point: complex, pixel: float = 0.0) -> dict[str, float]:
    """Return new values of the rule's controls (by label) for handle ``which`` dragged to ``point``.

    ``move`` sets step distance (and direction when the rule has one), ``turn`` the turn per
    step (or the direction when the rule turns only before its move), ``scale`` the scale per
    step, ``radius`` the step distance that gives a ring of the new radius.

    ``pixel`` is the size of one screen pixel in drawing units: each value is snapped to the
    simplest number that moves the dragged point by less than half a pixel
    (:func:`lsys_core.grammar.snap.snap`), so a drag writes ``46``, not ``45.9731``.
    """
    out = _raw_drag_values(h, which, point)
    if pixel > 0.0:
        out = {k: _snap_drag(k, v, h, which, point, pixel) for k, v in out.items()}
    return {k: v for k, v in out.items() if k in h.controls}


def _snap_drag(label: str, value: float, h: Handles, which: str, point: complex, pixel: float) -> float:
    """``value`` snapped within what half a screen pixel at the dragged point can tell."""
    half = 0.5 * pixel
    if label.endswith("scale"):
        return snap(value, half / max(abs(point - h.b1), 1e-12), "scale")
    if label.endswith(("direction", "turn")):
        arm = abs(point - (h.b0 if which == "move" else h.b1))
        return snap(value, math.degrees(half / max(arm, 1e-12)), "angle")
    return snap(value, half / max(abs(h.a0), 1e-12), "distance")


def _raw_drag_values(h: Handles, which: str, point: complex) -> dict[str, float]:
    """The exact control values a drag of handle ``which`` to ``point`` asks for."""
    out: dict[str, float] = {}
    if which == "move":
        local = (point - h.b0) / h.a0
        out["step distance"] = abs(local)
        if "step direction" in h.controls:
            out["step direction"] = math.degrees(cmath.phase(local))
    elif which == "turn":
        heading = cmath.phase(point - h.b1) - cmath.phase(h.a0)
        label = "step turn" if "step turn" in h.controls else "step direction"
        out[label] = math.degrees(math.remainder(heading, 2 * math.pi))
    elif which == "scale":
        out["step scale"] = max(abs(point - h.b1) / h.knob, 0.01) if h.knob else 1.0
    elif which == "radius" and h.center is not None:
        old = abs(h.b0 - h.center)
        if old > 0:
            out["step distance"] = abs(h.b1 - h.b0) / abs(h.a0) * abs(point - h.center) / old
    return out
