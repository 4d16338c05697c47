"""Tests of the ``.lsys`` text format: parsing, formatting, round trips, errors and validation."""

from __future__ import annotations

from dataclasses import replace

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lsys_core.errors import GrammarError, GrammarSyntaxError
from lsys_core.grammar import (
    COND_EQ0,
    COND_GT0,
    Case,
    Count,
    Grammar,
    Linear,
    NamedStyle,
    Paint,
    Pop,
    Push,
    Rule,
    Symbol,
    Terminal,
    Turtle,
    format_grammar,
    parse_grammar,
    validate,
)
from lsys_core.grammar.validate import RESERVED, find_problems

HEAD = 'lsys 1\nterminal A "M 0 0 L 10 0"\n'

BRIEF_EXAMPLE = """\
lsys 1
# comments run from '#' to end of line, anywhere
canvas viewbox 0 0 800 600 size "800" "600"      # optional line; either part optional
terminal A "M 0 0 C 1 2 3 4 5 6 Z" style "fill:#000;stroke:none"
terminal B "M 0 0 L 10 0" style "stroke:#f00" mirror A      # 'style' and 'mirror NAME' optional
axiom: +(90) f(100) *(0.5) P(119)
P(m): m > 0 -> A f(24) *(0.99) +(11) P(m-1)
P(m): m == 0 -> A
R(m): m > 0 -> A [ -(17) f(64) *(0.8) -(3) R(m-1) ] [ +(7) f(181) *(0.6) +(23) R(m-1) ]
R(m): m == 0 -> A
Q(m): m > 0 -> A +(10 + 2*m) f(5) Q(m-1)      # parameter linear in m: t0 + tΔ*m
X -> A f(10) B                                  # non-parametric rule, one case, no condition
Y(m) -> A f(3) Y(m-1)                            # parametric, no condition (applies for every m)
E -> ε          # empty body: 'ε' or 'eps' or nothing after the arrow
"""


def t(c0: float, cd: float = 0.0, op: str = "f") -> Turtle:
    """Return a turtle module."""
    return Turtle(op, Linear(c0, cd))


# -- the paper's examples and the reference file ---------------------------------------------------


def test_paper_helix_parses_to_the_sequence_rule():
    g = parse_grammar(
        HEAD + "axiom: P(336)\nP(m): m > 0 -> A f(27.5) *(0.993) +(8.5) P(m-1)\nP(m): m == 0 -> A\n"
    )
    assert g.axiom == (Symbol("P", Count(336)),)
    (rule,) = g.rules
    assert rule.parametric and [c.cond for c in rule.cases] == [COND_GT0, COND_EQ0]
    assert rule.cases[0].body == (
        Symbol("A"),
        t(27.5),
        t(0.993, op="*"),
        t(8.5, op="+"),
        Symbol("P", Count(-1, 1)),
    )
    assert rule.cases[1].body == (Symbol("A"),)


def test_paper_fig1_branching_parses_with_nested_brackets():
    text = HEAD + (
        "axiom: R(3)\n"
        "R(m): m > 0 -> A[−(17) f(64) ∗(0.8) −(3) R(m − 1)] [+(7) f(181) *(0.6) +(23) R(m−1)]\n"
        "R(m): m == 0 → A\n"
    )
    body = parse_grammar(text).rule("R").cases[0].body
    assert [type(x).__name__ for x in body].count("Push") == 2
    assert body[1:7] == (
        Push(),
        t(17, op="-"),
        t(64),
        t(0.8, op="*"),
        t(3, op="-"),
        Symbol("R", Count(-1, 1)),
    )
    assert body[7] == Pop() and body[-1] == Pop()
    assert body[8:14] == (
        Push(),
        t(7, op="+"),
        t(181),
        t(0.6, op="*"),
        t(23, op="+"),
        Symbol("R", Count(-1, 1)),
    )
    assert len(body) == 15


