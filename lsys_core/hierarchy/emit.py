"""Writing rules (§5.5, §5.7): a candidate becomes productions in the paper's turtle notation.

Transforms are written as ``+(α) f(d) *(s) +(β)`` without identity commands, their values
the shortest decimals within a small tolerance of the measured ones.  Every application of
the candidate becomes one node of the new non-terminal (its counter the application's length
or depth).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lsys_core.geometry.transforms import t4_from_rel, wrap_deg
from lsys_core.grammar.model import (
    COND_EQ0,
    COND_GT0,
    Case,
    Count,
    Linear,
    Module,
    Pop,
    Push,
    Rule,
    Symbol,
    Turtle,
)
from lsys_core.hierarchy.candidates import (
    BranchCandidate,
    Candidate,
    LinearCandidate,
    PairCandidate,
    SeqCandidate,
)
from lsys_core.hierarchy.flat import Groups
from lsys_core.hierarchy.symbols import SymbolTable

__all__ = [
    "ANGLE_SNAP",
    "DISTANCE_SNAP",
    "SCALE_SNAP",
    "Emitted",
    "const_t",
    "const_t_many",
    "counters",
    "emit",
    "nice",
    "nice_array",
    "rule_cases",
    "t_modules",
]

#: Written values are the shortest decimals within these tolerances of the measured ones
#: (degrees; relative for distances and scales, which compound along a sequence).
ANGLE_SNAP = 1e-5
DISTANCE_SNAP = 1e-6
SCALE_SNAP = 5e-8


@dataclass(frozen=True, eq=False)
class Emitted:
    """A candidate written as a rule: the rule, a log line, and the new node of every application.

    ``groups[k]`` (first node first) becomes one node of symbol ``syms[k]``.
    """

    rule: Rule
    log: str
    groups: Groups
    syms: tuple[int, ...]


def nice(x: float, *, abs_tol: float = 0.0, rel_tol: float = 0.0) -> float:
    """Return the decimal with the fewest digits within the tolerance of ``x`` (``45.0000049`` → ``45``)."""
    x = float(x)
    if x == 0 or not np.isfinite(x):
        return 0.0 if x == 0 else x
    tol = max(abs_tol, rel_tol * abs(x))
    for digits in range(0, 12):
        y = round(x, digits)
        if abs(y - x) <= tol:
            return y + 0.0
    return float(f"{x:.12g}") + 0.0


def t_modules(alpha: Linear, d: Linear, s: Linear, beta: Linear) -> tuple[Module, ...]:
    """Return ``+(α) f(d) *(s) +(β)`` without identity commands."""
    out: list[Module] = []
    if alpha.cd == 0 and beta.cd == 0 and d.cd == 0 and abs(float(wrap_deg(alpha.c0))) > 90.0:
        # +(α) f(d) … +(β) == +(α-180) f(-d) … +(β+180): keep the turn small.
        alpha = Linear(float(wrap_deg(alpha.c0 - 180.0)))
        d = Linear(-d.c0)
        beta = Linear(float(wrap_deg(beta.c0 + 180.0)))

    def angle(v: Linear) -> None:
        c0 = float(wrap_deg(v.c0)) if v.cd == 0 else v.c0
        if abs(c0) > 1e-9 or v.cd != 0:
            out.append(Turtle("+", Linear(nice(c0, abs_tol=ANGLE_SNAP), nice(v.cd, abs_tol=ANGLE_SNAP))))

    angle(alpha)
    if abs(d.c0) > 1e-12 or d.cd != 0:
        out.append(Turtle("f", Linear(nice(d.c0, rel_tol=DISTANCE_SNAP), nice(d.cd, rel_tol=DISTANCE_SNAP))))
    if abs(s.c0 - 1.0) > 1e-9 or s.cd != 0:
        out.append(Turtle("*", Linear(nice(s.c0, rel_tol=SCALE_SNAP), nice(s.cd, rel_tol=SCALE_SNAP))))
    angle(beta)
    return tuple(out)


def const_t(A: complex, B: complex) -> tuple[Module, ...]:
    """Return the modules of the constant relative frame ``(A, B)``."""
    al, d, s, be = (float(v) for v in t4_from_rel(A, B))
    return t_modules(Linear(al), Linear(d), Linear(s), Linear(be))


def nice_array(x: np.ndarray, *, abs_tol: float = 0.0, rel_tol: float = 0.0) -> np.ndarray:
    """:func:`nice` of every value of ``x`` (vectorised)."""
    x = np.asarray(x, float)
    tol = np.maximum(abs_tol, rel_tol * np.abs(x))
    out = np.where(np.isfinite(x), np.round(x, 12), x)
    done = (x == 0) | ~np.isfinite(x)
    out = np.where(x == 0, 0.0, out)
    for digits in range(0, 12):
        y = np.round(x, digits)
        hit = ~done & (np.abs(y - x) <= tol)
        out = np.where(hit, y, out)
        done |= hit
    return out + 0.0


def const_t_many(A: np.ndarray, B: np.ndarray) -> list[tuple[Module, ...]]:
    """:func:`const_t` of many relative frames at once (the same modules, computed vectorised)."""
    al, d, s, be = (np.asarray(v, float) for v in t4_from_rel(A, B))
    flip = np.abs(wrap_deg(al)) > 90.0
    al = np.where(flip, wrap_deg(al - 180.0), wrap_deg(al))
    d = np.where(flip, -d, d)
    be = wrap_deg(np.where(flip, be + 180.0, be))
    cols = (
        ("+", np.abs(al) > 1e-9, nice_array(al, abs_tol=ANGLE_SNAP)),
        ("f", np.abs(d) > 1e-12, nice_array(d, rel_tol=DISTANCE_SNAP)),
        ("*", np.abs(s - 1.0) > 1e-9, nice_array(s, rel_tol=SCALE_SNAP)),
        ("+", np.abs(be) > 1e-9, nice_array(be, abs_tol=ANGLE_SNAP)),
    )
    out: list[tuple[Module, ...]] = []
    for i in range(al.size):
        out.append(tuple(Turtle(op, Linear(float(v[i]))) for op, on, v in cols if on[i]))  # type: ignore[arg-type]
    return out


def _recursive(table: SymbolTable, name: str, si: int, step: tuple[Module, ...]) -> tuple[Case, ...]:
    gt = Case(COND_GT0, (*table.draw(si), *step, Symbol(name, Count(-1, 1))))
    eq = Case(COND_EQ0, table.draw(si, last=True))
    return (gt, eq)


def rule_cases(table: SymbolTable, c: Candidate, name: str) -> tuple[Case, ...]:
    """The productions of candidate ``c`` as rule ``name`` (nothing is registered in ``table``)."""
    si, sj = c.space
    if isinstance(c, PairCandidate):
        return (Case(None, table.draw(si) + const_t(c.A, c.B) + table.draw(sj, last=True)),)
    if isinstance(c, SeqCandidate):
        return _recursive(table, name, si, const_t(c.A, c.B))
    if isinstance(c, LinearCandidate):
        k = c.steps
        step = t_modules(
            Linear(c.alpha0 + k * c.d_alpha, -c.d_alpha),
            Linear(c.d),
            Linear(c.s),
            Linear(c.beta0 + k * c.d_beta, -c.d_beta),
        )
        return _recursive(table, name, si, step)
    if isinstance(c, BranchCandidate):
        (A1, B1), (A2, B2) = c.first, c.second
        rec = Symbol(name, Count(-1, 1))
        gt = Case(COND_GT0, (*table.draw(si), Push(), *const_t(A1, B1), rec, Pop(), *const_t(A2, B2), rec))
        return (gt, Case(COND_EQ0, table.draw(si, last=True)))
    raise TypeError(f"unknown candidate {type(c).__name__}")  # pragma: no cover


def counters(c: Candidate) -> tuple[int | None, ...]:
    """The counter every application of ``c`` calls its rule with (None: the rule takes none)."""
    if isinstance(c, PairCandidate):
        return tuple(None for _ in c.groups)
    if isinstance(c, BranchCandidate):
        return c.depths
    return tuple((c.groups.lengths - 1).tolist())


_PREFIX = {PairCandidate: "X", SeqCandidate: "P", LinearCandidate: "P", BranchCandidate: "R"}


def _log(table: SymbolTable, c: Candidate, name: str) -> str:
    si, sj = c.space
    first, second = table.infos[si].name, table.infos[sj].name
    if isinstance(c, PairCandidate):
        return f"{name}: {len(c.groups)} pairs {first}-{second}"
    if isinstance(c, LinearCandidate):
        return (
            f"{name}: {len(c.groups)} sequences with linear angles ({c.d_alpha:.3g}°, {c.d_beta:.3g}°/step)"
        )
    if isinstance(c, BranchCandidate):
        return f"{name}: {len(c.groups)} branching structures, depths {sorted(set(c.depths))}"
    return f"{name}: {len(c.groups)} sequences of {first}, lengths {sorted(set(c.groups.lengths.tolist()))}"


def emit(table: SymbolTable, c: Candidate) -> Emitted:
    """Write candidate ``c`` as a new rule and register the symbols of its applications."""
    name = table.new_name(_PREFIX[type(c)])
    cases = rule_cases(table, c, name)
    rule = Rule(name, not isinstance(c, PairCandidate), cases)
    syms = tuple(table.symbol(name, m) for m in counters(c))
    return Emitted(rule, _log(table, c, name), c.groups, syms)
