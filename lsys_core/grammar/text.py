"""Read and write the ``.lsys`` text format (see ``docs/lsys-format.md``).

>>> g = parse_grammar('lsys 1\\nterminal A "M 0 0 L 1 0"\\naxiom: P(3)\\nP(m): m > 0 -> A f(2) P(m-1)\\n')
>>> print(format_grammar(g), end="")
lsys 1
terminal A "M 0 0 L 1 0"
axiom: P(3)
P(m): m > 0 -> A f(2) P(m-1)

One statement per line: the ``lsys 1`` header, an optional ``canvas`` line,
``terminal`` declarations, the ``axiom`` and the productions.  Every error is a
:class:`~lsys_core.errors.GrammarSyntaxError` carrying the 1-based line and column of the
offending token; problems found by :mod:`.validate` (undefined symbols, arity,
non-termination) are mapped back to the module they concern.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import NamedTuple

from lsys_core.errors import GrammarSyntaxError
from lsys_core.grammar.model import (
    COND_EQ0,
    COND_GT0,
    JITTERS,
    Case,
    CaseCondition,
    Count,
    Grammar,
    Linear,
    Module,
    Pop,
    Push,
    Randomize,
    Rule,
    Symbol,
    Terminal,
    Turtle,
    TurtleOp,
)
from lsys_core.grammar.validate import KEYWORDS, RESERVED, Problem, count_text, find_problems, path_problem

__all__ = ["FORMAT_VERSION", "format_grammar", "parse_grammar"]

FORMAT_VERSION = 2
"""The newest format version: version 2 adds the ``randomize`` line to version 1.

A file is written in the oldest version that can express it (``lsys 1`` unless it has a
``randomize`` line), so files without one stay readable by version-1 readers."""
_VERSIONS = ("1", "2")
#: Seeds are stored as written; beyond this they would not survive a round trip through floats.
SEED_LIMIT = 2**53

_TOKEN = re.compile(
    r"""
      (?P<ws>[^\S\r\n]+)
    | (?P<nl>\r\n|\n|\r)
    | (?P<comment>\#[^\r\n]*)
    | (?P<str>"(?:[^"\\\r\n]|\\[^\r\n])*")
    | (?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)
    | (?P<name>[A-Za-z_][A-Za-z0-9_]*)
    | (?P<arrow>->|→)
    | (?P<punct>==|[-−+*∗()\[\]:>])
    | (?P<eps>ε)
    """,
    re.VERBOSE,
)
_NUMBER_TAIL = re.compile(r"[A-Za-z0-9_.]+")
_ESCAPE = re.compile(r"\\(.)", re.DOTALL)
_ESCAPES = {"\\": "\\", '"': '"', "n": "\n", "r": "\r", "t": "\t"}
_QUOTING = str.maketrans({v: "\\" + k for k, v in _ESCAPES.items()})
_NON_FINITE = frozenset({"nan", "inf", "infinity"})
_UNICODE_OPS = {"−": "-", "∗": "*"}  # the paper's minus and asterisk, as pasted from a PDF
_TURTLE_OPS: dict[str, TurtleOp] = {"f": "f", "+": "+", "-": "-", "*": "*"}


class _Tok(NamedTuple):
    """A token: kind (``num``, ``name``, ``str``, ``arrow``, ``eps``, ``punct``, ``eol``), text, position."""

    kind: str
    text: str
    line: int
    col: int

    @property
    def pos(self) -> tuple[int, int]:
        """Return ``(line, column)``."""
        return self.line, self.col

    def shown(self) -> str:
        """Return the token as it reads in a message."""
        return "end of line" if self.kind == "eol" else f"'{self.text}'"


def _fail(message: str, at: _Tok | tuple[int, int]) -> GrammarSyntaxError:
    """Return the syntax error ``message`` at a token or ``(line, column)``."""
    line, col = at.pos if isinstance(at, _Tok) else at
    return GrammarSyntaxError(message, line, col)


def _tokenize(text: str) -> tuple[list[list[_Tok]], list[tuple[int, str]], tuple[int, int]]:
    """Split ``text`` into non-empty lines of tokens, each ending with an ``eol`` token.

    Returns
    -------
    lines : list of list of _Tok
    comments : list of tuple
        ``(line, text)`` of each comment, without ``#`` and surrounding blanks.
    end : tuple of int
        ``(line, column)`` just past the end of the text.
    """
    lines: list[list[_Tok]] = []
    comments: list[tuple[int, str]] = []
    current: list[_Tok] = []
    line, line_start, pos = 1, 0, 0
    if text.startswith("\ufeff"):
        pos = line_start = 1
    while pos < len(text):
        mt = _TOKEN.match(text, pos)
        col = pos - line_start + 1
        if mt is None:
            if text[pos] == '"':
                raise _fail("unterminated string: add the closing '\"'", (line, col))
            raise _fail(f"unexpected character {text[pos]!r}", (line, col))
        kind, raw = mt.lastgroup, mt.group()
        assert kind is not None  # every alternative of _TOKEN is a named group
        pos = mt.end()
        if kind == "nl":
            if current:
                lines.append([*current, _Tok("eol", "", line, col)])
            current = []
            line, line_start = line + 1, pos
        elif kind == "comment":
            comments.append((line, raw[1:].strip()))
        elif kind == "num" and (tail := _NUMBER_TAIL.match(text, pos)):
            raise _fail(f"bad number '{raw + tail.group()}'", (line, col))
        elif kind == "str":
            current.append(_Tok("str", _unescape(raw, line, col), line, col))
        elif kind != "ws":
            current.append(_Tok(kind, _UNICODE_OPS.get(raw, raw), line, col))
    end = (line, pos - line_start + 1)
    if current:
        lines.append([*current, _Tok("eol", "", *end)])
    return lines, comments, end


def _unescape(raw: str, line: int, col: int) -> str:
    """Return the value of a quoted string token, resolving ``\\\\ \\" \\n \\r \\t``."""
    inner = raw[1:-1]
    if "\\" not in inner:
        return inner

    def resolve(mt: re.Match) -> str:
        esc = _ESCAPES.get(mt.group(1))
        if esc is None:
            where = (line, col + 1 + mt.start())
            raise _fail(f"unknown escape '\\{mt.group(1)}' in string (use \\\\ for a backslash)", where)
        return esc

    return _ESCAPE.sub(resolve, inner)