def test_reference_example_parses_in_full():
    g = parse_grammar(BRIEF_EXAMPLE)
    assert g.viewbox == (0, 0, 800, 600) and g.size == ("800", "600")
    # a version-1 file: strokes scale with the turtle, as that version drew them
    assert g.terminal("B") == Terminal("B", "M 0 0 L 10 0", "stroke:#f00", "A", scaled=True)
    assert [r.name for r in g.rules] == ["P", "R", "Q", "X", "Y", "E"]
    assert g.rule("Q").cases[0].body[1] == t(10, 2, op="+")
    assert g.rule("X") == Rule("X", False, (Case(None, (Symbol("A"), t(10), Symbol("B"))),))
    assert g.rule("Y").parametric and g.rule("Y").cases[0].cond is None
    assert g.rule("E").cases[0].body == ()
    assert g.axiom[:3] == (t(90, op="+"), t(100), t(0.5, op="*"))
    assert g.comments == ("comments run from '#' to end of line, anywhere",)
    assert parse_grammar(format_grammar(g)) == g


def test_cases_keep_text_order_and_rules_group_by_first_appearance():
    g = parse_grammar(
        HEAD + "axiom: P(2) Q(1)\nQ(m): m == 0 -> A\nP(m): m > 0 -> P(m-1)\nQ(m): m > 0 -> f(1)\n"
    )
    assert [r.name for r in g.rules] == ["Q", "P"]
    assert [c.cond for c in g.rule("Q").cases] == [COND_EQ0, COND_GT0]


@pytest.mark.parametrize(
    "text",
    [
        "P(m):m>0->A f(1)P(m-1)",
        "P ( m ) :  m  >  0  →  A  f ( 1 )  P ( m − 1 )",
        "P(m)\t: m > 0\t-> A\tf(1.0) P(m - 1)   # trailing comment",
    ],
)
def test_whitespace_arrows_and_unicode_minus_are_free(text):
    g = parse_grammar(HEAD + "axiom: P(1)\n" + text + "\n")
    assert g.rule("P").cases[0] == Case(COND_GT0, (Symbol("A"), t(1), Symbol("P", Count(-1, 1))))


@pytest.mark.parametrize("body", ["ε", "eps", ""])
def test_empty_bodies(body):
    g = parse_grammar(HEAD + f"axiom: A E\nE -> {body}\n")
    assert g.rule("E").cases[0].body == ()


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        ("10 + 2*m", (10, 2)),
        ("10 - 2*m", (10, -2)),
        ("2*m", (0, 2)),
        ("-3*m + 1", (1, -3)),
        ("m", (0, 1)),
        ("-m", (0, -1)),
        ("m*2.5", (0, 2.5)),
        ("1e-3", (0.001, 0)),
        ("-5", (-5, 0)),
        (".5", (0.5, 0)),
        ("1.5E+2 - m", (150, -1)),
    ],
)
def test_turtle_values_are_linear_in_m(value, expected):
    g = parse_grammar(HEAD + f"axiom: P(1)\nP(m) -> A f({value})\n")
    assert g.rule("P").cases[0].body[1].value == Linear(*expected)


@pytest.mark.parametrize(
    ("arg", "expected"),
    [
        ("m-1", (-1, 1)),
        ("m", (0, 1)),
        ("3", (3, 0)),
        ("2*m+1", (1, 2)),
        ("m - 2", (-2, 1)),
        ("-m+4", (4, -1)),
    ],
)
def test_counter_arguments_are_integer_affine(arg, expected):
    g = parse_grammar(HEAD + f"axiom: Q(1)\nQ(m) -> A P({arg})\nP(m): m > 0 -> A\n")
    assert g.rule("Q").cases[0].body[1].arg == Count(*expected)


def test_strings_resolve_escapes_and_keep_path_data_verbatim():
    g = parse_grammar(
        'lsys 1\nterminal A "M0,0 l 1e-3 -2z # not a comment" style "font: \\"x\\\\y\\"\\t"\naxiom: A\n'
    )
    assert g.terminals[0].path == "M0,0 l 1e-3 -2z # not a comment"
    assert g.terminals[0].style == 'font: "x\\y"\t'


