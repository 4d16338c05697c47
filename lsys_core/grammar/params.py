"""Name, list and change the numeric parameters of a grammar (editor sliders, ``--set NAME=VALUE``).

Every turtle value ``t(m) = t0 + tΔ·m`` but the paint-order moves ``z`` contributes its ``t0``
(and its ``tΔ`` when non-zero),
and every constant counter argument (``P(119)`` in the axiom, ``Q(5)`` in a body) is a
``count``.  A parameter's key is ``{owner}.{case}.{index}.{field}``:

owner
    the rule name, or ``axiom``;
case
    0-based case index in the rule (0 for the axiom);
index
    0-based module index in the body (brackets and symbols count too);
field
    ``v`` (``t0``), ``dv`` (``tΔ``), ``m`` (a constant counter argument) or, for a table value
    ``[v0, v1, ...]``, ``tJ`` (its entry ``J``; ``v`` names entry 0).

``P.0.1.v`` is the ``f(24)`` of ``P(m): m > 0 -> A f(24) ...``.  The key ``m`` is an alias
of the first constant counter argument of the axiom (the derivation depth).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, replace

from lsys_core.errors import GrammarError
from lsys_core.grammar.model import Grammar, Linear, Module, Symbol, Turtle
from lsys_core.grammar.validate import COUNT_LIMIT

__all__ = ["KINDS", "Param", "list_params", "set_param", "set_params"]

KINDS = ("angle", "distance", "scale", "angle_delta", "distance_delta", "scale_delta", "count")
"""Every :attr:`Param.kind`."""

#: How a parameter's label names its command when the operator alone would not say it.
_WORD_OF_OP = {"~": "stretch"}
_KIND_OF_OP = {"f": "distance", "+": "angle", "-": "angle", "*": "scale", "~": "distance"}


@dataclass(frozen=True)
class Param:
    """One numeric parameter of a grammar.

    Attributes
    ----------
    key : str
        Stable, typable name, e.g. ``P.0.1.v`` (see the module docstring).
    label : str
        Short text for a UI, e.g. ``"P (m > 0): f #1 Δ"``.
    value : float
        Current value.
    kind : str
        One of :data:`KINDS`.
    """

    key: str
    label: str
    value: float
    kind: str


def _bodies(g: Grammar) -> Iterator[tuple[str, int, str, tuple[Module, ...]]]:
    """Yield ``(owner, case index, label prefix, body)`` for the axiom and every case."""
    yield "axiom", 0, "axiom", g.axiom
    for r in g.rules:
        for ci, case in enumerate(r.cases):
            yield r.name, ci, (f"{r.name} ({case.cond})" if case.cond else r.name), case.body


def list_params(g: Grammar) -> list[Param]:
    """Return every numeric parameter of ``g``, axiom first, then rules in order.

    Parameters
    ----------
    g : Grammar
        The grammar.

    Returns
    -------
    list of Param
        Turtle values (``v``, and ``dv`` when non-zero) and constant counter arguments
        (``m``) in text order.  The alias ``m`` is accepted by :func:`set_param` but not listed.
    """
    out = []
    for owner, ci, prefix, body in _bodies(g):
        nth: Counter[str] = Counter()
        for i, mod in enumerate(body):
            key = f"{owner}.{ci}.{i}"
            if isinstance(mod, Turtle) and mod.op == "z":
                continue  # paint order, not geometry: not a slider (set_param still takes its key)
            if isinstance(mod, Turtle):
                nth[mod.op] += 1
                label = f"{prefix}: {_WORD_OF_OP.get(mod.op, mod.op)} #{nth[mod.op]}"
                kind = _KIND_OF_OP[mod.op]
                if mod.value.table:
                    out += [
                        Param(f"{key}.t{j}", f"{label} [{j}]", float(x), kind)
                        for j, x in enumerate(mod.value.table)
                    ]
                    continue
                out.append(Param(f"{key}.v", label, float(mod.value.c0), kind))
                if mod.value.cd != 0:
                    out.append(Param(f"{key}.dv", f"{label} Δ", float(mod.value.cd), f"{kind}_delta"))
            elif isinstance(mod, Symbol) and mod.arg is not None and mod.arg.k1 == 0:
                nth[mod.name] += 1
                out.append(
                    Param(
                        f"{key}.m", f"{prefix}: {mod.name} #{nth[mod.name]} count", float(mod.arg.k0), "count"
                    )
                )
    return out


def set_param(g: Grammar, key: str, value: float) -> Grammar:
    """Return a copy of ``g`` with the parameter ``key`` set to ``value``.

    Parameters
    ----------
    g : Grammar
        The grammar to change (left untouched).
    key : str
        A key of :func:`list_params`, ``{owner}.{case}.{index}.dv`` of any turtle value in
        a parametric rule (to add a Δ), or ``m``.
    value : float
        New value: finite; a constant scale must stay positive; a count must be an integer >= 0.

    Returns
    -------
    Grammar
        The changed grammar.

    Raises
    ------
    GrammarError
        For an unknown key (listing a few valid ones) or a value out of range.
    """
    owner, ci, index, fld = _resolve(g, key)
    body = _body(g, owner, ci)
    mod = body[index]
    x = _finite(key, value)
    # _resolve returns field m only for a constant counter argument, v and dv only for a turtle value
    if isinstance(mod, Symbol) and mod.arg is not None:
        if not x.is_integer() or not 0 <= x <= COUNT_LIMIT:
            raise GrammarError(f"parameter {key}: a count must be a whole number >= 0, got {value!r}")
        new: Module = replace(mod, arg=replace(mod.arg, k0=int(x)))
    elif isinstance(mod, Turtle) and mod.value.table:
        if mod.op == "*" and x <= 0:
            raise GrammarError(f"parameter {key}: a scale must be positive, got {value!r}")
        if fld == "dv":
            raise GrammarError(f"parameter {key}: a table value [...] has no Δ; set its entries t0, t1, ...")
        j = 0 if fld == "v" else int(fld[1:])
        table = mod.value.table
        new = replace(mod, value=Linear.of_table((*table[:j], x, *table[j + 1 :])))
    elif isinstance(mod, Turtle):
        lin = Linear(x, mod.value.cd) if fld == "v" else Linear(mod.value.c0, x)
        if mod.op == "*" and lin.cd == 0 and lin.c0 <= 0:
            raise GrammarError(f"parameter {key}: a scale must be positive, got {value!r}")
        new = replace(mod, value=lin)
    else:  # pragma: no cover - _resolve never returns another module
        raise GrammarError(f"unknown parameter '{key}'")
    body = (*body[:index], new, *body[index + 1 :])
    if owner == "axiom":
        return replace(g, axiom=body)
    rules = tuple(
        r
        if r.name != owner
        else replace(r, cases=tuple(replace(c, body=body) if j == ci else c for j, c in enumerate(r.cases)))
        for r in g.rules
    )
    return replace(g, rules=rules)


def set_params(g: Grammar, values: Mapping[str, float]) -> Grammar:
    """Return a copy of ``g`` with several parameters set (see :func:`set_param`)."""
    for key, value in values.items():
        g = set_param(g, key, value)
    return g


def _body(g: Grammar, owner: str, ci: int) -> tuple[Module, ...]:
    """Return body ``ci`` of rule ``owner`` (the axiom for ``axiom``); empty if there is none."""
    if owner == "axiom":
        return g.axiom if ci == 0 else ()
    rule = g.rule(owner)
    return rule.cases[ci].body if rule is not None and ci < len(rule.cases) else ()


def _finite(key: str, value: float | str) -> float:
    """Return ``value`` as a finite float or raise :class:`GrammarError`."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise GrammarError(f"parameter {key}: {value!r} is not a number") from None
    if not math.isfinite(x):
        raise GrammarError(f"parameter {key}: the value must be a finite number, got {value!r}")
    return x


