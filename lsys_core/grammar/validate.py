"""Check a :class:`~lsys_core.grammar.model.Grammar` for the errors a user can make.

The checks work on the model alone (no text positions), so grammars built by code
(inference, the editor's sliders) are checked the same way as parsed ones.
:func:`find_problems` returns every problem with a locator (which rule or the axiom,
which case, which module); the text parser maps locators to ``line:column``.
:func:`validate` raises the first problem as a :class:`~lsys_core.errors.GrammarError`.

Termination
-----------
Non-terminals form a call graph (an edge for every symbol a rule's body calls).  A
derivation can only run forever along a cycle of that graph, i.e. inside one strongly
connected component (SCC).  Inside an SCC every call must be to a parametric symbol
with an argument ``m - c`` (``Count(-c, 1)``, ``c >= 0``), and no cycle may consist of
``c == 0`` calls only, so the counter strictly decreases around every cycle.  Calls
leaving the SCC are unrestricted.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Literal

import numpy as np

from lsys_core.errors import GrammarError
from lsys_core.grammar.model import (
    COND_EQ0,
    COND_GT0,
    PAINT_PROPS,
    Count,
    Grammar,
    Linear,
    Module,
    Paint,
    Pop,
    Push,
    Rule,
    Symbol,
    Turtle,
)

__all__ = [
    "COUNT_LIMIT",
    "KEYWORDS",
    "KEYWORDS_V1",
    "NAME_RE",
    "RESERVED",
    "RESERVED_V1",
    "Problem",
    "count_text",
    "find_problems",
    "path_problem",
    "validate",
]

NAME_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
"""Pattern of a symbol name."""

KEYWORDS_V1 = frozenset({"lsys", "canvas", "viewbox", "size", "terminal", "style", "mirror", "axiom"})
"""Words of format version 1 that cannot name a symbol."""

KEYWORDS = KEYWORDS_V1 | {"scaled", "paint", "order", "defs", "verbatim", "what"}
"""Words of the text format that cannot name a symbol."""

RESERVED_V1 = KEYWORDS_V1 | {"f", "m", "eps", "nan", "inf", "infinity"}
"""The words format version 1 reserves."""

RESERVED = KEYWORDS | RESERVED_V1 | {"z"}
"""Every word that cannot name a symbol (keywords, the ``f`` and ``z`` modules, the counter, ε,
non-finite numbers)."""

COUNT_LIMIT = 2**31 - 1
"""Largest magnitude of a counter coefficient."""

Where = Literal["grammar", "canvas", "terminal", "axiom", "rule", "style", "table"]


@dataclass(frozen=True)
class Problem:
    """One problem of a grammar, with a locator.

    Attributes
    ----------
    message : str
        What is wrong, one line, without the location.
    where : str
        ``"rule"`` (``owner`` is the rule name), ``"axiom"``, ``"terminal"`` (``owner`` is
        the terminal name), ``"style"`` (a named style), ``"table"`` (``owner`` is
        ``"paint"``, ``"order"`` or ``"verbatim"``), ``"canvas"`` or ``"grammar"``.
    owner : str
        Rule or terminal name, ``"axiom"`` for the axiom, ``"viewbox"`` or ``"size"`` for
        the canvas, ``""`` for the whole grammar.
    case : int or None
        0-based case index within the rule (0 for the axiom).
    index : int or None
        0-based module index within the body; None for the rule or case as a whole.
    arg : bool
        True when the problem is the module's argument rather than the module itself.
    """

    message: str
    where: Where
    owner: str = ""
    case: int | None = None
    index: int | None = None
    arg: bool = False

    def describe(self) -> str:
        """Return the message with the locator in words, for grammars without text positions."""
        if self.where == "rule":
            place = f"rule {self.owner}"
            if self.case is not None:
                place += f", case {self.case + 1}"
        elif self.where == "terminal":
            place = f"terminal {self.owner}"
        else:
            place = self.where
        if self.index is not None:
            place += f", module {self.index + 1}"
        return f"{self.message} (in {place})"


def validate(g: Grammar) -> None:
    """Raise :class:`~lsys_core.errors.GrammarError` for the first problem of ``g``.

    Parameters
    ----------
    g : Grammar
        The grammar to check.

    Raises
    ------
    GrammarError
        Naming the problem and where it is (rule, case and module).
    """
    problems = find_problems(g)
    if problems:
        more = f" (and {len(problems) - 1} more problems)" if len(problems) > 1 else ""
        raise GrammarError(problems[0].describe() + more)


def find_problems(g: Grammar) -> list[Problem]:
    """Return every problem of ``g``: names, canvas, conditions, bodies, axiom, termination.

    Parameters
    ----------
    g : Grammar
        The grammar to check.

    Returns
    -------
    list of Problem
        Empty when the grammar is valid.
    """
    problems = list(_name_problems(g))
    problems += _canvas_problems(g)
    problems += _style_problems(g)
    names = _Names(
        {t.name for t in g.terminals}, {r.name: r.parametric for r in g.rules}, {s.name for s in g.styles}
    )
    for r in g.rules:
        problems += _case_problems(r)
        for ci, case in enumerate(r.cases):
            problems += _body_problems(names, case.body, "rule", r.name, ci, r.parametric)
    if not g.axiom:
        problems.append(Problem("missing axiom: add a line 'axiom: ...'", "grammar"))
    problems += _body_problems(names, g.axiom, "axiom", "axiom", 0, False)
    if not problems:  # the call graph is only meaningful for a well-formed grammar
        from lsys_core.grammar.termination import termination_problems

        problems += termination_problems(g)
    return problems


@dataclass(frozen=True)
class _Names:
    """The declared symbols: terminal names, and whether each rule is parametric."""

    terminals: set[str]
    parametric: dict[str, bool]
    styles: set[str]


def _name_problems(g: Grammar) -> Iterator[Problem]:
    """Yield problems with terminal and rule names."""
    seen: set[str] = set()
    for t in g.terminals:
        if bad := _bad_name(t.name):
            yield Problem(bad, "terminal", t.name)
        if t.name in seen:
            yield Problem(f"duplicate terminal '{t.name}'", "terminal", t.name)
        seen.add(t.name)
        if not isinstance(t.path, str) or not isinstance(t.style, str):
            yield Problem(f"terminal '{t.name}' needs string path data and style", "terminal", t.name)
    for t in g.terminals:
        if t.mirror_of is not None and t.mirror_of not in seen:
            yield Problem(f"'mirror {t.mirror_of}' does not name a terminal", "terminal", t.name, arg=True)
    rule_names: set[str] = set()
    for r in g.rules:
        if bad := _bad_name(r.name):
            yield Problem(bad, "rule", r.name, 0)
        if r.name in seen:
            yield Problem(f"'{r.name}' is a terminal and cannot have a rule", "rule", r.name, 0)
        if r.name in rule_names:
            yield Problem(f"rule '{r.name}' is defined twice", "rule", r.name, 0)
        rule_names.add(r.name)


def _bad_name(name: object) -> str | None:
    """Return why ``name`` cannot name a symbol, or None."""
    if not isinstance(name, str) or not NAME_RE.fullmatch(name):
        return f"invalid symbol name {name!r}"
    if name in RESERVED:
        return f"'{name}' is reserved and cannot name a symbol"
    return None


def _canvas_problems(g: Grammar) -> list[Problem]:
    """Return problems with the viewBox and size."""
    out = []
    if g.viewbox is not None:
        vb = g.viewbox
        if len(vb) != 4 or not all(_finite(v) for v in vb):
            out.append(Problem("viewbox needs 4 finite numbers", "canvas", "viewbox"))
        elif vb[2] <= 0 or vb[3] <= 0:
            out.append(Problem("viewbox width and height must be positive", "canvas", "viewbox"))
    if g.size is not None and (len(g.size) != 2 or not all(isinstance(s, str) for s in g.size)):
        out.append(Problem("size needs two strings (width and height)", "canvas", "size"))
    return out


def _style_problems(g: Grammar) -> list[Problem]:
    """Return problems with named styles, the per-instance tables and the verbatim content."""
    out = []
    seen: set[str] = set()
    for s in g.styles:
        if not isinstance(s.name, str) or not NAME_RE.fullmatch(s.name) or s.name in RESERVED:
            out.append(Problem(f"invalid style name {s.name!r}", "style", str(s.name)))
        elif s.name in seen:
            out.append(Problem(f"duplicate style '{s.name}'", "style", s.name))
        if not isinstance(s.css, str):
            out.append(Problem(f"style '{s.name}' needs a string of CSS declarations", "style", str(s.name)))
        seen.add(s.name)
    for name in dict.fromkeys(p for p in g.paint if p is not None):
        if name not in seen:
            out.append(Problem(f"paint: undefined style '{name}'", "table", name))
    if not all(_finite(v) for v in g.order):
        out.append(Problem("order: every entry must be a finite number", "table", "order"))
    for v in g.verbatim:
        if not _is_int(v.order) or v.order < 0 or not isinstance(v.xml, str):
            out.append(Problem("verbatim: needs a whole number >= 0 and SVG markup", "table", "verbatim"))
            break
    return out


def _paint_problem(names: _Names, paint: Paint, parametric: bool, no_m: str) -> str | None:
    """Return what is wrong with a terminal occurrence's paint, or None."""
    if not isinstance(paint, Paint):
        return f"unknown paint {paint!r}"
    if paint.style is not None and paint.style not in names.styles:
        return f"undefined style '{paint.style}': declare it with a line 'style {paint.style} \"...\"'"
    seen = set()
    for key, v in paint.props:
        if key not in PAINT_PROPS:
            return f"unknown paint property '{key}' (known: {', '.join(PAINT_PROPS)})"
        if key in seen:
            return f"duplicate paint property '{key}'"
        seen.add(key)
        if not isinstance(v, Linear) or not (_finite(v.c0) and _finite(v.cd)):
            return f"the value of '{key}' must be a finite number"
        if v.table:
            return f"paint property '{key}' takes a number or a value linear in m, not a table [...]"
        if v.cd != 0 and not parametric:
            return no_m
    return None