# -- formatting -----------------------------------------------------------------------------------


def test_format_writes_the_canonical_layout():
    g = Grammar(
        terminals=(Terminal("A", 'M 0 0 "q"', "fill:red"), Terminal("B", "M 1 1", mirror_of="A")),
        rules=(
            Rule(
                "P",
                True,
                (
                    Case(
                        COND_GT0,
                        (
                            Symbol("A"),
                            t(24.0),
                            t(0.99, op="*"),
                            Push(),
                            t(1e-5, op="+"),
                            t(-0.0, op="-"),
                            t(10, -2),
                            t(0, 2),
                            t(-3, 1),
                            Pop(),
                            Symbol("P", Count(-1, 1)),
                            Symbol("P", Count(1, 2)),
                        ),
                    ),
                    Case(COND_EQ0, ()),
                ),
            ),
        ),
        axiom=(Symbol("P", Count(3)),),
        viewbox=(0.0, -1.5, 800.0, 600.0),
        size=("8cm", "6cm"),
    )
    assert format_grammar(g) == (
        "lsys 2\n"
        'canvas viewbox 0 -1.5 800 600 size "8cm" "6cm"\n'
        'terminal A "M 0 0 \\"q\\"" style "fill:red"\n'
        'terminal B "M 1 1" mirror A\n'
        "axiom: P(3)\n"
        "P(m): m > 0 -> A f(24) *(0.99) [ +(1e-05) -(0) f(10 - 2*m) f(2*m) f(-3 + m) ] P(m-1) P(2*m+1)\n"
        "P(m): m == 0 -> ε\n"
    )


def test_formatting_hand_written_text_is_a_fixed_point():
    once = format_grammar(parse_grammar(BRIEF_EXAMPLE))
    assert once != BRIEF_EXAMPLE
    assert format_grammar(parse_grammar(once)) == once
    assert once.startswith("lsys 1\n# comments run from")  # nothing of version 2: still version 1


# -- random grammars ------------------------------------------------------------------------------

NAMES = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,5}", fullmatch=True).filter(lambda s: s not in RESERVED)
FLOATS = st.floats(allow_nan=False, allow_infinity=False)
POSITIVE = st.floats(min_value=0.0, exclude_min=True, allow_infinity=False)
NONZERO = FLOATS.filter(lambda x: x != 0)
STRINGS = st.one_of(
    st.sampled_from(["", "M 0 0 L 10 0", 'a"b\\c', "fill:#000;stroke:none"]), st.text(max_size=20)
)
CONDS = [(COND_GT0, COND_EQ0), (COND_GT0,), (None,), (COND_EQ0, COND_GT0), (COND_GT0, None), (COND_EQ0,)]


@st.composite
def turtles(draw, parametric: bool) -> Turtle:
    """Draw a valid turtle module; ``m`` only in parametric rules; constant scales positive."""
    op = draw(st.sampled_from("f+-*"))
    linear = parametric and draw(st.booleans())
    if op == "*":
        return Turtle(op, Linear(draw(FLOATS), draw(NONZERO)) if linear else Linear(draw(POSITIVE)))
    return Turtle(op, Linear(draw(FLOATS), draw(FLOATS) if linear else 0.0))


@st.composite
def bodies(draw, atoms, depth: int = 2) -> tuple:
    """Draw a body with balanced, possibly nested brackets."""
    out: list = []
    for _ in range(draw(st.integers(0, 5))):
        if depth and draw(st.integers(0, 3)) == 0:
            out += [Push(), *draw(bodies(atoms, depth - 1)), Pop()]
        else:
            out.append(draw(atoms))
    return tuple(out)


