"""Hostile inputs for the robustness tests and the fuzzer: fixed cases and hypothesis strategies.

Fixed cases (:func:`hostile_svgs`, :func:`hostile_rules`) are bytes/text builders, one per class of
the robustness issue; big inputs are generated on demand so nothing large is stored in the
repository.  The strategies (:func:`svg_documents`, :func:`svg_bytes`, :func:`lsys_texts`) produce
structured junk: well-formed XML trees with random SVG elements, attributes drawn from pools of
realistic and broken values, ``<use>`` references into a small id pool (so cycles and fan-out
happen), byte-level mutations of valid files, and token soups for the ``.lsys`` parser.
"""

from __future__ import annotations

import gzip
import random
from collections.abc import Callable
from pathlib import Path
from xml.sax.saxutils import escape, quoteattr

from hypothesis import strategies as st

__all__ = [
    "NS",
    "css_texts",
    "hostile_rules",
    "hostile_svgs",
    "lsys_texts",
    "path_texts",
    "seed_svgs",
    "svg",
    "svg_bytes",
    "svg_documents",
]

NS = 'xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink"'
ROOT = Path(__file__).resolve().parents[2]


def svg(body: str, attrs: str = 'width="100" height="100" viewBox="0 0 100 100"') -> str:
    """Return an SVG document with ``body`` inside the root element."""
    return f"<svg {NS} {attrs}>{body}</svg>"


SHAPE = '<path d="M0 0 L10 5 L4 12 Z" fill="#080"/>'


def _words(text: str) -> list[str]:
    """Split a vocabulary written as one string on whitespace."""
    return text.split()


# ---------------------------------------------------------------------------
# Fixed hostile SVG inputs, one per class


def _billion_laughs() -> str:
    ents = ['<!ENTITY lol "lol">'] + [
        f'<!ENTITY lol{i} "{("&lol" + str(i - 1) + ";") * 10 if i > 1 else "&lol;" * 10}">'
        for i in range(1, 10)
    ]
    return f'<?xml version="1.0"?>\n<!DOCTYPE svg [\n{chr(10).join(ents)}\n]>\n' + svg(
        f"<text>&lol9;</text>{SHAPE}"
    )


def _quadratic_blowup() -> str:
    big = "x" * 20_000
    return f'<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY a "{big}">]>' + svg(
        f'<path d="M0 0 L1 1" data-x="{"&a;" * 20_000}"/>'
    )


def _fan_out(levels: int, width: int) -> str:
    defs = ['<path id="l0" d="M0 0 L1 1"/>']
    for i in range(1, levels + 1):
        uses = f'<use href="#l{i - 1}"/>' * width
        defs.append(f'<g id="l{i}">{uses}</g>')
    return svg(f"<defs>{''.join(defs)}</defs><use href='#l{levels}'/>")


def _overlapping(n: int, seed: int = 0) -> str:
    rnd = random.Random(seed)
    body = "".join(
        f'<path d="M{rnd.uniform(0, 100):.2f} {rnd.uniform(0, 100):.2f} l10 5 l-3 8z" fill="#36a"/>'
        for _ in range(n)
    )
    return svg(body)


