"""Write a :class:`~lsys_core.grammar.model.Grammar` as ``.lsys`` text (see ``docs/lsys-format.md``)."""

from __future__ import annotations

from lsys_core.grammar.lexer import quote
from lsys_core.grammar.model import Grammar, Linear, Module, Paint, Pop, Push, Randomize, Symbol, Turtle
from lsys_core.grammar.validate import count_text

__all__ = ["FORMAT_VERSION", "format_grammar", "format_number", "format_version"]

FORMAT_VERSION = 4
"""The newest format version (versions 1 to 3 are read too).  A grammar is written in the oldest
version that expresses it: see :func:`format_version`."""

#: Table items per line of a ``paint:`` or ``order:`` statement (a continued statement repeats its keyword).
TABLE_ITEMS_PER_LINE = 40


def format_grammar(g: Grammar) -> str:
    """Write ``g`` as ``.lsys`` text; :func:`~lsys_core.grammar.text.parse_grammar` reads it back equal.

    Parameters
    ----------
    g : Grammar
        Any grammar; it is written as is, even if invalid.

    Returns
    -------
    str
        Header, comments, canvas, the ``randomize`` line, named styles, terminals, axiom, one line per production, then
        the per-instance tables, the defs and the verbatim content; each line ends with a newline.
        Formatting parsed text again gives the same text.
    """
    version = format_version(g)
    out = [f"lsys {version}"]
    for c in g.comments:
        out += [f"# {part}".rstrip() for part in (c.splitlines() or [""])]
    canvas = []
    if g.viewbox is not None:
        canvas.append("viewbox " + " ".join(format_number(v) for v in g.viewbox))
    if g.size is not None:
        canvas.append(f"size {quote(g.size[0])} {quote(g.size[1])}")
    if canvas:
        out.append("canvas " + " ".join(canvas))
    if g.randomize is not None:
        out.append(_randomize_line(g.randomize))
    out += [f"style {s.name} {quote(s.css)}" for s in g.styles]
    for t in g.terminals:
        line = f"terminal {t.name} {quote(t.path)}"
        if t.style:
            line += f" style {quote(t.style)}"
        if t.mirror_of is not None:
            line += f" mirror {t.mirror_of}"
        if t.scaled and version >= 2:
            line += " scaled"
        out.append(line)
    out.append(f"axiom: {_body(g.axiom)}")
    for r in g.rules:
        head = f"{r.name}(m)" if r.parametric else r.name
        for case in r.cases:
            cond = f": {case.cond}" if case.cond is not None else ""
            out.append(f"{head}{cond} -> {_body(case.body)}")
    out += _table("paint", _paint_items(g.paint))
    out += _table("order", _order_items(g.order))
    if g.defs:
        out.append(f"defs {quote(g.defs)}")
    for v in g.verbatim:
        line = f"verbatim {v.order} {quote(v.xml)}"
        out.append(line + (f" what {quote(v.what)}" if v.what else ""))
    return "\n".join(out) + "\n"


def format_version(g: Grammar) -> int:
    """Return the oldest format version that expresses ``g``.

    Version 1 holds a grammar whose terminals all scale their strokes with the turtle
    (:attr:`~lsys_core.grammar.model.Terminal.scaled`, version 1's meaning) and that uses nothing
    version 2 added: named styles, occurrence paints, ``z``, the ``paint:``/``order:`` tables,
    ``defs``, ``verbatim`` content and the ``randomize`` line.  So a version-1 file stays
    readable by version-1 readers after it is edited and saved.  Version 3 added table values
    ``[v0, v1, ...]``; a grammar without them is written in version 2 or 1.  Version 4 added
    the stretch command ``~(t)``.
    """
    stretch = table = modules_v2 = False
    for body in [g.axiom] + [c.body for r in g.rules for c in r.cases]:  # one pass over the modules
        for m in body:
            if isinstance(m, Turtle):
                stretch = stretch or m.op == "~"
                table = table or bool(m.value.table)
                modules_v2 = modules_v2 or m.op == "z"
            elif isinstance(m, Symbol) and m.paint is not None:
                modules_v2 = True
    if stretch:
        return 4
    if table:
        return 3
    v2 = (
        modules_v2
        or g.randomize is not None
        or bool(g.styles or g.paint or g.order or g.defs or g.verbatim)
        or not all(t.scaled for t in g.terminals)
    )
    return 2 if v2 else 1