@st.composite
def grammars(draw) -> Grammar:
    """Draw a valid grammar: rules call only later rules, plus decreasing self-calls."""
    names = draw(st.lists(NAMES, min_size=2, max_size=7, unique=True))
    split = draw(st.integers(1, len(names) - 1))
    tnames, rnames = names[:split], names[split:]
    terminals = tuple(
        Terminal(n, draw(STRINGS), draw(STRINGS), draw(st.none() | st.sampled_from(tnames))) for n in tnames
    )
    parametric = {n: draw(st.booleans()) for n in rnames}

    def calls(targets: list[str], in_param: bool, own: str | None):
        options = [st.sampled_from(tnames).map(Symbol)]
        for n in targets:
            if not parametric[n]:
                options.append(st.just(Symbol(n)))
            else:
                k1 = st.integers(-3, 3) if in_param else st.just(0)
                options.append(
                    st.builds(lambda k0, k1, n=n: Symbol(n, Count(k0, k1)), st.integers(-5, 300), k1)
                )
        if own is not None:
            options.append(st.integers(1, 3).map(lambda c: Symbol(own, Count(-c, 1))))
        return st.one_of(*options)

    rules = []
    for i, name in enumerate(rnames):
        p = parametric[name]
        atoms = st.one_of(turtles(p), calls(rnames[i + 1 :], p, name if p else None))
        conds = draw(st.sampled_from(CONDS)) if p else (None,)
        rules.append(Rule(name, p, tuple(Case(c, draw(bodies(atoms))) for c in conds)))
    axiom = draw(bodies(st.one_of(turtles(False), calls(rnames, False, None))))
    viewbox = draw(st.none() | st.tuples(FLOATS, FLOATS, POSITIVE, POSITIVE))
    size = draw(st.none() | st.tuples(STRINGS, STRINGS))
    return Grammar(terminals, tuple(rules), axiom or (Symbol(tnames[0]),), viewbox, size)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(grammars())
def test_parse_inverts_format_and_formatting_is_stable(g):
    assert find_problems(g) == []  # the strategy only makes valid grammars
    text = format_grammar(g)
    back = parse_grammar(text)
    assert back == g
    assert format_grammar(back) == text


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(grammars(), st.data())
def test_damaged_text_fails_only_with_a_located_syntax_error(g, data):
    text = format_grammar(g)
    i = data.draw(st.integers(0, len(text)))
    j = data.draw(st.integers(i, min(len(text), i + 3)))
    junk = data.draw(st.text(alphabet='[]()+-*:>=m#"\\ \n0.eε→−Ax', max_size=3))
    damaged = text[:i] + junk + text[j:]
    try:
        parse_grammar(damaged)
    except GrammarSyntaxError as e:
        lines = damaged.split("\n")
        assert 1 <= e.line <= len(lines) + 1 and e.column >= 1
        assert str(e).startswith(f"{e.line}:{e.column}: ")


# -- errors with line:column ----------------------------------------------------------------------

