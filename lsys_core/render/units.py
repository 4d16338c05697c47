"""Sizes for raster output: CSS lengths in pixels, colours given on the command line.

An SVG's ``width``/``height`` may carry a unit (``10cm``, ``4in``, ``72pt``).  CSS fixes
96 px to the inch, so :func:`length_px` turns such lengths into CSS pixels, and a PNG at
``dpi`` dots per inch has ``dpi / 96`` image pixels per CSS pixel.
"""

from __future__ import annotations

import math
import re

from lsys_core.errors import LsysError

__all__ = ["CSS_DPI", "length_px", "parse_color"]

#: CSS pixels per inch.
CSS_DPI = 96.0
#: CSS pixels per unit of the absolute CSS units.
UNITS = {
    "": 1.0,
    "px": 1.0,
    "in": CSS_DPI,
    "cm": CSS_DPI / 2.54,
    "mm": CSS_DPI / 25.4,
    "q": CSS_DPI / 101.6,
    "pt": CSS_DPI / 72.0,
    "pc": CSS_DPI / 6.0,
    "em": 16.0,  # the initial font size of CSS, what SVG viewers use on a root element
    "ex": 8.0,
}
_LENGTH = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([a-zA-Z]*)\s*")
_FUNCTION = re.compile(r"(?:rgba?|hsla?)\([-+0-9.eE%,\s/]*\)")
_HEX = re.compile(r"#(?:[0-9a-fA-F]{3,4}|[0-9a-fA-F]{6}|[0-9a-fA-F]{8})")


def length_px(text: str | None) -> float | None:
    """Return an absolute CSS length in CSS pixels, or None (missing, a percentage, unreadable, not positive).

    >>> length_px("2in"), length_px("72pt"), length_px("150")
    (192.0, 96.0, 150.0)
    >>> length_px("100%") is None
    True
    """
    if text is None:
        return None
    m = _LENGTH.fullmatch(text)
    if m is None or m.group(2).lower() not in UNITS:
        return None
    v = float(m.group(1)) * UNITS[m.group(2).lower()]
    return v if math.isfinite(v) and v > 0 else None


def parse_color(text: str) -> tuple[int, int, int, int]:
    """Return the RGBA bytes of a CSS colour (a name, ``#rgb[a]``, ``#rrggbb[aa]``, ``rgb()``, ``hsl()``, ``none``).

    Raises
    ------
    LsysError
        When ``text`` is not a colour.
    """
    from svgelements import Color

    t = text.strip().lower()
    if t in ("none", "transparent"):
        return (255, 255, 255, 0)
    named = t.isalpha() and (
        t == "black" or Color.parse(t) != Color.parse("black")
    )  # unknown names read as black
    known = _HEX.fullmatch(t) or _FUNCTION.fullmatch(t) or named
    if not known:
        raise LsysError(
            f"not a colour: {text!r} (use a CSS colour such as white, #ffffff or rgb(255,255,255))"
        )
    col = Color(t)
    return (col.red, col.green, col.blue, col.alpha)
