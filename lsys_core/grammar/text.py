"""Read and write the ``.lsys`` text format (see ``docs/lsys-format.md``).

>>> g = parse_grammar('lsys 2\\nterminal A "M 0 0 L 1 0"\\naxiom: P(3)\\nP(m): m > 0 -> A f(2) P(m-1)\\n')
>>> print(format_grammar(g), end="")
lsys 2
terminal A "M 0 0 L 1 0"
axiom: P(3)
P(m): m > 0 -> A f(2) P(m-1)

One statement per line: the ``lsys 2`` header, optional ``canvas`` and ``randomize`` lines,
named ``style`` s, ``terminal`` declarations, the ``axiom``, the productions, and optional
``paint:``/``order:`` tables, ``defs`` and ``verbatim`` content.  Every error is a
:class:`~lsys_core.errors.GrammarSyntaxError` carrying the 1-based line and column of the
offending token; problems found by :mod:`.validate` (undefined symbols, arity,
non-termination) are mapped back to the module they concern.  Version-1 files are read
into the current model (their terminals' strokes scale with the turtle, see
:attr:`~lsys_core.grammar.model.Terminal.scaled`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from lsys_core.grammar.edit import rename_symbols
from lsys_core.grammar.lexer import Tok, fail, tokenize
from lsys_core.grammar.model import (
    COND_EQ0,
    COND_GT0,
    Case,
    CaseCondition,
    Grammar,
    Module,
    NamedStyle,
    Randomize,
    Rule,
    Terminal,
    Verbatim,
)
from lsys_core.grammar.reader import LineReader
from lsys_core.grammar.validate import (
    KEYWORDS,
    KEYWORDS_V1,
    RESERVED,
    RESERVED_V1,
    Problem,
    find_problems,
    path_problem,
)
from lsys_core.grammar.writer import FORMAT_VERSION, format_grammar

__all__ = ["FORMAT_VERSION", "TABLE_LIMIT", "format_grammar", "parse_grammar"]

#: Most entries of a ``paint:`` or ``order:`` table.
TABLE_LIMIT = 2_000_000


@dataclass
class _RuleAcc:
    """A rule being collected: its cases in text order, and the line of its first case."""

    parametric: bool
    first: Tok
    cases: list[Case] = field(default_factory=list)


@dataclass
class _State:
    """What the statements read so far declare, and where each piece is in the text."""

    version: int = FORMAT_VERSION
    terminals: dict[str, Terminal] = field(default_factory=dict)
    styles: dict[str, NamedStyle] = field(default_factory=dict)
    rules: dict[str, _RuleAcc] = field(default_factory=dict)
    axiom: tuple[Module, ...] | None = None
    viewbox: tuple[float, float, float, float] | None = None
    size: tuple[str, str] | None = None
    canvas_at: Tok | None = None
    axiom_at: Tok | None = None
    paint: list[str | None] = field(default_factory=list)
    order: list[float] = field(default_factory=list)
    defs: list[str] = field(default_factory=list)
    verbatim: list[Verbatim] = field(default_factory=list)
    randomize: Randomize | None = None
    randomize_at: Tok | None = None
    places: dict[tuple, tuple[int, int]] = field(default_factory=dict)


class _Line(LineReader):
    """Reader of one statement."""

    def __init__(self, toks: list[Tok], state: _State) -> None:
        v1 = state.version == 1
        super().__init__(toks, RESERVED_V1 if v1 else RESERVED, state.places, "f" if v1 else "fz")
        self.st = state
        self.tables = state.version >= 3
        self.stretch = state.version >= 4
        self.keywords = KEYWORDS_V1 if v1 else KEYWORDS

    def header(self) -> None:
        """Read ``lsys VERSION``."""
        first = self.peek()
        if not (first.kind == "name" and first.text == "lsys"):
            raise fail(f"expected the header 'lsys {FORMAT_VERSION}' first, got {first.shown()}", first)
        self.take()
        tok = self.peek()
        if tok.kind != "num":
            raise fail(f"expected a format version after 'lsys', got {tok.shown()}", tok)
        if tok.text not in tuple(str(v) for v in range(1, FORMAT_VERSION + 1)):
            raise fail(
                f"unsupported format version {tok.text}: this program reads versions 1 to {FORMAT_VERSION}",
                tok,
            )
        self.st.version = int(self.take().text)
        self.tables = self.st.version >= 3
        self.stretch = self.st.version >= 4
        self.end()

    def statement(self) -> None:
        """Read one statement after the header."""
        tok = self.peek()
        v2 = self.st.version >= 2
        if tok.kind == "name" and tok.text in ("canvas", "terminal", "axiom"):
            getattr(self, tok.text)()
        elif tok.kind == "name" and tok.text == "randomize" and self.toks[self.i + 1].kind == "name":
            self.randomize()  # a name follows: not a rule called randomize
        elif v2 and tok.kind == "name" and tok.text in ("style", "paint", "order", "defs", "verbatim"):
            getattr(self, f"{tok.text}_statement")()
        elif tok.kind == "name" and tok.text == "lsys":
            raise fail("duplicate header 'lsys'", tok)
        elif tok.kind == "name" and tok.text not in self.keywords:
            self.rule()
        else:
            raise fail(f"unexpected {tok.shown()}: expected a rule, 'terminal', 'axiom' or 'canvas'", tok)
        self.end()

    def canvas(self) -> None:
        """Read ``canvas [viewbox X Y W H] [size "W" "H"]``."""
        kw = self.take()
        if self.st.canvas_at is not None:
            raise fail(f"duplicate canvas line (first on line {self.st.canvas_at.line})", kw)
        self.st.canvas_at = kw
        seen: set[str] = set()
        while self.peek().kind == "name" and self.peek().text in ("viewbox", "size"):
            if self.peek().text in seen:
                raise fail(f"duplicate '{self.peek().text}'", self.peek())
            opt = self.take().text
            seen.add(opt)
            self.places[("canvas", opt)] = self.toks[self.i - 1].pos
            if opt == "viewbox":
                x, y, w, h = (self.signed_number() for _ in range(4))
                self.st.viewbox = (x, y, w, h)
            else:
                self.st.size = (self.string("the width"), self.string("the height"))
        if not seen:
            raise fail(f"expected 'viewbox' or 'size', got {self.peek().shown()}", self.peek())

    def randomize(self) -> None:
        """Read ``randomize [angle A] [distance D] [scale S] [seed N] [jitter instance|cumulative]``."""
        kw = self.take()
        if self.st.version < 2:
            raise fail("the randomize line needs format version 2: write 'lsys 2' as the header", kw)
        if self.st.randomize_at is not None:
            raise fail(f"duplicate randomize line (first on line {self.st.randomize_at.line})", kw)
        self.st.randomize_at = kw
        self.st.randomize = self.randomize_options()

    def terminal(self) -> None:
        """Read ``terminal NAME "PATH" [style "CSS"] [mirror NAME] [scaled]``."""
        self.take()
        tok = self.name("a terminal name")
        if tok.text in self.st.terminals:
            first = self.places[("terminal", tok.text)]
            raise fail(f"duplicate terminal '{tok.text}' (first on line {first[0]})", tok)
        self.places[("terminal", tok.text)] = tok.pos
        self.places[("terminal", tok.text, "path")] = self.peek().pos
        path = self.string("the terminal's SVG path data")
        opts: dict[str, str] = {}
        words = ("style", "mirror") if self.st.version == 1 else ("style", "mirror", "scaled")
        while self.peek().kind == "name" and self.peek().text in words:
            opt = self.take()
            if opt.text in opts:
                raise fail(f"duplicate '{opt.text}'", opt)
            if opt.text == "style":
                opts["style"] = self.string("the CSS style")
            elif opt.text == "scaled":
                opts["scaled"] = ""
            else:
                self.places[("terminal", tok.text, True)] = self.peek().pos
                opts["mirror"] = self.name("a terminal name").text
        scaled = "scaled" in opts or self.st.version == 1
        self.st.terminals[tok.text] = Terminal(
            tok.text, path, opts.get("style", ""), opts.get("mirror"), scaled
        )

    def style_statement(self) -> None:
        """Read ``style NAME "CSS"``."""
        self.take()
        tok = self.name("a style name")
        if tok.text in self.st.styles:
            first = self.places[("style", tok.text)]
            raise fail(f"duplicate style '{tok.text}' (first on line {first[0]})", tok)
        self.places[("style", tok.text)] = tok.pos
        self.st.styles[tok.text] = NamedStyle(tok.text, self.string("the CSS declarations"))

    def paint_statement(self) -> None:
        """Read ``paint: ITEM ...`` with items ``NAME``, ``NAME*k``, ``-`` and ``-*k``."""
        kw = self.take()
        self.expect(":", "':' after 'paint'")
        self.places.setdefault(("paint",), kw.pos)
        while self.peek().kind != "eol":
            tok = self.peek()
            if self.at("-"):
                self.take()
                value = None
            else:
                value = self.name("a style name or '-'").text
                self.places.setdefault(("paint", value), tok.pos)
            self._extend(self.st.paint, value, tok)

    def order_statement(self) -> None:
        """Read ``order: ITEM ...`` with items ``N``, ``N*k`` and ``A..B`` (whole numbers A to B)."""
        kw = self.take()
        self.expect(":", "':' after 'order'")
        self.places.setdefault(("order",), kw.pos)
        while self.peek().kind != "eol":
            tok = self.peek()
            if tok.kind == "range":
                a, b = (int(x) for x in self.take().text.split(".."))
                step = 1 if b >= a else -1
                if len(self.st.order) + abs(b - a) + 1 > TABLE_LIMIT:
                    raise fail(f"table too long (more than {TABLE_LIMIT:,} entries)", tok)
                self.st.order.extend(float(v) for v in range(a, b + step, step))
            else:
                self._extend(self.st.order, self.signed_number(), tok)

    def _extend(self, table: list, value: object, tok: Tok) -> None:
        """Append ``value`` once, or ``k`` times for a following ``*k``."""
        k = 1
        if self.at("*"):
            self.take()
            k = self.integer("a repeat count")
        if len(table) + k > TABLE_LIMIT:
            raise fail(f"table too long (more than {TABLE_LIMIT:,} entries)", tok)
        table.extend([value] * k)

    def defs_statement(self) -> None:
        """Read ``defs "MARKUP"`` (several lines are joined)."""
        self.take()
        self.st.defs.append(self.string("the SVG markup"))

    def verbatim_statement(self) -> None:
        """Read ``verbatim N "MARKUP" [what "TEXT"]``."""
        self.take()
        at = self.integer("the number of instances drawn before it")
        xml = self.string("the SVG markup")
        what = ""
        if self.at("what", "name"):
            self.take()
            what = self.string("a description")
        self.st.verbatim.append(Verbatim(at, xml, what))

    def axiom(self) -> None:
        """Read ``axiom: BODY``."""
        kw = self.take()
        if self.st.axiom_at is not None:
            raise fail(f"duplicate axiom (first on line {self.st.axiom_at.line})", kw)
        self.st.axiom_at = kw
        if self.at(":"):
            self.take()
        body = self.body("axiom", 0, None)
        if not body:
            raise fail("empty axiom: give a start, e.g. 'axiom: P(10)'", kw)
        self.st.axiom = body

    def rule(self) -> None:
        """Read ``NAME[(m)] [: m > 0 | : m == 0] -> BODY``."""
        tok = self.name("a rule name")
        parametric = self.at("(")
        if parametric:
            self.take()
            if not self.at("m", "name"):
                raise fail(f"the counter of a rule is written m, got {self.peek().shown()}", self.peek())
            self.take()
            self.expect(")")
        acc = self.st.rules.setdefault(tok.text, _RuleAcc(parametric, tok))
        if acc.parametric != parametric:
            form = f"{tok.text}(m)" if acc.parametric else tok.text
            raise fail(
                f"rule {tok.text} is written {form} on line {acc.first.line}; write it the same way", tok
            )
        cond = None
        if self.at(":"):
            colon = self.take()
            if not parametric:
                raise fail(f"rule {tok.text} has no counter: write {tok.text}(m) to use a condition", colon)
            cond = self.condition()
        if self.peek().kind != "arrow":
            raise fail(f"expected '->', got {self.peek().shown()}", self.peek())
        self.take()
        ci = len(acc.cases)
        self.places[("rule", tok.text, ci, None, False)] = tok.pos
        acc.cases.append(Case(cond, self.body(tok.text, ci, parametric)))

    def condition(self) -> CaseCondition:
        """Read ``m > 0`` or ``m == 0``."""
        toks = []
        for ok in (lambda t: t.text == "m", lambda t: t.text in (">", "=="), lambda t: t.text == "0"):
            tok = self.peek()
            if tok.kind == "eol" or not ok(tok):
                raise fail(f"expected a condition 'm > 0' or 'm == 0', got {tok.shown()}", tok)
            toks.append(self.take())
        return COND_GT0 if toks[1].text == ">" else COND_EQ0


def parse_grammar(text: str, *, check_paths: bool = False) -> Grammar:
    """Parse ``.lsys`` text into a validated :class:`~lsys_core.grammar.model.Grammar`.

    Parameters
    ----------
    text : str
        The whole file, starting with the ``lsys 2`` (or ``lsys 1``) header; comments may come first.
    check_paths : bool
        Also require every terminal's path data to parse with finite coordinates
        (see :func:`~lsys_core.grammar.validate.path_problem`); by default path data
        is kept as given.

    Returns
    -------
    Grammar
        Rules grouped by name in order of first appearance, cases in text order;
        ``comments`` holds the comments that come before the first statement.

    Raises
    ------
    GrammarSyntaxError
        For the first problem in text order, with its 1-based line and column: syntax,
        undefined symbol or style, duplicate terminal, wrong arity, ``m`` where there is no
        counter, non-finite number, missing axiom, non-terminating rule, non-positive scale.
    """
    lines, comments, end = tokenize(text)
    if not lines:
        raise fail(f"missing header 'lsys {FORMAT_VERSION}'", (1, 1))
    st = _State()
    _Line(lines[0], st).header()
    for toks in lines[1:]:
        _Line(toks, st).statement()
    if st.axiom is None:
        raise fail("missing axiom: add a line 'axiom: ...'", end)
    g = Grammar(
        terminals=tuple(st.terminals.values()),
        rules=tuple(Rule(name, acc.parametric, tuple(acc.cases)) for name, acc in st.rules.items()),
        axiom=st.axiom,
        viewbox=st.viewbox,
        size=st.size,
        comments=tuple(c for line, c in comments if len(lines) < 2 or line < lines[1][0].line),
        defs="\n".join(st.defs),
        verbatim=tuple(st.verbatim),
        styles=tuple(st.styles.values()),
        paint=tuple(st.paint),
        order=tuple(st.order),
        randomize=st.randomize,
    )
    if st.version == 1:
        g = _rename_reserved(g)
    problems = find_problems(g)
    if problems:
        first = min(problems, key=lambda p: _place(p, st, end))
        raise fail(first.message, _place(first, st, end))
    if check_paths:
        for t in g.terminals:
            if (why := path_problem(t.path)) is not None:
                raise fail(f"terminal {t.name}: {why}", st.places[("terminal", t.name, "path")])
    return g


def _rename_reserved(g: Grammar) -> Grammar:
    """Rename version-1 symbols whose names the current version reserves (``z`` becomes ``z_``)."""
    names = {t.name for t in g.terminals} | {r.name for r in g.rules}
    new: dict[str, str] = {}
    for old in sorted(names & (RESERVED - RESERVED_V1)):
        cand = old + "_"
        while cand in names or cand in new.values():
            cand += "_"
        new[old] = cand
    return rename_symbols(g, new)


def _place(p: Problem, st: _State, end: tuple[int, int]) -> tuple[int, int]:
    """Return the ``(line, column)`` a validation problem refers to."""
    places = st.places
    if p.where in ("rule", "axiom") and p.index is not None:
        key = (p.where, p.owner, p.case, p.index)
        found = places.get((*key, p.arg)) or places.get((*key, False))
    elif p.where == "rule":
        found = places.get(("rule", p.owner, p.case or 0, None, False))
    elif p.where == "terminal":
        found = places.get(("terminal", p.owner, p.arg)) or places.get(("terminal", p.owner))
    elif p.where == "axiom" and st.axiom_at is not None:
        found = st.axiom_at.pos
    elif p.where == "style":
        found = places.get(("style", p.owner))
    elif p.where == "table":
        found = places.get(("paint", p.owner)) or places.get((p.owner,))
    else:
        found = places.get(("canvas", p.owner))
    return found or end