ERRORS = [
    # (text, line, column, message fragment)
    ("", 1, 1, "missing header"),
    ("# only a comment\n", 1, 1, "missing header"),
    ('terminal A "M0 0"\n', 1, 1, "expected the header"),
    ("lsys 5\n", 1, 6, "unsupported format version 5"),
    ("lsys\n", 1, 5, "expected a format version"),
    (HEAD + "axiom: A\nlsys 1\n", 4, 1, "duplicate header"),
    (HEAD + "axiom: A\nX A\n", 4, 3, "expected '->'"),
    (HEAD + "axiom: A\nX -> A )\n", 4, 8, "unexpected ')'"),
    (HEAD + "axiom: f(1.2.3) A\n", 3, 10, "bad number '1.2.3'"),
    (HEAD + "axiom: f(2m) A\n", 3, 10, "bad number '2m'"),
    (HEAD + 'terminal B "abc\naxiom: A\n', 3, 12, "unterminated string"),
    (HEAD + 'terminal B "a\\q"\naxiom: A\n', 3, 14, "unknown escape"),
    (HEAD + "axiom: A ? \n", 3, 10, "unexpected character '?'"),
    (HEAD + "axiom: P(3)\nP(m): m > 0 -> A [ f(1) P(m-1)\n", 4, 18, "unbalanced '['"),
    (HEAD + "axiom: P(3)\nP(m): m > 0 -> A ] P(m-1)\n", 4, 18, "unbalanced ']'"),
    (HEAD + "axiom: f(1 A\n", 3, 12, "expected ')'"),
    (HEAD + "axiom: + A\n", 3, 10, "expected '(' after '+'"),
    (HEAD + "axiom: P(3)\nP(m): m > 0 -> A Z P(m-1)\n", 4, 18, "undefined symbol 'Z'"),
    (HEAD + "axiom: A\nX -> A\naxiom: X\n", 5, 1, "duplicate axiom"),
    (HEAD + 'terminal A "x"\naxiom: A\n', 3, 10, "duplicate terminal 'A'"),
    (HEAD + "axiom: A(3)\n", 3, 8, "terminal A takes no argument"),
    (HEAD + "axiom: P\nP(m) -> A\n", 3, 8, "P takes a counter"),
    (HEAD + "axiom: X(3)\nX -> A\n", 3, 8, "X takes no counter"),
    (HEAD + "axiom: X\nX -> A P\nP(m) -> A\n", 4, 8, "P takes a counter"),
    (HEAD + "axiom: P(m)\nP(m) -> A\n", 3, 10, "m cannot be used in the axiom"),
    (HEAD + "axiom: f(2*m) A\n", 3, 12, "m cannot be used in the axiom"),
    (HEAD + "axiom: X\nX -> f(m)\n", 4, 8, "m cannot be used in rule X"),
    (HEAD + "axiom: X\nX -> Y(m)\nY(m) -> A\n", 4, 8, "m cannot be used in rule X"),
    (HEAD + "axiom: X\nX: m > 0 -> A\n", 4, 2, "has no counter"),
    (HEAD + "axiom: P(1.5)\nP(m) -> A\n", 3, 10, "whole numbers"),
    (HEAD + "axiom: f(nan) A\n", 3, 10, "non-finite number 'nan'"),
    (HEAD + "axiom: f(-inf) A\n", 3, 11, "non-finite number 'inf'"),
    (HEAD + "axiom: f(1e999) A\n", 3, 10, "number out of range '1e999'"),
    (HEAD + "axiom: f(1e308 + 1e308) A\n", 3, 10, "not a finite number"),
    (HEAD + "canvas viewbox 0 0 inf 1\naxiom: A\n", 3, 20, "non-finite number 'inf'"),
    (HEAD, 3, 1, "missing axiom"),
    (HEAD + "X -> A\n", 4, 1, "missing axiom"),
    (HEAD + "axiom:\n", 3, 1, "empty axiom"),
    (HEAD + "axiom: *(0) A\n", 3, 10, "scale must be positive"),
    (HEAD + "axiom: *(-1) A\n", 3, 10, "scale must be positive"),
    (HEAD + "axiom: P(3)\nP(m): m > 0 -> A P(m)\n", 4, 18, "rule P never terminates: the call P(m)"),
    (HEAD + "axiom: P(3)\nP(m) -> A P(m+1)\n", 4, 11, "the call P(m+1) does not decrease m"),
    (HEAD + "axiom: P(3)\nP(m) -> A P(2*m)\n", 4, 11, "the call P(2*m) does not decrease m"),
    (HEAD + "axiom: P(3)\nP(m) -> A P(5)\n", 4, 11, "the call P(5) does not decrease m"),
    (HEAD + "axiom: X\nX -> A Y\nY -> [ X ]\n", 4, 8, "rule X never terminates"),
    (HEAD + "axiom: X\nX -> A X\n", 4, 8, "rule X never terminates"),
    (HEAD + "axiom: P(3)\nP(m) -> Q(m)\nQ(m) -> A P(m)\n", 4, 9, "rule P never terminates: the call Q(m)"),
    (HEAD + "axiom: P(3)\nP(m): m > 0 -> A\nP: m == 0 -> A\n", 5, 1, "rule P is written P(m) on line 4"),
    (HEAD + "axiom: A\nX -> A\nX -> f(1)\n", 5, 1, "this case is never used"),
    (HEAD + "axiom: P(1)\nP(m): m > 0 -> A\nP(m): m == 0 -> A\nP(m) -> A\n", 6, 1, "never used"),
    (HEAD + "axiom: P(1)\nP(m): m > 1 -> A\n", 4, 11, "expected a condition 'm > 0' or 'm == 0', got '1'"),
    (HEAD + "axiom: P(1)\nP(n) -> A\n", 4, 3, "the counter of a rule is written m"),
    (HEAD + "axiom: A\nf -> A\n", 4, 1, "'f' is reserved"),
    (HEAD + "axiom: A\nA -> f(1)\n", 4, 1, "'A' is a terminal and cannot have a rule"),
    (HEAD + "axiom: A\nX -> m\n", 4, 6, "m is the counter"),
    (HEAD + "axiom: A ε\n", 3, 10, "ε stands alone"),
    ('lsys 1\nterminal A "x" mirror Q\naxiom: A\n', 2, 23, "'mirror Q' does not name a terminal"),
    (HEAD + "canvas viewbox 0 0 -1 5\naxiom: A\n", 3, 8, "viewbox width and height must be positive"),
    (HEAD + 'canvas size "1"\naxiom: A\n', 3, 16, "expected the height"),
    (HEAD + "canvas\naxiom: A\n", 3, 7, "expected 'viewbox' or 'size'"),
    (HEAD + 'axiom: A\ncanvas size "1" "2"\ncanvas size "1" "2"\n', 5, 1, "duplicate canvas"),
]