@dataclass
class _RuleAcc:
    """A rule being collected: its cases in text order, and the line of its first case."""

    parametric: bool
    first: _Tok
    cases: list[Case] = field(default_factory=list)


@dataclass
class _State:
    """What the statements read so far declare, and where each piece is in the text."""

    terminals: dict[str, Terminal] = field(default_factory=dict)
    rules: dict[str, _RuleAcc] = field(default_factory=dict)
    axiom: tuple[Module, ...] | None = None
    viewbox: tuple[float, float, float, float] | None = None
    size: tuple[str, str] | None = None
    canvas_at: _Tok | None = None
    axiom_at: _Tok | None = None
    version: int = 1
    randomize: Randomize | None = None
    randomize_at: _Tok | None = None
    places: dict[tuple, tuple[int, int]] = field(default_factory=dict)


class _Line:
    """Recursive-descent reader of one statement (one line of tokens)."""

    def __init__(self, toks: list[_Tok], state: _State) -> None:
        self.toks = toks
        self.i = 0
        self.st = state

    def peek(self) -> _Tok:
        """Return the current token without consuming it."""
        return self.toks[self.i]

    def take(self) -> _Tok:
        """Consume and return the current token (the final ``eol`` is never passed)."""
        tok = self.toks[self.i]
        if tok.kind != "eol":
            self.i += 1
        return tok

    def at(self, text: str, kind: str = "punct") -> bool:
        """Tell whether the current token is ``text`` of ``kind``."""
        tok = self.peek()
        return tok.kind == kind and tok.text == text

    def expect(self, text: str, what: str | None = None, kind: str = "punct") -> _Tok:
        """Consume the token ``text`` or fail with "expected ...", naming what was found."""
        if not self.at(text, kind):
            raise _fail(f"expected {what or repr(text)}, got {self.peek().shown()}", self.peek())
        return self.take()

    def end(self) -> None:
        """Fail unless the line is finished."""
        if self.peek().kind != "eol":
            raise _fail(f"unexpected {self.peek().shown()}: expected end of line", self.peek())

    def name(self, what: str) -> _Tok:
        """Consume a symbol name, refusing reserved words."""
        tok = self.peek()
        if tok.kind != "name":
            raise _fail(f"expected {what}, got {tok.shown()}", tok)
        if tok.text in RESERVED:
            raise _fail(f"'{tok.text}' is reserved and cannot name a symbol", tok)
        return self.take()

    def string(self, what: str) -> str:
        """Consume a quoted string."""
        if self.peek().kind != "str":
            raise _fail(f"expected {what} as a quoted string, got {self.peek().shown()}", self.peek())
        return self.take().text

    # -- statements -------------------------------------------------------------------------------

    def header(self) -> None:
        """Read ``lsys VERSION``."""
        first = self.peek()
        if not (first.kind == "name" and first.text == "lsys"):
            raise _fail(f"expected the header 'lsys {FORMAT_VERSION}' first, got {first.shown()}", first)
        self.take()
        tok = self.peek()
        if tok.kind != "num":
            raise _fail(f"expected a format version after 'lsys', got {tok.shown()}", tok)
        if tok.text not in _VERSIONS:
            raise _fail(
                f"unsupported format version {tok.text}: this program reads versions 1 to {FORMAT_VERSION}",
                tok,
            )
        self.st.version = int(self.take().text)
        self.end()

    def statement(self) -> None:
        """Read one statement after the header."""
        tok = self.peek()
        if tok.kind == "name" and tok.text in ("canvas", "terminal", "axiom"):
            getattr(self, tok.text)()
        elif tok.kind == "name" and tok.text == "randomize" and self.toks[self.i + 1].kind == "name":
            self.randomize()  # a name follows: not a rule called randomize
        elif tok.kind == "name" and tok.text == "lsys":
            raise _fail("duplicate header 'lsys'", tok)
        elif tok.kind == "name" and tok.text not in KEYWORDS:
            self.rule()
        else:
            raise _fail(f"unexpected {tok.shown()}: expected a rule, 'terminal', 'axiom' or 'canvas'", tok)
        self.end()

    def canvas(self) -> None:
        """Read ``canvas [viewbox X Y W H] [size "W" "H"]``."""
        kw = self.take()
        if self.st.canvas_at is not None:
            raise _fail(f"duplicate canvas line (first on line {self.st.canvas_at.line})", kw)
        self.st.canvas_at = kw
        seen: set[str] = set()
        while self.peek().kind == "name" and self.peek().text in ("viewbox", "size"):
            if self.peek().text in seen:
                raise _fail(f"duplicate '{self.peek().text}'", self.peek())
            opt = self.take().text
            seen.add(opt)
            self.st.places[("canvas", opt)] = self.toks[self.i - 1].pos
            if opt == "viewbox":
                x, y, w, h = (self.signed_number() for _ in range(4))
                self.st.viewbox = (x, y, w, h)
            else:
                self.st.size = (self.string("the width"), self.string("the height"))
        if not seen:
            raise _fail(f"expected 'viewbox' or 'size', got {self.peek().shown()}", self.peek())

    def randomize(self) -> None:
        """Read ``randomize [angle A] [distance D] [scale S] [seed N] [jitter instance|cumulative]``."""
        kw = self.take()
        if self.st.version < 2:
            raise _fail("the randomize line needs format version 2: write 'lsys 2' as the header", kw)
        if self.st.randomize_at is not None:
            raise _fail(f"duplicate randomize line (first on line {self.st.randomize_at.line})", kw)
        self.st.randomize_at = kw
        opts: dict[str, float | str] = {}
        names = ("angle", "distance", "scale", "seed", "jitter")
        while self.peek().kind == "name" and self.peek().text in names:
            opt = self.take()
            if opt.text in opts:
                raise _fail(f"duplicate '{opt.text}'", opt)
            tok = self.peek()
            if opt.text == "jitter":
                if tok.kind != "name" or tok.text not in JITTERS:
                    raise _fail(f"expected 'instance' or 'cumulative' after 'jitter', got {tok.shown()}", tok)
                opts["jitter"] = self.take().text
                continue
            value = self.signed_number()
            if value < 0 or (opt.text == "seed" and (not value.is_integer() or value >= SEED_LIMIT)):
                what = "a whole number >= 0" if opt.text == "seed" else "a number >= 0"
                raise _fail(f"{opt.text} must be {what}, got {value:g}", tok)
            opts[opt.text] = value
        if not opts:
            raise _fail(f"expected one of {', '.join(names)}, got {self.peek().shown()}", self.peek())
        seed = int(opts.pop("seed", 0))
        self.st.randomize = Randomize(seed=seed, **opts)  # type: ignore[arg-type]

    def terminal(self) -> None:
        """Read ``terminal NAME "PATH" [style "CSS"] [mirror NAME]``."""
        self.take()
        tok = self.name("a terminal name")
        if tok.text in self.st.terminals:
            first = self.st.places[("terminal", tok.text)]
            raise _fail(f"duplicate terminal '{tok.text}' (first on line {first[0]})", tok)
        self.st.places[("terminal", tok.text)] = tok.pos
        self.st.places[("terminal", tok.text, "path")] = self.peek().pos
        path = self.string("the terminal's SVG path data")
        opts: dict[str, str] = {}
        while self.peek().kind == "name" and self.peek().text in ("style", "mirror"):
            opt = self.take()
            if opt.text in opts:
                raise _fail(f"duplicate '{opt.text}'", opt)
            if opt.text == "style":
                opts["style"] = self.string("the CSS style")
            else:
                self.st.places[("terminal", tok.text, True)] = self.peek().pos
                opts["mirror"] = self.name("a terminal name").text
        self.st.terminals[tok.text] = Terminal(tok.text, path, opts.get("style", ""), opts.get("mirror"))

    def axiom(self) -> None:
        """Read ``axiom: BODY``."""
        kw = self.take()
        if self.st.axiom_at is not None:
            raise _fail(f"duplicate axiom (first on line {self.st.axiom_at.line})", kw)
        self.st.axiom_at = kw
        if self.at(":"):
            self.take()
        body = self.body("axiom", 0, None)
        if not body:
            raise _fail("empty axiom: give a start, e.g. 'axiom: P(10)'", kw)
        self.st.axiom = body

    def rule(self) -> None:
        """Read ``NAME[(m)] [: m > 0 | : m == 0] -> BODY``."""
        tok = self.name("a rule name")
        parametric = self.at("(")
        if parametric:
            self.take()
            if not self.at("m", "name"):
                raise _fail(f"the counter of a rule is written m, got {self.peek().shown()}", self.peek())
            self.take()
            self.expect(")")
        acc = self.st.rules.setdefault(tok.text, _RuleAcc(parametric, tok))
        if acc.parametric != parametric:
            form = f"{tok.text}(m)" if acc.parametric else tok.text
            raise _fail(
                f"rule {tok.text} is written {form} on line {acc.first.line}; write it the same way", tok
            )
        cond = None
        if self.at(":"):
            colon = self.take()
            if not parametric:
                raise _fail(f"rule {tok.text} has no counter: write {tok.text}(m) to use a condition", colon)
            cond = self.condition()
        if self.peek().kind != "arrow":
            raise _fail(f"expected '->', got {self.peek().shown()}", self.peek())
        self.take()
        ci = len(acc.cases)
        self.st.places[("rule", tok.text, ci, None, False)] = tok.pos
        acc.cases.append(Case(cond, self.body(tok.text, ci, parametric)))

    def condition(self) -> CaseCondition:
        """Read ``m > 0`` or ``m == 0``."""
        toks = []
        for ok in (lambda t: t.text == "m", lambda t: t.text in (">", "=="), lambda t: t.text == "0"):
            tok = self.peek()
            if tok.kind == "eol" or not ok(tok):
                raise _fail(f"expected a condition 'm > 0' or 'm == 0', got {tok.shown()}", tok)
            toks.append(self.take())
        return COND_GT0 if toks[1].text == ">" else COND_EQ0

    # -- bodies -----------------------------------------------------------------------------------

    def body(self, owner: str, ci: int, parametric: bool | None) -> tuple[Module, ...]:
        """Read modules up to the end of the line; ``parametric`` is None for the axiom."""
        tok = self.peek()
        if tok.kind == "eps" or (tok.kind == "name" and tok.text == "eps"):
            self.take()
            self.end()
            return ()
        if parametric:
            no_m = None
        elif parametric is None:
            no_m = "m cannot be used in the axiom"
        else:
            no_m = f"m cannot be used in rule {owner}, which has no counter (declare {owner}(m))"
        where = "axiom" if parametric is None else "rule"
        mods: list[Module] = []
        opens: list[_Tok] = []
        while (tok := self.peek()).kind != "eol":
            self.st.places[(where, owner, ci, len(mods), False)] = tok.pos
            if tok.kind == "punct" and tok.text in "[]":
                if tok.text == "]" and not opens:
                    raise _fail("unbalanced ']': no '[' to close", tok)
                if tok.text == "[":
                    opens.append(tok)
                    mods.append(Push())
                else:
                    opens.pop()
                    mods.append(Pop())
                self.take()
            elif (tok.kind == "punct" and tok.text in "+-*") or (tok.kind == "name" and tok.text == "f"):
                self.take()
                self.expect("(", f"'(' after '{tok.text}'")
                self.st.places[(where, owner, ci, len(mods), True)] = self.peek().pos
                mods.append(Turtle(_TURTLE_OPS[tok.text], self.linear(no_m)))
                self.expect(")")
            elif tok.kind == "name" and tok.text == "m":
                raise _fail("m is the counter: use it in an argument, e.g. P(m-1) or f(2*m)", tok)
            elif tok.kind == "eps" or (tok.kind == "name" and tok.text == "eps"):
                raise _fail("ε stands alone for an empty body", tok)
            elif tok.kind == "name":
                self.name("a symbol")
                arg = None
                if self.at("("):
                    self.take()
                    self.st.places[(where, owner, ci, len(mods), True)] = self.peek().pos
                    arg = self.count(no_m)
                    self.expect(")")
                mods.append(Symbol(tok.text, arg))
            else:
                raise _fail(f"unexpected {tok.shown()}: expected a module", tok)
        if opens:
            raise _fail("unbalanced '[': no ']' closes it", opens[-1])
        return tuple(mods)

    def terms(self, no_m: str | None) -> list[tuple[int, _Tok | None, _Tok | None]]:
        """Read ``[±] term {± term}`` with terms ``N``, ``N*m``, ``m``, ``m*N``; return (sign, number, m)."""
        out = []
        while True:
            sign = 1
            while self.peek().kind == "punct" and self.peek().text in "+-":
                sign = -sign if self.take().text == "-" else sign
            tok = self.peek()
            if tok.kind == "name" and tok.text in _NON_FINITE:
                raise _fail(f"non-finite number '{tok.text}'", tok)
            num = m = None
            if tok.kind == "num":
                num = self.take()
                if self.at("*"):
                    self.take()
                    m = self.expect("m", "'m' after '*'", "name")
            elif tok.kind == "name" and tok.text == "m":
                m = self.take()
                if self.at("*"):
                    self.take()
                    if self.peek().kind != "num":
                        raise _fail(f"expected a number after '*', got {self.peek().shown()}", self.peek())
                    num = self.take()
            else:
                raise _fail(f"expected a number, got {tok.shown()}", tok)
            if m is not None and no_m is not None:
                raise _fail(no_m, m)
            out.append((sign, num, m))
            if not (self.peek().kind == "punct" and self.peek().text in "+-"):
                return out

    def linear(self, no_m: str | None) -> Linear:
        """Read a value ``c0 + cd*m`` (any sum of such terms)."""
        start = self.peek()
        c0 = cd = 0.0
        for sign, num, m in self.terms(no_m):
            v = sign * (_number(num) if num is not None else 1.0)
            if m is None:
                c0 += v
            else:
                cd += v
        if not (math.isfinite(c0) and math.isfinite(cd)):
            raise _fail("value out of range (not a finite number)", start)
        return Linear(c0, cd)

    def count(self, no_m: str | None) -> Count:
        """Read an integer counter argument ``k0 + k1*m``."""
        k0 = k1 = 0
        for sign, num, m in self.terms(no_m):
            if num is not None and not num.text.isdigit():
                raise _fail(f"counter arguments are whole numbers, got '{num.text}'", num)
            if num is not None and len(num.text) > 18:
                raise _fail(f"counter argument out of range '{num.text}'", num)
            v = sign * (int(num.text) if num is not None else 1)
            if m is None:
                k0 += v
            else:
                k1 += v
        return Count(k0, k1)

    def signed_number(self) -> float:
        """Read a number with an optional sign."""
        sign = -1.0 if self.at("-") else 1.0
        if self.at("-") or self.at("+"):
            self.take()
        tok = self.peek()
        if tok.kind == "name" and tok.text in _NON_FINITE:
            raise _fail(f"non-finite number '{tok.text}'", tok)
        if tok.kind != "num":
            raise _fail(f"expected a number, got {tok.shown()}", tok)
        return sign * _number(self.take())