def _case_problems(r: Rule) -> list[Problem]:
    """Return problems with a rule's conditions: wrong kind, or a case no counter can reach."""
    out = []
    if not r.cases:
        out.append(Problem(f"rule {r.name} has no productions", "rule", r.name, 0))
    covered: set[str | None] = set()
    for ci, case in enumerate(r.cases):
        msg = None
        if case.cond is not None and not r.parametric:
            msg = f"rule {r.name} has no counter m, so it cannot have a condition"
        elif case.cond not in (None, COND_GT0, COND_EQ0):
            msg = f"unknown condition {case.cond!r}: use 'm > 0' or 'm == 0'"
        elif (
            None in covered or case.cond in covered or (case.cond is None and {COND_GT0, COND_EQ0} <= covered)
        ):
            msg = f"rule {r.name}: this case is never used (an earlier case covers it)"
        if msg:
            out.append(Problem(msg, "rule", r.name, ci))
        covered.add(case.cond)
    return out


def _body_problems(
    names: _Names, body: tuple[Module, ...], where: Where, owner: str, ci: int, parametric: bool
) -> list[Problem]:
    """Return problems with the modules of one body (values, symbols, arity, brackets)."""
    out: list[Problem] = []

    def add(msg: str, i: int, arg: bool = False) -> None:
        out.append(Problem(msg, where, owner, ci, i, arg))

    no_m = "m cannot be used in the axiom" if where == "axiom" else f"m cannot be used in rule {owner}"
    if where == "rule" and not parametric:
        no_m += f", which has no counter (declare {owner}(m))"
    opens: list[int] = []
    for i, mod in enumerate(body):
        if isinstance(mod, Push):
            opens.append(i)
        elif isinstance(mod, Pop):
            if not opens:
                add("unbalanced ']': no '[' to close", i)
            else:
                opens.pop()
        elif isinstance(mod, Turtle):
            if msg := _turtle_problem(mod, parametric, no_m):
                add(msg, i, arg=True)
        elif isinstance(mod, Symbol):
            if found := _symbol_problem(names, mod, parametric, no_m):
                add(found[0], i, found[1])
        else:
            add(f"unknown module {mod!r}", i)
    for i in opens:
        add("unbalanced '[': no ']' closes it", i)
    return out


