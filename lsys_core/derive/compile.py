"""Compile a grammar's bodies into flat op lists for the vectorised derivation.

Ops: ``("t", op, c0, cd, table)`` turtle command (``f + - * z``; ``table`` the value's table, empty
or None when it is linear), ``("[",)`` push, ``("]",)`` pop,
``("draw", terminal, paint, slot)`` a terminal occurrence (``paint`` indexes the compiled
paints, -1 for none; ``slot`` numbers every terminal occurrence of the grammar), and
``("call", rule, k0, k1)`` a non-terminal with counter ``k0 + k1·m``.
"""

from __future__ import annotations

from dataclasses import dataclass

from lsys_core.errors import GrammarError
from lsys_core.grammar.model import Grammar, Module, Paint, Pop, Push, Symbol, Turtle

__all__ = ["Compiled", "Program", "compile_grammar"]

Op = tuple


@dataclass
class Compiled:
    """One case: its ops, and ``(step c, index of the tail call)`` when it is a self sequence."""

    ops: list[Op]
    tail: tuple[int, int] | None


@dataclass
class Program:
    """A compiled grammar: the axiom's ops, every rule's cases, the paints and the slots.

    ``slots[s]`` is ``(owner, case, module index)`` of terminal occurrence ``s`` (owner: a
    rule name or ``"axiom"``).
    """

    axiom: list[Op]
    rules: list[list[Compiled]]
    paints: list[Paint]
    slots: list[tuple[str, int, int]]


def compile_grammar(grammar: Grammar) -> Program:
    """Compile ``grammar``; raise :class:`GrammarError` for an undefined symbol."""
    terms = {t.name: i for i, t in enumerate(grammar.terminals)}
    rules = {r.name: i for i, r in enumerate(grammar.rules)}
    paints: list[Paint] = []
    paint_ids: dict[Paint, int] = {}
    slots: list[tuple[str, int, int]] = []

    def body_ops(body: tuple[Module, ...], owner: str, ci: int, axiom: bool) -> list[Op]:
        ops: list[Op] = []
        for i, mod in enumerate(body):
            if isinstance(mod, Turtle):
                v = mod.value
                ops.append(
                    ("t", mod.op, float(v.c0), 0.0 if axiom else float(v.cd), None if axiom else v.table)
                )
            elif isinstance(mod, Push):
                ops.append(("[",))
            elif isinstance(mod, Pop):
                ops.append(("]",))
            elif isinstance(mod, Symbol) and mod.name in terms:
                paint = -1
                if mod.paint is not None:
                    paint = paint_ids.setdefault(mod.paint, len(paints))
                    if paint == len(paints):
                        paints.append(mod.paint)
                ops.append(("draw", terms[mod.name], paint, len(slots)))
                slots.append((owner, ci, i))
            elif isinstance(mod, Symbol) and mod.name in rules:
                arg = mod.arg
                k1 = 0 if axiom or arg is None else arg.k1
                ops.append(("call", rules[mod.name], arg.k0 if arg else 0, k1))
            else:
                where = "the axiom" if axiom else f"rule {owner}"
                raise GrammarError(f"undefined symbol {getattr(mod, 'name', mod)} in {where}")
        return ops

    axiom = body_ops(grammar.axiom, "axiom", 0, True)
    compiled = []
    for ri, rule in enumerate(grammar.rules):
        cases = []
        for ci, case in enumerate(rule.cases):
            ops = body_ops(case.body, rule.name, ci, False)
            tail = None
            if rule.parametric and ops and ops[-1][0] == "call" and ops[-1][1] == ri:
                _, _, k0, k1 = ops[-1]
                depth = sum(1 if o[0] == "[" else -1 if o[0] == "]" else 0 for o in ops)
                if k1 == 1 and k0 <= -1 and depth == 0:
                    tail = (-k0, len(ops) - 1)
            cases.append(Compiled(ops, tail))
        compiled.append(cases)
    return Program(axiom, compiled, paints, slots)