@pytest.mark.parametrize(("text", "line", "column", "fragment"), ERRORS)
def test_errors_carry_line_and_column(text, line, column, fragment):
    with pytest.raises(GrammarSyntaxError) as info:
        parse_grammar(text)
    err = info.value
    assert fragment in err.message
    assert (err.line, err.column) == (line, column), str(err)
    assert str(err) == f"{line}:{column}: {err.message}"


def test_the_first_problem_in_text_order_is_reported():
    text = HEAD + "axiom: P(3)\nP(m) -> A Z P(m)\nQ -> Y\n"
    with pytest.raises(GrammarSyntaxError) as info:
        parse_grammar(text)
    assert (info.value.line, info.value.column) == (4, 11)


@pytest.mark.parametrize(
    "rules",
    [
        "P(m) -> A Q(m)\nQ(m) -> A P(m-1)",  # a zero step is fine when the cycle still decreases
        # calls leaving the cycle are free
        "P(m): m > 0 -> A [ P(m-1) ] [ P(m-2) ] Q(2*m+7)\nQ(m) -> A Q(m-3)",
        "P(m) -> X\nX -> Q(5)\nQ(m) -> A Q(m-1)",
        "P(m): m == 0 -> A P(m-1)",
    ],
)
def test_terminating_recursion_is_accepted(rules):
    parse_grammar(HEAD + "axiom: P(4)\n" + rules + "\n")


# -- validate on grammars built by code -----------------------------------------------------------


def _grammar(body, parametric=True, cond=COND_GT0, axiom=None, terminals=None):
    """Return a one-rule grammar ``P`` with one case (axiom ``P(3)`` by default), for validate tests."""
    return Grammar(
        terminals=terminals or (Terminal("A", "M 0 0"),),
        rules=(Rule("P", parametric, (Case(cond, tuple(body)),)),),
        axiom=(Symbol("P", Count(3)),) if axiom is None else axiom,
    )


def test_validate_accepts_a_valid_grammar():
    validate(parse_grammar(BRIEF_EXAMPLE))
    validate(_grammar([Symbol("A"), t(1, 2), Symbol("P", Count(-1, 1))]))


