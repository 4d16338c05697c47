"""Reading one line of ``.lsys`` tokens: names, strings, numbers and production bodies.

:class:`LineReader` is the recursive-descent base of the statement reader in
:mod:`lsys_core.grammar.text`; it records where each module stands (``places``) so problems
found later by :mod:`.validate` can be reported at their ``line:column``.
"""

from __future__ import annotations

from lsys_core.grammar.lexer import Tok, fail, number
from lsys_core.grammar.model import (
    JITTERS,
    PAINT_PROPS,
    Count,
    Linear,
    Module,
    Paint,
    Pop,
    Push,
    Randomize,
    Symbol,
    Turtle,
    TurtleOp,
)

__all__ = ["NON_FINITE", "SEED_LIMIT", "LineReader"]

NON_FINITE = frozenset({"nan", "inf", "infinity"})
#: Seeds are stored as written; beyond this they would not survive a round trip through floats.
SEED_LIMIT = 2**53
_TURTLE_OPS: dict[str, TurtleOp] = {"f": "f", "+": "+", "-": "-", "*": "*", "z": "z", "~": "~"}


class LineReader:
    """Recursive-descent reader of one statement (one line of tokens).

    ``reserved`` are the words that cannot name a symbol; ``places`` maps locators to
    ``(line, column)``; ``turtle_ops`` the turtle commands of the file's version.
    """

    def __init__(self, toks: list[Tok], reserved: frozenset[str], places: dict, turtle_ops: str) -> None:
        self.toks = toks
        self.i = 0
        self.reserved = reserved
        self.places = places
        self.turtle_ops = turtle_ops
        #: Whether the file's version has table values ``[v0, v1, ...]`` (version 3).
        self.tables = True
        #: Whether the file's version has the stretch command ``~(t)`` (version 4).
        self.stretch = True

    def peek(self) -> Tok:
        """Return the current token without consuming it."""
        return self.toks[self.i]

    def take(self) -> Tok:
        """Consume and return the current token (the final ``eol`` is never passed)."""
        tok = self.toks[self.i]
        if tok.kind != "eol":
            self.i += 1
        return tok

    def at(self, text: str, kind: str = "punct") -> bool:
        """Tell whether the current token is ``text`` of ``kind``."""
        tok = self.peek()
        return tok.kind == kind and tok.text == text

    def expect(self, text: str, what: str | None = None, kind: str = "punct") -> Tok:
        """Consume the token ``text`` or fail with "expected ...", naming what was found."""
        if not self.at(text, kind):
            raise fail(f"expected {what or repr(text)}, got {self.peek().shown()}", self.peek())
        return self.take()

    def end(self) -> None:
        """Fail unless the line is finished."""
        if self.peek().kind != "eol":
            raise fail(f"unexpected {self.peek().shown()}: expected end of line", self.peek())

    def name(self, what: str) -> Tok:
        """Consume a symbol name, refusing reserved words."""
        tok = self.peek()
        if tok.kind != "name":
            raise fail(f"expected {what}, got {tok.shown()}", tok)
        if tok.text in self.reserved:
            raise fail(f"'{tok.text}' is reserved and cannot name a symbol", tok)
        return self.take()

    def string(self, what: str) -> str:
        """Consume a quoted string."""
        if self.peek().kind != "str":
            raise fail(f"expected {what} as a quoted string, got {self.peek().shown()}", self.peek())
        return self.take().text

    def integer(self, what: str) -> int:
        """Consume a whole number >= 0."""
        tok = self.peek()
        if tok.kind != "num" or not tok.text.isdigit() or len(tok.text) > 18:
            raise fail(f"expected {what} (a whole number), got {tok.shown()}", tok)
        return int(self.take().text)

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
        opens: list[Tok] = []
        while (tok := self.peek()).kind != "eol":
            self.places[(where, owner, ci, len(mods), False)] = tok.pos
            if tok.kind == "punct" and tok.text in "[]":
                if tok.text == "]" and not opens:
                    raise fail("unbalanced ']': no '[' to close", tok)
                if tok.text == "[":
                    opens.append(tok)
                    mods.append(Push())
                else:
                    opens.pop()
                    mods.append(Pop())
                self.take()
            elif self._turtle_at(tok):
                if tok.text == "~" and not self.stretch:
                    raise fail("a stretch ~(...) needs format version 4: write 'lsys 4' as the header", tok)
                self.take()
                self.expect("(", f"'(' after '{tok.text}'")
                self.places[(where, owner, ci, len(mods), True)] = self.peek().pos
                value = self.table(no_m) if self.at("[") else self.linear(no_m)
                mods.append(Turtle(_TURTLE_OPS[tok.text], value))
                self.expect(")")
            elif tok.kind == "name" and tok.text == "m":
                raise fail("m is the counter: use it in an argument, e.g. P(m-1) or f(2*m)", tok)
            elif tok.kind == "eps" or (tok.kind == "name" and tok.text == "eps"):
                raise fail("ε stands alone for an empty body", tok)
            elif tok.kind == "name":
                mods.append(self.symbol(tok, (where, owner, ci, len(mods), True), no_m))
            else:
                raise fail(f"unexpected {tok.shown()}: expected a module", tok)
        if opens:
            raise fail("unbalanced '[': no ']' closes it", opens[-1])
        return tuple(mods)

    def _turtle_at(self, tok: Tok) -> bool:
        """Tell whether ``tok`` starts a turtle command of this version."""
        if tok.kind == "punct":
            return tok.text in "+-*~"
        return tok.kind == "name" and tok.text in ("f", "z") and tok.text in self.turtle_ops

    def symbol(self, tok: Tok, place: tuple, no_m: str | None) -> Symbol:
        """Read ``NAME``, ``NAME(count)`` or ``NAME{paint}``."""
        self.name("a symbol")
        arg = None
        if self.at("("):
            self.take()
            self.places[place] = self.peek().pos
            arg = self.count(no_m)
            self.expect(")")
        paint = None
        if self.at("{") and "z" in self.turtle_ops:
            self.places.setdefault(place, self.peek().pos)
            paint = self.paint(no_m)
        return Symbol(tok.text, arg, paint)

    def paint(self, no_m: str | None) -> Paint:
        """Read ``{STYLE, prop: value, ...}`` (the style name first, each property once)."""
        self.take()
        style = None
        props: dict[str, Linear] = {}
        while True:
            tok = self.peek()
            if tok.kind != "name":
                raise fail(f"expected a style name or a property, got {tok.shown()}", tok)
            key = self.take().text
            while self.at("-") and self.toks[self.i + 1].kind == "name":  # fill-opacity
                self.take()
                key += "-" + self.take().text
            if self.at(":"):
                self.take()
                if key not in PAINT_PROPS:
                    raise fail(f"unknown paint property '{key}' (known: {', '.join(PAINT_PROPS)})", tok)
                if key in props:
                    raise fail(f"duplicate paint property '{key}'", tok)
                props[key] = self.linear(no_m)
            elif style is None and not props:
                if key in self.reserved:
                    raise fail(f"'{key}' is reserved and cannot name a style", tok)
                style = key
            else:
                raise fail(f"expected 'property: value' after the style name, got '{key}'", tok)
            if self.at("}"):
                self.take()
                return Paint(style, tuple(props.items()))
            self.expect(",", "',' or '}'")

    def terms(self, no_m: str | None) -> list[tuple[int, Tok | None, Tok | None]]:
        """Read ``[±] term {± term}`` with terms ``N``, ``N*m``, ``m``, ``m*N``; return (sign, number, m)."""
        out = []
        while True:
            sign = 1
            while self.peek().kind == "punct" and self.peek().text in "+-":
                sign = -sign if self.take().text == "-" else sign
            tok = self.peek()
            if tok.kind == "name" and tok.text in NON_FINITE:
                raise fail(f"non-finite number '{tok.text}'", tok)
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
                        raise fail(f"expected a number after '*', got {self.peek().shown()}", self.peek())
                    num = self.take()
            else:
                raise fail(f"expected a number, got {tok.shown()}", tok)
            if m is not None and no_m is not None:
                raise fail(no_m, m)
            out.append((sign, num, m))
            if not (self.peek().kind == "punct" and self.peek().text in "+-"):
                return out

    def linear(self, no_m: str | None) -> Linear:
        """Read a value ``c0 + cd*m`` (any sum of such terms)."""
        start = self.peek()
        c0 = cd = 0.0
        for sign, num, m in self.terms(no_m):
            v = sign * (number(num) if num is not None else 1.0)
            if m is None:
                c0 += v
            else:
                cd += v
        if not (abs(c0) < float("inf") and abs(cd) < float("inf")):
            raise fail("value out of range (not a finite number)", start)
        return Linear(c0, cd)

    def table(self, no_m: str | None) -> Linear:
        """Read a table value ``[v0, v1, ...]`` (signed numbers, at least one)."""
        start = self.take()
        if not self.tables:
            raise fail("a table value [...] needs format version 3: write 'lsys 3' as the header", start)
        if no_m is not None:
            raise fail(no_m.replace("m cannot", "a table [...] indexed by m cannot"), start)
        values = [self.signed_number()]
        while self.at(","):
            self.take()
            values.append(self.signed_number())
        self.expect("]", "',' or ']' in the table")
        return Linear.of_table(values)

    def count(self, no_m: str | None) -> Count:
        """Read an integer counter argument ``k0 + k1*m``."""
        k0 = k1 = 0
        for sign, num, m in self.terms(no_m):
            if num is not None and not num.text.isdigit():
                raise fail(f"counter arguments are whole numbers, got '{num.text}'", num)
            if num is not None and len(num.text) > 18:
                raise fail(f"counter argument out of range '{num.text}'", num)
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
        if tok.kind == "name" and tok.text in NON_FINITE:
            raise fail(f"non-finite number '{tok.text}'", tok)
        if tok.kind != "num":
            raise fail(f"expected a number, got {tok.shown()}", tok)
        return sign * number(self.take())

    def randomize_options(self) -> Randomize:
        """Read ``[angle A] [distance D] [scale S] [seed N] [jitter instance|cumulative]`` (at least one)."""
        opts: dict[str, float | str] = {}
        names = ("angle", "distance", "scale", "seed", "jitter")
        while self.peek().kind == "name" and self.peek().text in names:
            opt = self.take()
            if opt.text in opts:
                raise fail(f"duplicate '{opt.text}'", opt)
            tok = self.peek()
            if opt.text == "jitter":
                if tok.kind != "name" or tok.text not in JITTERS:
                    raise fail(f"expected 'instance' or 'cumulative' after 'jitter', got {tok.shown()}", tok)
                opts["jitter"] = self.take().text
                continue
            value = self.signed_number()
            if value < 0 or (opt.text == "seed" and (not value.is_integer() or value >= SEED_LIMIT)):
                what = "a whole number >= 0" if opt.text == "seed" else "a number >= 0"
                raise fail(f"{opt.text} must be {what}, got {value:g}", tok)
            opts[opt.text] = value
        if not opts:
            raise fail(f"expected one of {', '.join(names)}, got {self.peek().shown()}", self.peek())
        seed = int(opts.pop("seed", 0))
        return Randomize(seed=seed, **opts)  # type: ignore[arg-type]