def hostile_svgs() -> dict[str, Callable[[], bytes]]:
    """Return builders of hostile SVG files by case name (built lazily: some are megabytes)."""

    def text(f: Callable[[], str]) -> Callable[[], bytes]:
        return lambda: f().encode("utf-8")

    return {
        # not an SVG at all
        "empty": lambda: b"",
        "whitespace": lambda: b" \n\t ",
        "binary": lambda: bytes(range(256)) * 16,
        "png_magic": lambda: b"\x89PNG\r\n\x1a\n" + bytes(64),
        "truncated": text(lambda: svg(SHAPE * 3)[:-20]),
        "wrong_encoding": lambda: ('<?xml version="1.0" encoding="UTF-8"?>' + svg("é" + SHAPE)).encode(
            "latin-1"
        ),
        "unknown_encoding": lambda: b'<?xml version="1.0" encoding="x-nope"?><svg/>',
        "html": lambda: b"<!DOCTYPE html><html><body><p>hi</p></body></html>",
        "corrupt_gzip": lambda: b"\x1f\x8b\x08\x00junkjunkjunk",
        "gzip_bomb": lambda: gzip.compress(b" " * 60_000_000, 9),
        # XML attacks
        "billion_laughs": text(_billion_laughs),
        "quadratic_blowup": text(_quadratic_blowup),
        "xxe": text(
            lambda: (
                '<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY x SYSTEM "file:///etc/passwd">]>'
                + svg(f"<text>&x;</text>{SHAPE}")
            )
        ),
        "parameter_entity": text(
            lambda: (
                '<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY % p SYSTEM "http://127.0.0.1:9/x.dtd"> %p;]>'
                + svg(SHAPE)
            )
        ),
        "too_many_elements": text(lambda: svg("<g/>" * 210_000 + SHAPE)),
        "too_large": lambda: svg(SHAPE).encode() + b"<!--" + b"x" * 51_000_000 + b"-->",
        # <use>
        "use_self": text(lambda: svg(f'<use id="u" href="#u"/>{SHAPE}')),
        "use_cycle": text(lambda: svg('<g id="a"><use href="#b"/></g><g id="b"><use xlink:href="#a"/></g>')),
        "use_fan_out": text(lambda: _fan_out(12, 10)),
        "use_missing": text(
            lambda: svg(f'<use href="#nowhere"/><use href="http://127.0.0.1:9/x.svg#a"/>{SHAPE}')
        ),
        # nothing drawable / few / many
        "only_text_images_defs": text(
            lambda: svg('<text>hi</text><image href="x.png" width="5" height="5"/><defs>' + SHAPE + "</defs>")
        ),
        "single_element": text(lambda: svg(SHAPE)),
        "two_elements": text(lambda: svg(SHAPE + '<path d="M30 0 L40 5 L34 12 Z" fill="#080"/>')),
        "exact_duplicates": text(lambda: svg(SHAPE * 1000)),
        "overlapping_3000": text(lambda: _overlapping(3000)),
        # numbers and geometry
        "non_finite": text(
            lambda: svg(
                '<path d="M0 0 L1e400 0"/><rect x="inf" width="5" height="5"/><circle r="nan"/>'
                '<rect width="3" height="3" transform="scale(1e999)"/>'
                + SHAPE
                + '<path d="M20 0 L30 5 L24 12 Z" fill="#080"/>'
            )
        ),
        "huge_coordinates": text(
            lambda: svg(
                '<path d="M0 0 L1e11 5e10 L4e10 1.2e11 Z"/><path d="M3e11 0 L4e11 5e10 L3.4e11 1.2e11 Z"/>'
                '<path d="M6e11 0 L7e11 5e10 L6.4e11 1.2e11 Z"/>',
                'viewBox="0 0 1e12 2e11"',
            )
        ),
        "zero_length_paths": text(
            lambda: svg(
                '<path d="M5 5 L5 5"/><path d="M1 1"/><path d=""/><line x1="2" y1="2" x2="2" y2="2"/>' + SHAPE
            )
        ),
        "malformed_path_data": text(
            lambda: svg(
                '<path d="hello world"/><path d="M 1 1 L 2 x"/><path d="M0 0 A nan 1 0 0 0 5 5"/>' + SHAPE
            )
        ),
        "zero_viewbox": text(lambda: svg(SHAPE * 2, 'width="100" height="100" viewBox="0 0 0 0"')),
        "nested_zero_viewbox": text(
            lambda: svg(f'<svg viewBox="0 0 0 0" width="10" height="10">{SHAPE}</svg>{SHAPE}')
        ),
        "degenerate_transforms": text(
            lambda: svg(
                f'<g transform="scale(0)">{SHAPE}</g><g transform="matrix(0 0 0 0 0 0)">{SHAPE}</g>'
                f'<g transform="skewX(90)">{SHAPE}</g>{SHAPE}'
            )
        ),
        "invalid_transform": text(lambda: svg(f'<g transform="rotate(foo)">{SHAPE}</g>{SHAPE}')),
        "overflowing_opacity": text(
            lambda: svg(
                f'<path d="M0 0 L5 5" stroke="red" stroke-opacity="1e999" fill-opacity="-1e999"/>{SHAPE}'
            )
        ),
        "deep_nesting": text(lambda: svg("<g>" * 5000 + SHAPE + "</g>" * 5000)),
    }


# ---------------------------------------------------------------------------
# Fixed hostile rule files

_HEAD = 'lsys 1\nterminal A "M0 0 L1 0 L0.5 0.8 Z" style "fill:#080"\n'