def _turtle_problem(mod: Turtle, parametric: bool, no_m: str) -> str | None:
    """Return what is wrong with a turtle module, or None."""
    if mod.op not in ("f", "+", "-", "*", "z", "~"):
        return f"unknown turtle command {mod.op!r}"
    v = mod.value
    if not isinstance(v, Linear) or not (_finite(v.c0) and _finite(v.cd)):
        return f"the value of {mod.op}(...) must be a finite number"
    if v.table and not all(_finite(x) for x in v.table):
        return f"the values of {mod.op}([...]) must be finite numbers"
    if (v.cd != 0 or v.table) and not parametric:
        return no_m
    if mod.op == "*" and v.table and min(v.table) <= 0:
        return "scale must be positive: a table of *([...]) holds 0 or a negative scale"
    if mod.op == "*" and v.cd == 0 and v.c0 <= 0:
        return "scale must be positive: *(0) or a negative *(s) collapses or flips the drawing"
    return None


def _symbol_problem(names: _Names, mod: Symbol, parametric: bool, no_m: str) -> tuple[str, bool] | None:
    """Return what is wrong with a symbol module and whether it is the argument, or None."""
    name = mod.name
    if name in names.terminals:
        if mod.arg is not None:
            return f"terminal {name} takes no argument", False
        if mod.paint is not None and (msg := _paint_problem(names, mod.paint, parametric, no_m)):
            return msg, True
        return None
    if mod.paint is not None:
        return f"{name} is not a terminal: only terminals take a paint {{...}}", False
    parametric_rule = names.parametric.get(name)
    if parametric_rule is None:
        return f"undefined symbol '{name}': declare it as a terminal or give it a rule", False
    if parametric_rule and mod.arg is None:
        return f"{name} takes a counter argument, e.g. {name}(3) or {name}(m-1)", False
    if not parametric_rule and mod.arg is not None:
        return f"{name} takes no counter: write {name}, or declare its rule as {name}(m)", False
    if mod.arg is None:
        return None
    a = mod.arg
    if not isinstance(a, Count) or not all(_is_int(k) for k in (a.k0, a.k1)):
        return f"counter argument of {name} must be integer", True
    if abs(a.k0) > COUNT_LIMIT or abs(a.k1) > COUNT_LIMIT:
        return f"counter argument of {name} is out of range (|k| <= {COUNT_LIMIT})", True
    if a.k1 != 0 and not parametric:
        return no_m, True
    return None


def count_text(a: Count) -> str:
    """Return a counter argument as ``.lsys`` text: ``3``, ``m``, ``m-1``, ``2*m+1``, ``-m``."""
    k0, k1 = int(a.k0), int(a.k1)
    if k1 == 0:
        return str(k0)
    head = "m" if k1 == 1 else "-m" if k1 == -1 else f"{k1}*m"
    return head if k0 == 0 else f"{head}{k0:+d}"


def _finite(x: object) -> bool:
    """Tell whether ``x`` is a finite real number."""
    if isinstance(x, bool) or not isinstance(x, int | float | np.integer | np.floating):
        return False
    return math.isfinite(x)


def _is_int(x: object) -> bool:
    """Tell whether ``x`` is an integer (Python or numpy), not a bool."""
    return isinstance(x, int | np.integer) and not isinstance(x, bool)


def path_problem(d: str) -> str | None:
    """Return why terminal path data cannot be drawn, or None (see :mod:`.termination`)."""
    from lsys_core.grammar.termination import path_problem as check

    return check(d)