def _table_entry(fld: str, size: int) -> bool:
    """Tell whether ``fld`` is ``tJ``, an entry of a table of ``size`` values."""
    return fld.startswith("t") and fld[1:].isdigit() and int(fld[1:]) < size


def _resolve(g: Grammar, key: str) -> tuple[str, int, int, str]:
    """Return ``(owner, case, index, field)`` of a parameter key, checked against ``g``."""
    if key == "m":
        for i, mod in enumerate(g.axiom):
            if isinstance(mod, Symbol) and mod.arg is not None and mod.arg.k1 == 0:
                return "axiom", 0, i, "m"
        raise GrammarError("parameter m: the axiom has no counter argument to set")
    parts = key.split(".")
    if len(parts) == 4 and parts[1].isdigit() and parts[2].isdigit():
        owner, ci, index, fld = parts[0], int(parts[1]), int(parts[2]), parts[3]
        rule = g.rule(owner)
        body = _body(g, owner, ci)
        target = body[index] if index < len(body) else None
        if isinstance(target, Turtle) and (
            fld == "v" or (fld == "dv" and rule is not None and rule.parametric)
        ):
            return owner, ci, index, fld
        if isinstance(target, Turtle) and _table_entry(fld, len(target.value.table)):
            return owner, ci, index, fld
        if isinstance(target, Symbol) and fld == "m" and target.arg is not None and target.arg.k1 == 0:
            return owner, ci, index, fld
    valid = [p.key for p in list_params(g)]
    some = ", ".join(valid[:6]) + (", ..." if len(valid) > 6 else "") if valid else "none"
    raise GrammarError(f"unknown parameter '{key}' (valid keys: {some}; keys are owner.case.index.v|dv|m)")