def _randomize_line(r: Randomize) -> str:
    """Return the ``randomize`` line: the non-zero amounts, the seed and the jitter."""
    amounts = [f"{k} {format_number(getattr(r, k))}" for k in ("angle", "distance", "scale") if getattr(r, k)]
    return " ".join(["randomize", *amounts, f"seed {int(r.seed)}", f"jitter {r.jitter}"])


def _table(keyword: str, items: list[str]) -> list[str]:
    """Return the lines of a per-instance table, :data:`TABLE_ITEMS_PER_LINE` items each."""
    return [
        f"{keyword}: " + " ".join(items[i : i + TABLE_ITEMS_PER_LINE])
        for i in range(0, len(items), TABLE_ITEMS_PER_LINE)
    ]


def _runs(values: tuple) -> list[tuple[object, int]]:
    """Return ``(value, count)`` of the runs of equal consecutive values."""
    out: list[tuple[object, int]] = []
    for v in values:
        if out and out[-1][0] == v:
            out[-1] = (v, out[-1][1] + 1)
        else:
            out.append((v, 1))
    return out


def _paint_items(paint: tuple[str | None, ...]) -> list[str]:
    """Return ``s1``, ``s2*4``, ``-`` items of a paint table."""
    return [(str(v) if v else "-") + (f"*{k}" if k > 1 else "") for v, k in _runs(paint)]


def _order_items(order: tuple[float, ...]) -> list[str]:
    """Return ``7``, ``0..9``, ``3*4`` items of an order table (runs of consecutive integers as ranges)."""
    out: list[str] = []
    i, n = 0, len(order)
    while i < n:
        v = order[i]
        j = i + 1
        if float(v).is_integer() and v >= 0:
            step = order[j] - v if j < n else 0
            if step in (1, -1):
                while j < n and order[j] - order[j - 1] == step and order[j] >= 0:
                    j += 1
                if j - i >= 3:
                    out.append(f"{int(v)}..{int(order[j - 1])}")
                    i = j
                    continue
                j = i + 1
        while j < n and order[j] == v:
            j += 1
        out.append(format_number(v) + (f"*{j - i}" if j - i > 1 else ""))
        i = j
    return out


def _body(body: tuple[Module, ...]) -> str:
    """Return a production's right-hand side, ``ε`` when empty."""
    return " ".join(_module(mod) for mod in body) or "ε"


def _module(mod: Module) -> str:
    """Return one module as text."""
    if isinstance(mod, Push):
        return "["
    if isinstance(mod, Pop):
        return "]"
    if isinstance(mod, Turtle):
        return f"{mod.op}({_linear(mod.value)})"
    text = mod.name if mod.arg is None else f"{mod.name}({count_text(mod.arg)})"
    return text + _paint(mod.paint) if mod.paint is not None else text


def _paint(p: Paint) -> str:
    """Return ``{s1, opacity: 0.5}``."""
    items = ([p.style] if p.style else []) + [f"{k}: {_linear(v)}" for k, v in p.props]
    return "{" + ", ".join(items) + "}"


def format_number(x: float) -> str:
    """Return the shortest round-trip text of ``x`` without a trailing ``.0`` (``-0`` is ``0``)."""
    x = float(x)
    if x == 0:
        return "0"
    s = repr(x)
    return s[:-2] if s.endswith(".0") else s


def _linear(v: Linear) -> str:
    """Return ``c0``, ``c0 + cd*m``, ``c0 - cd*m``, ``cd*m`` or a table ``[v0, v1, ...]``."""
    if v.table:
        return "[" + ", ".join(format_number(x) for x in v.table) + "]"
    if v.cd == 0:
        return format_number(v.c0)
    mag = abs(float(v.cd))
    term = "m" if mag == 1 else f"{format_number(mag)}*m"
    if v.c0 == 0:
        return term if v.cd > 0 else f"-{term}"
    return f"{format_number(v.c0)} {'+' if v.cd > 0 else '-'} {term}"