def _number(tok: _Tok) -> float:
    """Return the value of a number token, refusing overflow to infinity."""
    v = float(tok.text)
    if not math.isfinite(v):
        raise _fail(f"number out of range '{tok.text}'", tok)
    return v


def parse_grammar(text: str, *, check_paths: bool = False) -> Grammar:
    """Parse ``.lsys`` text into a validated :class:`~lsys_core.grammar.model.Grammar`.

    Parameters
    ----------
    text : str
        The whole file, starting with the ``lsys 1`` header (comments may come first).
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
        undefined symbol, duplicate terminal, wrong arity, ``m`` where there is no counter,
        non-finite number, missing axiom, non-terminating rule, non-positive scale.
    """
    lines, comments, end = _tokenize(text)
    if not lines:
        raise _fail(f"missing header 'lsys {FORMAT_VERSION}'", (1, 1))
    st = _State()
    _Line(lines[0], st).header()
    for toks in lines[1:]:
        _Line(toks, st).statement()
    if st.axiom is None:
        raise _fail("missing axiom: add a line 'axiom: ...'", end)
    g = Grammar(
        terminals=tuple(st.terminals.values()),
        rules=tuple(Rule(name, acc.parametric, tuple(acc.cases)) for name, acc in st.rules.items()),
        axiom=st.axiom,
        viewbox=st.viewbox,
        size=st.size,
        randomize=st.randomize,
        comments=tuple(c for line, c in comments if len(lines) < 2 or line < lines[1][0].line),
    )
    problems = find_problems(g)
    if problems:
        first = min(problems, key=lambda p: _place(p, st, end))
        raise _fail(first.message, _place(first, st, end))
    if check_paths:
        for t in g.terminals:
            if (why := path_problem(t.path)) is not None:
                raise _fail(f"terminal {t.name}: {why}", st.places[("terminal", t.name, "path")])
    return g


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
    else:
        found = places.get(("canvas", p.owner))
    return found or end


