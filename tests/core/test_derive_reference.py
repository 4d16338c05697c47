"""The vectorised derivation against a tiny string-rewriting interpreter on random small grammars.

The reference rewrites the string one symbol at a time (depth first, left to right), then walks
the turtle over the final string; its instances, stably sorted by their paint-order value ``z``,
must equal the vectorised derivation's, in the same order.
"""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.derive.derivation import derive, derive_traced
from lsys_core.grammar import Case, Count, Grammar, Linear, Pop, Push, Rule, Symbol, Terminal, Turtle
from lsys_core.grammar.model import COND_EQ0, COND_GT0, Paint

DEG = np.pi / 180


def case_for(r: Rule, m: int) -> Case | None:
    """The first case whose condition holds for counter ``m`` (none for a negative counter)."""
    if r.parametric and m < 0:
        return None
    for c in r.cases:
        if c.cond is None or (c.cond == COND_GT0 and m > 0) or (c.cond == COND_EQ0 and m == 0):
            return c
    return None


def reference(g: Grammar) -> list[tuple[str, complex, complex, float]]:
    """Instances ``(terminal, a, b, z)`` in paint order, by plain rewriting and a turtle walk."""
    terminals = {t.name for t in g.terminals}
    rules = {r.name: r for r in g.rules}
    out: list[tuple[str, complex, complex, float]] = []
    # The derived string is produced depth first; the turtle walks it as it is produced.
    stack: list[tuple[complex, complex, float]] = []
    state = [1 + 0j, 0j, 0.0]

    def walk(body, m: int) -> None:
        for mod in body:
            if isinstance(mod, Push):
                stack.append(tuple(state))
            elif isinstance(mod, Pop):
                state[:] = stack.pop()
            elif isinstance(mod, Turtle):
                v = mod.value.c0 + mod.value.cd * m
                if mod.op == "f":
                    state[1] += state[0] * v
                elif mod.op == "*":
                    state[0] *= v
                elif mod.op == "z":
                    state[2] += v
                else:
                    state[0] *= np.exp(1j * DEG * (v if mod.op == "+" else -v))
            elif mod.name in terminals:
                out.append((mod.name, state[0], state[1], state[2]))
            else:
                r = rules[mod.name]
                k = mod.arg.k0 + mod.arg.k1 * m if mod.arg is not None else 0
                case = case_for(r, k)
                if case is not None:
                    walk(case.body, k)

    walk(g.axiom, 0)
    order = sorted(range(len(out)), key=lambda i: out[i][3])  # stable: derived-string order on ties
    return [out[i] for i in order]


def random_grammar(rng: np.random.Generator) -> Grammar:
    """A random small terminating grammar: sequences, branches, nested calls, z moves, paints.

    Calls are bracketed or last in their body, as in inferred grammars (the derivation leaves
    the caller's turtle state unchanged by a call, see docs/lsys-format.md).
    """
    names = ["A", "B", "C"]
    terminals = tuple(Terminal(n, "M 0 0 L 1 0") for n in names)
    n_rules = int(rng.integers(1, 4))
    rules = []

    def body(ri: int, parametric: bool, recursive: bool) -> tuple:
        mods: list = []
        for _ in range(int(rng.integers(1, 6))):
            kind = rng.integers(0, 6)
            if kind == 0:
                mods.append(Symbol(str(rng.choice(names))))
            elif kind == 1:
                mods.append(Symbol(str(rng.choice(names)), paint=Paint(None, (("opacity", Linear(0.5)),))))
            elif kind == 2:
                op = str(rng.choice(["f", "+", "*", "z", "-"]))
                c0 = float(rng.uniform(0.8, 1.2)) if op == "*" else float(rng.integers(-5, 6))
                cd = float(rng.integers(-2, 3)) if parametric and op in "f+z" else 0.0
                mods.append(Turtle(op, Linear(c0, cd)))
            elif kind == 3 and ri + 1 < n_rules:  # a call to a later rule (no cycles), bracketed
                k1 = int(rng.integers(0, 2)) if parametric else 0
                mods += [Push(), Symbol(f"R{ri + 1}", Count(int(rng.integers(0, 3)), k1)), Pop()]
            elif kind == 4 and recursive:  # a branch calling itself with m - 1
                mods += [Push(), Turtle("+", Linear(30.0)), Symbol(f"R{ri}", Count(-1, 1)), Pop()]
            else:
                mods.append(Symbol(str(rng.choice(names))))
        if recursive and rng.random() < 0.6:
            mods.append(Symbol(f"R{ri}", Count(-int(rng.integers(1, 3)), 1)))  # a tail sequence
        return tuple(mods)

    for ri in range(n_rules):
        cases = (Case(COND_GT0, body(ri, True, True)), Case(COND_EQ0, body(ri, True, False)))
        rules.append(Rule(f"R{ri}", True, cases))
    z = Turtle("z", Linear(float(rng.integers(-3, 4))))
    axiom = (Symbol("A"), z, Push(), Symbol("R0", Count(int(rng.integers(0, 5)))), Pop(), Symbol("B"))
    return Grammar(terminals, tuple(rules), axiom)


@pytest.mark.parametrize("seed", range(60))
def test_vectorised_derivation_matches_rewriting(seed: int) -> None:
    g = random_grammar(np.random.default_rng(seed))
    ref = reference(g)
    d = derive(g, limit=100_000)
    assert len(d) == len(ref)
    names = [d.terminals[s].name for s in d.symbol]
    assert names == [r[0] for r in ref]
    assert np.allclose(d.a, [r[1] for r in ref], atol=1e-9)
    assert np.allclose(d.b, [r[2] for r in ref], atol=1e-7)


def test_trace_positions_are_the_derived_string() -> None:
    g = random_grammar(np.random.default_rng(7))
    d, trace = derive_traced(g)
    assert sorted(trace.position.tolist()) == list(range(len(d)))
    # Without z moves the paint order is the derived string's order.
    flat = Grammar(g.terminals, g.rules, tuple(m for m in g.axiom if not isinstance(m, Turtle)))
    _, t2 = derive_traced(flat)
    assert t2.position.tolist() == list(range(len(t2.position))) or np.any(t2.z != 0)
