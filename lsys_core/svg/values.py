"""SVG attribute values: numbers, lengths and units, transforms, viewBox and preserveAspectRatio (colours: :mod:`.colors`).

Every reader here is a small scanner over the text (short plain numbers go through ``float``,
anything else through the vectorised number lexer of :mod:`lsys_core.geometry.numbers`); none
uses a backtracking regular expression, so the work is linear in the length of the value.
Readers return None for a value they cannot read; the caller decides what SVG does then (ignore
the attribute, or not draw the element).

Why not svgelements' ``Matrix`` and ``Length``: on the 5,127 distinct ``transform`` attributes of
the SVG test suite and the real files, ``Matrix`` gives the same matrices, but the ``transform``
style property (CSS units: ``rotate(30deg)``, ``translate(2px)``) needs this reader anyway, and
``Matrix`` is 3x slower (63 us against 20 us for ``translate(10,20) rotate(30)``).  ``Length``
reads 3 of 124 length values differently (``1lh`` and ``inherit`` as lengths).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from lsys_core.geometry.numbers import numbers_from_text

__all__ = [
    "IDENTITY",
    "Length",
    "Matrix",
    "Viewport",
    "invert",
    "multiply",
    "parse_length",
    "parse_number",
    "parse_numbers",
    "parse_transform",
    "parse_viewbox",
    "viewbox_transform",
]

Matrix = tuple[float, float, float, float, float, float]
IDENTITY: Matrix = (1.0, 0.0, 0.0, 1.0, 0.0, 0.0)

#: User units (px) per unit; font-relative and viewport-relative units are resolved by the caller.
ABSOLUTE_UNITS = {"": 1.0, "px": 1.0, "pt": 96 / 72, "pc": 16.0, "mm": 96 / 25.4, "cm": 96 / 2.54}
ABSOLUTE_UNITS |= {"in": 96.0, "q": 96 / 101.6}
RELATIVE_UNITS = frozenset({"%", "em", "ex", "rem", "ch", "vw", "vh", "vmin", "vmax"})


class Length(NamedTuple):
    """A number with its unit (lower case; ``""`` for a plain number)."""

    value: float
    unit: str


class Viewport(NamedTuple):
    """What relative lengths resolve against: the viewport size and the font sizes (user units)."""

    width: float
    height: float
    font_size: float = 16.0
    root_font_size: float = 16.0

    @property
    def diagonal(self) -> float:
        """The reference length of percentages that are neither horizontal nor vertical."""
        return math.sqrt((self.width**2 + self.height**2) / 2.0)


def parse_number(text: str | None) -> float | None:
    """Read one finite number (surrounding white space allowed), or None."""
    if text is None:
        return None
    t = text.strip()
    quick = _quick_numbers(t, one=True)
    if quick is not None:
        return quick[0]
    values, error = numbers_from_text(t)
    if error >= 0 or values.size != 1 or not math.isfinite(values[0]):
        return None
    return float(values[0])


def parse_numbers(text: str | None) -> list[float] | None:
    """Read a list of numbers separated by white space and/or commas, or None if malformed."""
    if text is None:
        return None
    quick = _quick_numbers(text.strip(), one=False)
    if quick is not None:
        return quick
    values, error = numbers_from_text(text)
    if error >= 0:
        return None
    return values.tolist()


#: Characters of plain SVG numbers; on such text Python's ``float`` reads exactly the SVG grammar.
_NUMBER_CHARS = frozenset("0123456789+-.eE")
#: Attribute values up to this length take the quick path (the vectorised lexer costs ~0.2 ms a call).
_QUICK_LENGTH = 256


def _quick_numbers(t: str, one: bool) -> list[float] | None:
    """Read short, plainly separated numbers with ``float``; None: let the lexer decide.

    Only text whose tokens are separated by white space or single commas, each token made of
    number characters and finite, is read here; anything else (``1-2``, ``.5.5``, ``1,,2``, huge
    exponents, errors) goes to :func:`numbers_from_text`, which gives the same answer on what
    both read.
    """
    if not t or len(t) > _QUICK_LENGTH:
        return None
    tokens = t.replace(",", " ").split()
    if one and len(tokens) != 1:
        return None
    if "," in t:
        compact = "".join(t.split())
        if compact[0] == "," or compact[-1] == "," or ",," in compact:
            return None
    out = []
    for tok in tokens:
        if not _NUMBER_CHARS.issuperset(tok):
            return None
        try:
            v = float(tok)
        except ValueError:
            return None
        if not math.isfinite(v):
            return None
        out.append(v)
    return out


def _split_unit(text: str) -> tuple[str, str]:
    """Split ``"12.5px"`` into ``("12.5", "px")`` (the unit is the trailing letters or ``%``)."""
    t = text.strip()
    if t.endswith("%"):
        return t[:-1], "%"
    i = len(t)
    while i > 0 and t[i - 1].isalpha():
        i -= 1
    unit = t[i:].lower()
    if unit in ("e",):  # "1e" is a malformed number, not a unit
        return t, ""
    return t[:i], unit


def parse_length(text: str | None) -> Length | None:
    """Read a length such as ``12``, ``1.5em``, ``50%`` or ``3mm``; None if malformed."""
    if text is None:
        return None
    number, unit = _split_unit(text)
    if unit not in ABSOLUTE_UNITS and unit not in RELATIVE_UNITS:
        return None
    v = parse_number(number)
    if v is None:
        return None
    return Length(v, unit)


def to_user(length: Length, vp: Viewport, axis: str = "o") -> float:
    """Convert a length to user units; ``axis`` ``x``/``y``/``o`` says what a percentage refers to."""
    v, unit = length
    if unit in ABSOLUTE_UNITS:
        return v * ABSOLUTE_UNITS[unit]
    if unit == "%":
        ref = vp.width if axis == "x" else vp.height if axis == "y" else vp.diagonal
        return v * ref / 100.0
    if unit == "em":
        return v * vp.font_size
    if unit in ("ex", "ch"):
        return v * vp.font_size / 2.0
    if unit == "rem":
        return v * vp.root_font_size
    if unit == "vw":
        return v * vp.width / 100.0
    if unit == "vh":
        return v * vp.height / 100.0
    if unit == "vmin":
        return v * min(vp.width, vp.height) / 100.0
    return v * max(vp.width, vp.height) / 100.0  # vmax


# ---------------------------------------------------------------------------
# Colours


def multiply(m: Matrix, n: Matrix) -> Matrix:
    """Return the affine product ``m @ n`` (``n`` applied first)."""
    a, b, c, d, e, f = m
    a2, b2, c2, d2, e2, f2 = n
    return (
        a * a2 + c * b2,
        b * a2 + d * b2,
        a * c2 + c * d2,
        b * c2 + d * d2,
        a * e2 + c * f2 + e,
        b * e2 + d * f2 + f,
    )


def invert(m: Matrix) -> Matrix | None:
    """Return the inverse of an affine matrix, or None if it is singular."""
    a, b, c, d, e, f = m
    det = a * d - b * c
    if det == 0 or not math.isfinite(det):
        return None
    ia, ib, ic, id_ = d / det, -b / det, -c / det, a / det
    return (ia, ib, ic, id_, -(ia * e + ic * f), -(ib * e + id_ * f))


_ARITY = {
    "matrix": (6,),
    "translate": (1, 2),
    "scale": (1, 2),
    "rotate": (1, 3),
    "skewx": (1,),
    "skewy": (1,),
}
_ANGLE_UNITS = {"deg": 1.0, "rad": 180.0 / math.pi, "grad": 0.9, "turn": 360.0}


def parse_transform(text: str | None, css: bool = False) -> Matrix | None:
    """Read a transform list (``translate(10 20) rotate(45)``); None if malformed.

    ``css`` accepts the CSS property syntax as well (``translate(10px, 20px)``, ``rotate(45deg)``).
    An empty text or ``none`` is the identity.
    """
    if text is None:
        return None
    t = text.strip()
    if not t or t.lower() == "none":
        return IDENTITY
    m = IDENTITY
    i, n = 0, len(t)
    while True:
        while i < n and (t[i].isspace() or t[i] == ","):
            i += 1
        if i >= n:
            return m
        j = i
        while j < n and t[j].isalpha():
            j += 1
        name = t[i:j].lower()
        k = j
        while k < n and t[k].isspace():
            k += 1
        if name not in _ARITY or k >= n or t[k] != "(":
            return None
        close = t.find(")", k)
        if close < 0:
            return None
        args = _transform_args(t[k + 1 : close], name, css)
        if args is None or len(args) not in _ARITY[name]:
            return None
        m = multiply(m, _one_transform(name, args))
        i = close + 1


def _transform_args(inner: str, name: str, css: bool) -> list[float] | None:
    """Read the arguments of one transform function (CSS units stripped when allowed)."""
    if not css:
        return parse_numbers(inner)
    out = []
    for part in inner.replace(",", " ").split():
        number, unit = _split_unit(part)
        v = parse_number(number)
        if v is None:
            return None
        if name in ("rotate", "skewx", "skewy") and unit:
            if unit not in _ANGLE_UNITS:
                return None
            v *= _ANGLE_UNITS[unit]
        elif unit not in ("", "px"):
            return None
        out.append(v)
    return out


def _one_transform(name: str, a: list[float]) -> Matrix:
    if name in ("rotate", "skewx", "skewy") and not math.isfinite(a[0]):
        nan = math.nan  # an overflowing angle (1e999): what it draws is skipped as non-finite
        return (nan, nan, nan, nan, nan, nan)
    if name == "matrix":
        return (a[0], a[1], a[2], a[3], a[4], a[5])
    if name == "translate":
        return (1.0, 0.0, 0.0, 1.0, a[0], a[1] if len(a) > 1 else 0.0)
    if name == "scale":
        return (a[0], 0.0, 0.0, a[1] if len(a) > 1 else a[0], 0.0, 0.0)
    if name == "rotate":
        r = math.radians(a[0])
        c, s = math.cos(r), math.sin(r)
        rot = (c, s, -s, c, 0.0, 0.0)
        if len(a) == 3:
            cx, cy = a[1], a[2]
            return multiply(multiply((1.0, 0.0, 0.0, 1.0, cx, cy), rot), (1.0, 0.0, 0.0, 1.0, -cx, -cy))
        return rot
    if name == "skewx":
        return (1.0, 0.0, math.tan(math.radians(a[0])), 1.0, 0.0, 0.0)
    return (1.0, math.tan(math.radians(a[0])), 0.0, 1.0, 0.0, 0.0)  # skewY


def parse_viewbox(text: str | None) -> tuple[float, float, float, float] | None:
    """Read a ``viewBox``: four finite numbers with positive width and height; None otherwise."""
    vals = parse_numbers(text) if text else None
    if vals is None or len(vals) != 4 or not all(math.isfinite(v) for v in vals):
        return None
    if vals[2] <= 0 or vals[3] <= 0:
        return None
    return (vals[0], vals[1], vals[2], vals[3])


def viewbox_transform(
    viewbox: tuple[float, float, float, float], x: float, y: float, w: float, h: float, par: str | None
) -> Matrix:
    """Return the matrix mapping a viewBox into the viewport ``(x, y, w, h)`` (preserveAspectRatio)."""
    vx, vy, vw, vh = viewbox
    words = (par or "").split()
    if words and words[0] == "defer":
        words = words[1:]
    align = words[0] if words else "xMidYMid"
    slice_ = len(words) > 1 and words[1] == "slice"
    sx, sy = w / vw, h / vh
    if align == "none":
        return (sx, 0.0, 0.0, sy, x - vx * sx, y - vy * sy)
    s = max(sx, sy) if slice_ else min(sx, sy)
    tx, ty = x - vx * s, y - vy * s
    if len(align) == 8 and align[0] == "x" and align[4] == "Y":
        ax, ay = align[1:4], align[5:8]
    else:
        ax, ay = "Mid", "Mid"
    if ax == "Mid":
        tx += (w - vw * s) / 2
    elif ax == "Max":
        tx += w - vw * s
    if ay == "Mid":
        ty += (h - vh * s) / 2
    elif ay == "Max":
        ty += h - vh * s
    return (s, 0.0, 0.0, s, tx, ty)