# -- formatting ------------------------------------------------------------------------------------


def format_grammar(g: Grammar) -> str:
    """Write ``g`` as ``.lsys`` text; :func:`parse_grammar` reads it back equal.

    Parameters
    ----------
    g : Grammar
        Any grammar; it is written as is, even if invalid.

    Returns
    -------
    str
        Header, comments, canvas, terminals, axiom, then one line per production, each
        line ending with a newline.  Formatting parsed text again gives the same text.
    """
    out = [f"lsys {1 if g.randomize is None else 2}"]
    for c in g.comments:
        out += [f"# {part}".rstrip() for part in (c.splitlines() or [""])]
    canvas = []
    if g.viewbox is not None:
        canvas.append("viewbox " + " ".join(_num(v) for v in g.viewbox))
    if g.size is not None:
        canvas.append(f"size {_quote(g.size[0])} {_quote(g.size[1])}")
    if canvas:
        out.append("canvas " + " ".join(canvas))
    if g.randomize is not None:
        out.append(_randomize_line(g.randomize))
    for t in g.terminals:
        line = f"terminal {t.name} {_quote(t.path)}"
        if t.style:
            line += f" style {_quote(t.style)}"
        if t.mirror_of is not None:
            line += f" mirror {t.mirror_of}"
        out.append(line)
    out.append(f"axiom: {_body(g.axiom)}")
    for r in g.rules:
        head = f"{r.name}(m)" if r.parametric else r.name
        for case in r.cases:
            cond = f": {case.cond}" if case.cond is not None else ""
            out.append(f"{head}{cond} -> {_body(case.body)}")
    return "\n".join(out) + "\n"