def hostile_rules() -> dict[str, str]:
    """Return hostile ``.lsys`` texts by case name."""
    seq = "P(m): m > 0 -> A f(1) P(m-1)\nP(m): m == 0 -> A\n"
    return {
        "syntax_error": _HEAD + "axiom: P(5\n" + seq,
        "undefined_symbol": _HEAD + "axiom: Q(5)\n" + seq,
        "never_terminates": _HEAD + "axiom: P(3)\nP(m) -> A P(m)\n",
        "mutual_recursion": _HEAD + "axiom: P\nP -> A Q\nQ -> A P\n",
        "m_1e9": _HEAD + "axiom: P(1000000000)\n" + seq,
        "m_too_big": _HEAD + "axiom: P(99999999999999999999999)\n" + seq,
        "exponential_branching": _HEAD
        + "axiom: P(60)\nP(m): m > 0 -> A [ +(30) P(m-1) ] [ +(-30) P(m-1) ]\n",
        "scale_zero": _HEAD + "axiom: *(0) A\n",
        "scale_negative": _HEAD + "axiom: P(3)\nP(m): m > 0 -> *(-0.5) A P(m-1)\n",
        "nan": _HEAD + "axiom: f(nan) A\n",
        "overflowing_number": _HEAD + "axiom: f(1e999) A\n",
        "empty": "",
        "binary": "\x00\x01\x02\ufffd",
        "bad_terminal_path": 'lsys 1\nterminal A "hello world"\naxiom: A\n',
        "non_finite_terminal_path": 'lsys 1\nterminal A "M0 0 L1e999 0"\naxiom: A\n',
        "overflowing_scale": _HEAD + "axiom: P(5000)\nP(m): m > 0 -> *(2) A f(1) P(m-1)\n",
        "overflowing_distance": _HEAD + "axiom: f(1e308) f(1e308) A\n",
    }


# ---------------------------------------------------------------------------
# Strategies: SVG

_NUMBERS = st.one_of(
    st.integers(-200, 200).map(str),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(
        ["", " ", *_words("0 -0 1e999 -1e999 1e308 1e-320 nan inf NaN 1. .5 5e --1 1e-7 3,4 +.e1 0x10")]
    ),
    st.just("9" * 40),
)
_UNITS = st.sampled_from(["", "", "", "px", "%", "em", "mm", "in", "pt", "abc", " "])
_LENGTHS = st.builds(lambda n, u: n + u, _NUMBERS, _UNITS)
_SEPARATORS = st.sampled_from([" ", ",", "", "  ", "\n", ", "])


@st.composite
def _path_data(draw) -> str:
    cmds = "MmLlHhVvCcSsQqTtAaZz"
    parts = []
    if draw(st.booleans()):
        parts.append("M")
    for _ in range(draw(st.integers(0, 12))):
        if draw(st.integers(0, 2)) == 0:
            parts.append(draw(st.sampled_from(cmds)))
        else:
            parts.append(draw(_NUMBERS))
        parts.append(draw(_SEPARATORS))
    if draw(st.integers(0, 9)) == 0:
        parts.append(draw(st.text(max_size=4)))
    return "".join(parts)


@st.composite
def _transforms(draw) -> str:
    funcs = ["matrix", "translate", "scale", "rotate", "skewX", "skewY", "foo", ""]
    out = []
    for _ in range(draw(st.integers(0, 3))):
        name = draw(st.sampled_from(funcs))
        args = draw(st.lists(_NUMBERS, max_size=7))
        sep = draw(_SEPARATORS)
        out.append(f"{name}({sep.join(args)})")
    if draw(st.integers(0, 9)) == 0:
        out.append(draw(st.sampled_from([")(", "(", "rotate(", "matrix(1 2 3", "scale()"])))
    return " ".join(out)


_COLORS = st.one_of(
    st.sampled_from(
        [
            *_words(
                "red #000 #0a0 #zzz #12345678 none transparent currentColor inherit url(#a) rgb(1,2,3) #"
            ),
            *["", "url(#nope) red", "rgb(1e999,0,0)", "rgba(1,2,3,nan)", "hsl(400, 200%, -5%)"],
        ]
    ),
    st.builds(lambda a, b, c: f"rgb({a},{b},{c})", _NUMBERS, _NUMBERS, _NUMBERS),
)
_STYLE_PROPS = _words(
    "fill stroke stroke-width opacity fill-opacity stroke-opacity display visibility fill-rule "
    "stroke-linecap transform font-size stroke-dasharray"
)


