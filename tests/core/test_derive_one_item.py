"""A body run for one item (scalar turtle, draws recorded at once) derives what the vectorised run derives."""

from __future__ import annotations

import numpy as np
import pytest

import lsys_core.derive.derivation as derivation
import lsys_core.derive.turtle as turtle
from lsys_core.grammar import parse_grammar

WIDE = """lsys 2
terminal A "M 0 0 L 4 0 L 2 3 Z" style "fill:#789"
terminal B "M 0 0 L 3 0 L 3 3 L 0 3 Z" style "fill:#a00"
axiom: Z [ +(30) f(50) R(3) ]
Z -> {body}
R(m): m > 0 -> B f(7) *(0.9) +(12) R(m-1)
R(m): m == 0 -> A
"""


def _wide(n: int) -> str:
    rng = np.random.default_rng(n)
    parts = []
    for k in range(n):
        a, d, s = rng.uniform(-180, 180), rng.uniform(-300, 300), rng.uniform(0.5, 2)
        parts.append(f"[ +({a:.3f}) f({d:.3f}) *({s:.3f}) +({-a:.3f}) z({k % 3}) {'AB'[k % 2]} ]")
    return WIDE.replace("{body}", " ".join(parts))


def _the_old_way(monkeypatch) -> None:
    """Run one-item bodies with the vectorised turtle (on two copies) and record draws one by one."""
    real = turtle.Interpreter.run

    def run(self, ops, m, a=None, b=None, z=None, perturb=True):
        if m.size != 1:
            return real(self, ops, m, a, b, z, perturb)

        def two(x):
            return None if x is None else np.repeat(x, 2)

        fa, fb, fz, draws, calls = real(self, ops, np.repeat(m, 2), two(a), two(b), two(z), perturb)
        return (
            fa[:1],
            fb[:1],
            fz[:1],
            [(i, op, da[:1], db[:1], dz[:1]) for i, op, da, db, dz in draws],
            [(i, t, mm[:1], ca[:1], cb[:1], cz[:1]) for i, t, mm, ca, cb, cz in calls],
        )

    def emit_all(self, draws, rule, where, m, parent):
        for i, op, a, b, z in draws:
            self.emit([(i, op, a, b, z)], rule, where, m, parent, i)

    monkeypatch.setattr(turtle.Interpreter, "run", run)
    monkeypatch.setattr(derivation._Derivation, "emit_all", emit_all)


@pytest.mark.parametrize("n", [1, 2, 40, 500])
def test_one_item_runs_derive_what_the_vectorised_turtle_derives(monkeypatch, n):
    g = parse_grammar(_wide(n))
    fast = derivation.derive(g)
    with monkeypatch.context() as patch:
        _the_old_way(patch)
        slow = derivation.derive(g)
    assert len(fast) == len(slow) == n + 4
    assert np.array_equal(fast.symbol, slow.symbol) and np.array_equal(fast.rule, slow.rule)
    assert np.array_equal(
        fast.style if fast.style is not None else [], slow.style if slow.style is not None else []
    )
    assert np.allclose(fast.a, slow.a, rtol=1e-12) and np.allclose(fast.b, slow.b, rtol=1e-12, atol=1e-9)


def test_a_non_finite_turn_overflows_as_in_the_vectorised_turtle():
    from lsys_core.errors import LimitError

    g = parse_grammar(_wide(3).replace("axiom: Z", "axiom: *(1e300) *(1e300) Z"))
    with pytest.raises(LimitError, match="overflows"):
        derivation.derive(g)