def _randomize_line(r: Randomize) -> str:
    """Return the ``randomize`` line: the non-zero amounts, the seed and the jitter."""
    amounts = [f"{k} {_num(getattr(r, k))}" for k in ("angle", "distance", "scale") if getattr(r, k)]
    return " ".join(["randomize", *amounts, f"seed {int(r.seed)}", f"jitter {r.jitter}"])


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
    return mod.name if mod.arg is None else f"{mod.name}({count_text(mod.arg)})"


def _num(x: float) -> str:
    """Return the shortest round-trip text of ``x`` without a trailing ``.0`` (``-0`` is ``0``)."""
    x = float(x)
    if x == 0:
        return "0"
    s = repr(x)
    return s[:-2] if s.endswith(".0") else s


def _linear(v: Linear) -> str:
    """Return ``c0``, ``c0 + cd*m``, ``c0 - cd*m`` or ``cd*m``."""
    if v.cd == 0:
        return _num(v.c0)
    mag = abs(float(v.cd))
    term = "m" if mag == 1 else f"{_num(mag)}*m"
    if v.c0 == 0:
        return term if v.cd > 0 else f"-{term}"
    return f"{_num(v.c0)} {'+' if v.cd > 0 else '-'} {term}"


def _quote(s: str) -> str:
    """Return ``s`` double-quoted with backslash escapes."""
    return '"' + s.translate(_QUOTING) + '"'
