"""Runs of turtle commands in a rule body, and the controls (semantic parameters) they give.

A run ``[turns] [f] [scales] [turns]`` between two symbols places what follows it: its
:class:`Control` values are the step's distance and direction, the turn and the scale per
step, and how they change with the counter m; each control says which parameters it writes
(:class:`Write`).  :func:`sequence_words` names the figure a sequence's step draws (row, ring,
arc, spiral).  Read by :mod:`lsys_core.grammar.semantics`.
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Iterator
from dataclasses import dataclass

from lsys_core.grammar.model import Module, Turtle

__all__ = ["Control", "Op", "Write", "merge", "runs", "sequence_words", "signature", "step_controls"]

_FLAT_SCALE = 1e-3  # |scale - 1| below this: no growth or shrinking
_STRAIGHT = 0.5  # degrees of turn per step below which a sequence is straight


@dataclass(frozen=True)
class Write:
    """One parameter a control sets: ``key ← coef · value + offset``."""

    key: str
    coef: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class Control:
    """A semantic parameter of a rule.

    Attributes
    ----------
    name : str
        ``count``, ``levels``, ``distance``, ``direction``, ``turn``, ``scale`` or one of them
        with `` change`` (the change per step of a value linear in m).
    label : str
        Words for a user interface ("turn per step").
    value : float
        Current value (a count is the number of repetitions drawn, not the counter).
    kind : str
        The parameter kind of :mod:`lsys_core.grammar.params` (slider ranges, snapping).
    unit : str
        ``"°"`` for angles, ``"×"`` for scales, else ``""``.
    writes : tuple of Write
        Every parameter the control sets.
    """

    name: str
    label: str
    value: float
    kind: str
    unit: str
    writes: tuple[Write, ...]

    def values(self, value: float) -> dict[str, float]:
        """Return ``{key: new value}`` of every parameter this control writes for ``value``."""
        out = {}
        for w in self.writes:
            v = w.coef * value + w.offset
            out[w.key] = float(round(v)) if self.kind == "count" else v
        return out


# -- turtle runs ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class Op:
    """One turtle command of a rule body: its parameter key, operator and value ``c0 + cd·m``."""

    key: str  # the v key of this module
    op: str
    c0: float
    cd: float


def runs(owner: str, ci: int, body: tuple[Module, ...]) -> Iterator[tuple[int, list[Op]]]:
    """Yield ``(index after the run, ops)`` for every run of consecutive turtle commands."""
    run: list[Op] = []
    for i, mod in enumerate(body):
        if isinstance(mod, Turtle) and mod.op in ("z", "~"):
            continue  # paint order and stretch move no pose: the run goes on
        if isinstance(mod, Turtle) and not mod.value.table:  # a table value ends a run, as a symbol does
            run.append(Op(f"{owner}.{ci}.{i}.v", mod.op, float(mod.value.c0), float(mod.value.cd)))
            continue
        if run:
            yield i, run
        run = []
    if run:
        yield len(body), run


def _angle(op: Op) -> float:
    return op.c0 if op.op == "+" else -op.c0


def _sign(op: Op) -> float:
    return 1.0 if op.op == "+" else -1.0


def _net(run: list[Op]) -> complex | None:
    """Return the translation of a run (heading 0, scale 1 at its start), or None."""
    a, b = 1 + 0j, 0j
    for op in run:
        if op.op == "f":
            b += a * op.c0
        elif op.op == "*":
            a *= op.c0
        else:
            a *= cmath.exp(1j * math.radians(_angle(op)))
    return b


def step_controls(run: list[Op], prefix: str) -> list[Control]:
    """Controls of one run ``[turns] [f] [scales] [turns]`` (none for other shapes of run)."""
    moves = [i for i, op in enumerate(run) if op.op == "f"]
    if len(moves) > 1:
        return []
    at = moves[0] if moves else len(run)
    before = [op for op in run[:at] if op.op in "+-"]
    after = [op for op in run[at:] if op.op in "+-"]
    scales = [op for op in run if op.op == "*"]
    out: list[Control] = []
    flip = 0.0
    if moves:
        f = run[at]
        flip = 180.0 if f.c0 < 0 else 0.0
        out.append(
            Control(
                "distance",
                f"{prefix}distance",
                abs(f.c0),
                "distance",
                "",
                (Write(f.key, -1.0 if flip else 1.0),),
            )
        )
    sum_before = sum(_angle(op) for op in before)
    sum_after = sum(_angle(op) for op in after)
    turn = sum_before + sum_after
    if moves and before:
        r = before[-1]
        others = sum_before - _angle(r)
        writes = [Write(r.key, _sign(r), -_sign(r) * (others + flip))]
        if after:  # keep the turn: the last turn after the move takes up the difference
            q = after[-1]
            rest = sum_after - _angle(q)
            writes.append(Write(q.key, -_sign(q), _sign(q) * (turn + flip - rest)))
        direction = _wrap(sum_before + flip)
        out.append(Control("direction", f"{prefix}direction", direction, "angle", "°", tuple(writes)))
    turns = after if (moves and before) else before + after
    if turns:
        q = turns[-1]
        rest = turn - _angle(q)
        out.append(
            Control("turn", f"{prefix}turn", turn, "angle", "°", (Write(q.key, _sign(q), -_sign(q) * rest),))
        )
    if scales:
        s1 = scales[0]
        others = math.prod(op.c0 for op in scales[1:])
        if others != 0:
            total = s1.c0 * others
            out.append(
                Control("scale", f"{prefix}scale", total, "scale", "×", (Write(s1.key, 1.0 / others),))
            )
    for i, op in enumerate(run):  # values linear in m: how much they change with m
        if op.cd:
            name = {"f": "distance", "*": "scale"}.get(op.op) or ("direction" if i < at else "turn")
            kind = {"distance": "distance_delta", "scale": "scale_delta"}.get(name, "angle_delta")
            sign = -1.0 if op.op == "-" else 1.0
            dkey = op.key[: -len(".v")] + ".dv"
            label = f"{prefix}{name} change with m"
            n = sum(c.label.startswith(label) for c in out)
            out.append(
                Control(
                    f"{name} change",
                    label + (f" #{n + 1}" if n else ""),
                    sign * op.cd,
                    kind,
                    "",
                    (Write(dkey, sign),),
                )
            )
    return out


def _wrap(deg: float) -> float:
    """Return ``deg`` in (-180, 180]."""
    x = math.fmod(deg + 180.0, 360.0)
    return (x + 360.0 if x <= 0 else x) - 180.0


def merge(controls: list[Control]) -> list[Control]:
    """Merge controls of the same name and value (a step repeated in another case) into one.

    Controls are grouped by ``(name, label)`` first, so a start with 240 controls compares each
    only with its namesakes (a scan of all earlier controls took 6 ms for 120 rules).
    """
    out: list[Control] = []
    by_key: dict[tuple[str, str], list[int]] = {}
    for c in controls:
        slots = by_key.setdefault((c.name, c.label), [])
        for i in slots:
            d = out[i]
            if math.isclose(d.value, c.value, rel_tol=1e-9, abs_tol=1e-12):
                out[i] = Control(d.name, d.label, d.value, d.kind, d.unit, d.writes + c.writes)
                break
        else:
            slots.append(len(out))
            out.append(c)
    return out


def _fmt(x: float) -> str:
    return f"{x:.3g}" if abs(x) < 100 else f"{x:.0f}"


def signature(run: list[Op]) -> tuple[tuple[str, float, float], ...]:
    """Return what identifies a run's commands (operators and values, not keys)."""
    return tuple((op.op, op.c0, op.cd) for op in run)