@st.composite
def _style_text(draw) -> str:
    decls = []
    for _ in range(draw(st.integers(0, 4))):
        prop = draw(st.sampled_from(_STYLE_PROPS))
        value = draw(
            st.one_of(_COLORS, _LENGTHS, st.sampled_from(["none", "hidden", "evenodd", "round", ""]))
        )
        decls.append(f"{prop}:{value}")
    return draw(st.sampled_from([";", "; ", ";;"])).join(decls)


_IDS = st.sampled_from(["a", "b", "c", "d"])
_HREFS = st.one_of(_IDS.map(lambda i: "#" + i), st.sampled_from(["", "#", "#zz", "x.svg#a", "data:,x"]))
_POINTS = st.lists(_NUMBERS, max_size=9).map(" ".join)

_ATTRS: dict[str, st.SearchStrategy[str]] = {
    "d": _path_data(),
    "transform": _transforms(),
    **dict.fromkeys(_words("x y width height cx cy r rx ry x1 y1 x2 y2 stroke-width"), _LENGTHS),
    **dict.fromkeys(_words("opacity fill-opacity stroke-opacity"), _NUMBERS),
    "points": _POINTS,
    "fill": _COLORS,
    "stroke": _COLORS,
    "style": _style_text(),
    "class": st.sampled_from(["k", "k j", "", "x" * 50]),
    "id": _IDS,
    "href": _HREFS,
    "xlink:href": _HREFS,
    "viewBox": st.lists(_NUMBERS, min_size=0, max_size=5).map(" ".join),
    "display": st.sampled_from(["none", "inline", "", "x"]),
    "visibility": st.sampled_from(["hidden", "visible", "collapse", ""]),
    "preserveAspectRatio": st.sampled_from(["none", "xMidYMid slice", "junk", ""]),
}
_TAGS = _words(
    "path rect circle ellipse line polyline polygon g use defs symbol svg text image a switch clipPath mask "
    "marker pattern style title foo"
)


def _element(children: st.SearchStrategy) -> st.SearchStrategy[str]:
    @st.composite
    def build(draw) -> str:
        tag = draw(st.sampled_from(_TAGS))
        names = draw(st.lists(st.sampled_from(sorted(_ATTRS)), max_size=5, unique=True))
        attrs = "".join(f" {n}={quoteattr(draw(_ATTRS[n]))}" for n in names)
        if tag == "style":
            sel = draw(st.sampled_from(["path", ".k", "#a", "*", "g > rect", "@media x", "{"]))
            return f"<style>{escape(sel)} {{{escape(draw(_style_text()))}}}</style>"
        inner = "".join(draw(st.lists(children, max_size=4)))
        if tag == "text":
            inner = escape(draw(st.text(max_size=5))) + inner
        return f"<{tag}{attrs}>{inner}</{tag}>"

    return build()


_LEAF = st.builds(
    lambda tag, d: f'<{tag} d="{d}" x="1" y="1" width="4" height="3" r="2" points="0 0 5 5 9 0"/>',
    st.sampled_from(["path", "rect", "circle", "polygon"]),
    st.sampled_from(["M0 0 L10 5 L4 12 Z", "M0 0 C 5 5 10 5 15 0", "M1 1 A 5 5 0 0 1 9 9"]),
)


@st.composite
def svg_documents(draw) -> str:
    """Draw a well-formed SVG document of random, often broken, elements and attributes."""
    tree = st.recursive(_LEAF, _element, max_leaves=12)
    body = "".join(draw(st.lists(tree, max_size=6)))
    names = draw(st.lists(st.sampled_from(["width", "height", "viewBox", "transform", "style"]), unique=True))
    attrs = " ".join(f"{n}={quoteattr(draw(_ATTRS.get(n, _LENGTHS)))}" for n in names)
    return f"<svg {NS} {attrs}>{body}</svg>"


def seed_svgs() -> list[bytes]:
    """Return small real SVG files to mutate (examples shipped with the project)."""
    files = sorted((ROOT / "resources" / "examples").glob("*.svg"))
    out = [f.read_bytes() for f in files if f.stat().st_size < 200_000]
    return out or [svg(SHAPE * 3).encode()]