@pytest.mark.parametrize(
    ("grammar", "fragment"),
    [
        (_grammar([Symbol("Z")]), "undefined symbol 'Z'"),
        (_grammar([Symbol("A"), Symbol("P")]), "P takes a counter argument"),
        (_grammar([Symbol("A"), Symbol("P", Count(0, 1))]), "never terminates"),
        (_grammar([t(0, op="*")]), "scale must be positive"),
        (_grammar([t(float("nan"))]), "finite"),
        (
            _grammar([t(1, 2)], parametric=False, cond=None, axiom=(Symbol("P"),)),
            "m cannot be used in rule P",
        ),
        (_grammar([Push()]), "unbalanced '['"),
        (_grammar([Pop()]), "unbalanced ']'"),
        (_grammar([Symbol("A")], axiom=()), "missing axiom"),
        (_grammar([Symbol("A")], axiom=(Symbol("P", Count(2, 1)),)), "m cannot be used in the axiom"),
        (_grammar([Symbol("A")], terminals=(Terminal("A", ""), Terminal("A", ""))), "duplicate terminal 'A'"),
        (_grammar([Symbol("A")], terminals=(Terminal("f", ""),)), "'f' is reserved"),
        (
            _grammar([Symbol("A")], parametric=False, cond=COND_GT0, axiom=(Symbol("P"),)),
            "cannot have a condition",
        ),
        (_grammar([Symbol("A", Count(1))]), "terminal A takes no argument"),
        (_grammar([Symbol("P", Count(2.5))]), "must be integer"),
        (_grammar([Symbol("A")], axiom=(Symbol("P", Count(2**40)),)), "out of range"),
    ],
)
def test_validate_reports_problems_of_programmatic_grammars(grammar, fragment):
    with pytest.raises(GrammarError) as info:
        validate(grammar)
    assert fragment in str(info.value)


def test_problems_carry_a_locator_and_validate_names_it():
    g = _grammar([Symbol("A"), Push(), Symbol("Z"), Pop()])
    (p,) = find_problems(g)
    assert (p.where, p.owner, p.case, p.index) == ("rule", "P", 0, 2)
    with pytest.raises(GrammarError, match=r"'Z'.*\(in rule P, case 1, module 3\)$"):
        validate(g)


def test_examples_in_the_format_documentation_parse():
    from pathlib import Path

    doc = (Path(__file__).parents[2] / "docs" / "lsys-format.md").read_text(encoding="utf-8")
    blocks = [b.split("```", 1)[0] for b in doc.split("```text\n")[1:]]
    examples = [b for b in blocks if b.startswith("lsys ")]
    assert len(examples) >= 3
    for text in examples:
        g = parse_grammar(text)
        assert parse_grammar(format_grammar(g)) == g


# -- versions -------------------------------------------------------------------------------------


def test_a_grammar_is_written_in_the_oldest_version_that_holds_it():
    v1 = parse_grammar('lsys 1\nterminal z "M 0 0 L 1 0" style "stroke:#000"\naxiom: z f(2) z\n')
    # read as drawn: the terminal's strokes scale (version 1), 'z' (a version-2 module) is renamed
    assert v1.terminals == (Terminal("z_", "M 0 0 L 1 0", "stroke:#000", scaled=True),)
    text = format_grammar(v1)
    assert text.startswith("lsys 1\n") and " scaled" not in text
    assert parse_grammar(text) == v1
    # anything of version 2 makes it version 2, and the terminal keeps its meaning there
    painted = replace(v1, axiom=(Symbol("z_", paint=Paint(props=(("opacity", Linear(0.5)),))),))
    for g in (painted, replace(v1, styles=(NamedStyle("s1", "fill:red"),)), replace(v1, order=(1.0,))):
        text = format_grammar(g)
        assert text.startswith("lsys 2\n") and 'terminal z_ "M 0 0 L 1 0" style "stroke:#000" scaled' in text
        assert parse_grammar(text) == g
    unscaled = replace(v1, terminals=(replace(v1.terminals[0], scaled=False),))
    assert format_grammar(unscaled).startswith("lsys 2\n")