def sequence_words(run: list[Op] | None, reps: float | None, calls: tuple[str, ...]) -> tuple[str, str]:
    """Return the kind and summary of a sequence rule from its step."""
    n = f" of {int(reps)}" if reps is not None else ""
    what = f" × {', '.join(calls)}" if calls else ""
    if run is None:
        return "row", f"sequence{n}{what}"
    b = _net(run) or 0j
    rotations = [(i, op) for i, op in enumerate(run) if op.op in "+-"]
    move_at = next((i for i, op in enumerate(run) if op.op == "f"), len(run))
    growing = sum(_sign(op) * op.cd for _, op in rotations)
    if growing:
        return (
            "sequence",
            f"sequence{n}{what}, {_fmt(abs(b))} apart, turning {_fmt(-growing)}° more each step",
        )
    # The direction of the move may change with m while the heading turns: the moves turn by
    # the heading's turn minus that change (``+(630 - 90*m) f(40) +(-720 + 90*m)`` is straight).
    heading = sum(_angle(op) for _, op in rotations)
    turn = heading - sum(_sign(op) * op.cd for i, op in rotations if i < move_at)
    each = f", each turned {_fmt(_wrap(heading))}°" if abs(_wrap(heading - turn)) >= _STRAIGHT else ""
    scale = math.prod(op.c0 for op in run if op.op == "*")
    straight = abs(_wrap(turn)) < _STRAIGHT
    flat = abs(scale - 1.0) < _FLAT_SCALE
    if flat and straight:
        return "row", f"row{n}{what}, {_fmt(abs(b))} apart{each}"
    closes = reps is not None and reps > 2 and abs(_wrap(reps * turn)) < max(1.0, 0.5 * abs(turn))
    if flat and closes and abs(turn) > _STRAIGHT:
        radius = abs(b) / (2 * math.sin(math.radians(abs(turn)) / 2)) if abs(b) else 0.0
        return "ring", f"ring{n}{what}" + (f", radius {_fmt(radius)}" if radius else "") + each
    if flat:
        return "arc", f"arc{n}{what}, turning {_fmt(turn)}° per step{each}"
    words = f"×{scale:.4g} per step"
    if straight:
        return "row", f"row{n}{what}, {_fmt(abs(b))} apart, {words}"
    return "spiral", f"spiral{n}{what}, {_fmt(turn)}° and {words}"