_SEEDS = seed_svgs()
_JUNK_BYTES = st.sampled_from(
    [
        *b'< > / & &lol; ]> " = <g> </g> <![CDATA[ ]]> <?x?> <!-- --> 1e999 nan'.split(),
        *[b"<!DOCTYPE svg [", b"<!ENTITY a 'b'>", b"<use href='#a'/>", b" id='a'", b"\x00", b"\xff", b"\n"],
        b"\xef\xbb\xbf",
    ]
)


@st.composite
def _mutated(draw) -> bytes:
    base = bytearray(draw(st.one_of(st.sampled_from(_SEEDS), svg_documents().map(str.encode))))
    for _ in range(draw(st.integers(1, 6))):
        if not base:
            break
        i = draw(st.integers(0, len(base)))
        op = draw(st.integers(0, 3))
        if op == 0:  # delete a run
            del base[i : i + draw(st.integers(1, 16))]
        elif op == 1:  # insert XML-ish junk
            base[i:i] = draw(_JUNK_BYTES)
        elif op == 2:  # replace one byte
            base[i : i + 1] = bytes([draw(st.integers(0, 255))])
        else:  # truncate
            del base[i:]
    return bytes(base)


def svg_bytes() -> st.SearchStrategy[bytes]:
    """Return a strategy of SVG-like bytes: random documents, mutated real files and plain junk."""
    return st.one_of(
        svg_documents().map(str.encode),
        _mutated(),
        st.binary(max_size=64),
        st.text(max_size=64).map(str.encode),
    )


# ---------------------------------------------------------------------------
# Strategies: .lsys text

_LSYS_TOKENS = [
    *_words(
        "lsys 1 2 terminal A B P Q style mirror canvas viewbox size 0 -5 1e999 1e-320 nan inf axiom : ( ) m"
    ),
    *_words("- + * − ∗ f [ ] -> → == > ε eps # \\ m-1 2147483648 99999999999999999999 0.5 . é"),
    *['"M0 0 L1 0"', '"hello"', '"M0 0 L1e999 0"', '"', '"fill:#000"', "\x00", "\t"],
]


@st.composite
def lsys_texts(draw) -> str:
    """Draw ``.lsys``-like text: mostly a header and lines of format tokens, sometimes raw text."""
    if draw(st.integers(0, 9)) == 0:
        return draw(st.text(max_size=80))
    lines = ["lsys 1"] if draw(st.integers(0, 4)) else []
    if draw(st.booleans()):
        lines.append('terminal A "M0 0 L1 0"')
    for _ in range(draw(st.integers(0, 6))):
        toks = draw(st.lists(st.sampled_from(_LSYS_TOKENS), max_size=12))
        lines.append(" ".join(toks))
    return draw(st.sampled_from(["\n", "\r\n", "\r"])).join(lines) + draw(st.sampled_from(["", "\n"]))


# ---------------------------------------------------------------------------
# CSS and path data on their own (fuzz targets of their parsers)

_CSS_TOKENS = _words(
    "rect path g svg * .a .b #i #x [x] [x=1] [fill~=red] :first-child :last-child :hover ::before "
    "> + ~ , { } ; : fill stroke opacity transform marker display none red #f00 url(#g) "
    "!important @import @media @font-face screen print 1 2.5 -3 1e9 nan inf em % px ' \" /* */ "
    "\\ \\41 ( ) [ ] <!-- --> @ url( rgb( hsl( calc("
)


@st.composite
def css_texts(draw) -> str:
    """Style sheets: token soups (unterminated strings, comments and blocks included)."""
    tokens = draw(st.lists(st.sampled_from(_CSS_TOKENS), max_size=60))
    seps = draw(st.lists(st.sampled_from(["", " ", "\n", "\t"]), min_size=len(tokens), max_size=len(tokens)))
    text = "".join(t + s for t, s in zip(tokens, seps, strict=True))
    if draw(st.booleans()):
        text += draw(st.text(max_size=40))
    return text


_PATH_TOKENS = _words(
    "M m L l H h V v C c S s Q q T t A a Z z 0 1 -1 .5 1e3 1e-3 -.5e+2 1.5.5 1e 1e400 nan , x"
)


@st.composite
def path_texts(draw) -> str:
    """Path data: command and number soups (flags without separators, broken numbers included)."""
    tokens = draw(st.lists(st.sampled_from(_PATH_TOKENS), max_size=80))
    seps = draw(st.lists(st.sampled_from(["", " ", ","]), min_size=len(tokens), max_size=len(tokens)))
    return "".join(t + s for t, s in zip(tokens, seps, strict=True))
