"""CSS colours: ``#hex``, ``rgb()``/``hsl()`` (legacy and CSS Color 4 syntax) and the named colours.

Why not svgelements' ``Color`` (the rest of the program uses its ``Color``
on colours this module wrote): on the 513 distinct colour values of the SVG test suite, the real
files and a few CSS Color 4 cases, svgelements reads 23 differently -- an invalid colour becomes
black instead of being ignored (``#12``, ``rgb(1,2)``, ``context-fill``), the space and ``/``
syntax (``rgb(0 128 0 / 50%)``), upper-case function names, ``deg`` and percentage alpha are not
read, and fractional or overflowing ``rgb()`` arguments raise.  Each of these changes what the
input draws.  Speed is not the reason: with the quick path, a colour, length or transform here
takes 5-10 us (svgelements' ``Color``: 24 us).
"""

from __future__ import annotations

import colorsys

from lsys_core.svg.values import parse_number

__all__ = ["NAMED_COLORS", "hex_of", "parse_color"]

NAMED_COLORS: dict[str, tuple[int, int, int]] = {
    "aliceblue": (250, 248, 255),
    "antiquewhite": (250, 235, 215),
    "aqua": (0, 255, 255),
    "aquamarine": (127, 255, 212),
    "azure": (240, 255, 255),
    "beige": (245, 245, 220),
    "bisque": (255, 228, 196),
    "black": (0, 0, 0),
    "blanchedalmond": (255, 235, 205),
    "blue": (0, 0, 255),
    "blueviolet": (138, 43, 226),
    "brown": (165, 42, 42),
    "burlywood": (222, 184, 135),
    "cadetblue": (95, 158, 160),
    "chartreuse": (127, 255, 0),
    "chocolate": (210, 105, 30),
    "coral": (255, 127, 80),
    "cornflowerblue": (100, 149, 237),
    "cornsilk": (255, 248, 220),
    "crimson": (220, 20, 60),
    "cyan": (0, 255, 255),
    "darkblue": (0, 0, 139),
    "darkcyan": (0, 139, 139),
    "darkgoldenrod": (184, 134, 11),
    "darkgray": (169, 169, 169),
    "darkgreen": (0, 100, 0),
    "darkgrey": (169, 169, 169),
    "darkkhaki": (189, 183, 107),
    "darkmagenta": (139, 0, 139),
    "darkolivegreen": (85, 107, 47),
    "darkorange": (255, 140, 0),
    "darkorchid": (153, 50, 204),
    "darkred": (139, 0, 0),
    "darksalmon": (233, 150, 122),
    "darkseagreen": (143, 188, 143),
    "darkslateblue": (72, 61, 139),
    "darkslategray": (47, 79, 79),
    "darkslategrey": (47, 79, 79),
    "darkturquoise": (0, 206, 209),
    "darkviolet": (148, 0, 211),
    "deeppink": (255, 20, 147),
    "deepskyblue": (0, 191, 255),
    "dimgray": (105, 105, 105),
    "dimgrey": (105, 105, 105),
    "dodgerblue": (30, 144, 255),
    "firebrick": (178, 34, 34),
    "floralwhite": (255, 250, 240),
    "forestgreen": (34, 139, 34),
    "fuchsia": (255, 0, 255),
    "gainsboro": (220, 220, 220),
    "ghostwhite": (248, 248, 255),
    "gold": (255, 215, 0),
    "goldenrod": (218, 165, 32),
    "gray": (128, 128, 128),
    "grey": (128, 128, 128),
    "green": (0, 128, 0),
    "greenyellow": (173, 255, 47),
    "honeydew": (240, 255, 240),
    "hotpink": (255, 105, 180),
    "indianred": (205, 92, 92),
    "indigo": (75, 0, 130),
    "ivory": (255, 255, 240),
    "khaki": (240, 230, 140),
    "lavender": (230, 230, 250),
    "lavenderblush": (255, 240, 245),
    "lawngreen": (124, 252, 0),
    "lemonchiffon": (255, 250, 205),
    "lightblue": (173, 216, 230),
    "lightcoral": (240, 128, 128),
    "lightcyan": (224, 255, 255),
    "lightgoldenrodyellow": (250, 250, 210),
    "lightgray": (211, 211, 211),
    "lightgreen": (144, 238, 144),
    "lightgrey": (211, 211, 211),
    "lightpink": (255, 182, 193),
    "lightsalmon": (255, 160, 122),
    "lightseagreen": (32, 178, 170),
    "lightskyblue": (135, 206, 250),
    "lightslategray": (119, 136, 153),
    "lightslategrey": (119, 136, 153),
    "lightsteelblue": (176, 196, 222),
    "lightyellow": (255, 255, 224),
    "lime": (0, 255, 0),
    "limegreen": (50, 205, 50),
    "linen": (250, 240, 230),
    "magenta": (255, 0, 255),
    "maroon": (128, 0, 0),
    "mediumaquamarine": (102, 205, 170),
    "mediumblue": (0, 0, 205),
    "mediumorchid": (186, 85, 211),
    "mediumpurple": (147, 112, 219),
    "mediumseagreen": (60, 179, 113),
    "mediumslateblue": (123, 104, 238),
    "mediumspringgreen": (0, 250, 154),
    "mediumturquoise": (72, 209, 204),
    "mediumvioletred": (199, 21, 133),
    "midnightblue": (25, 25, 112),
    "mintcream": (245, 255, 250),
    "mistyrose": (255, 228, 225),
    "moccasin": (255, 228, 181),
    "navajowhite": (255, 222, 173),
    "navy": (0, 0, 128),
    "oldlace": (253, 245, 230),
    "olive": (128, 128, 0),
    "olivedrab": (107, 142, 35),
    "orange": (255, 165, 0),
    "orangered": (255, 69, 0),
    "orchid": (218, 112, 214),
    "palegoldenrod": (238, 232, 170),
    "palegreen": (152, 251, 152),
    "paleturquoise": (175, 238, 238),
    "palevioletred": (219, 112, 147),
    "papayawhip": (255, 239, 213),
    "peachpuff": (255, 218, 185),
    "peru": (205, 133, 63),
    "pink": (255, 192, 203),
    "plum": (221, 160, 221),
    "powderblue": (176, 224, 230),
    "purple": (128, 0, 128),
    "rebeccapurple": (102, 51, 153),
    "red": (255, 0, 0),
    "rosybrown": (188, 143, 143),
    "royalblue": (65, 105, 225),
    "saddlebrown": (139, 69, 19),
    "salmon": (250, 128, 114),
    "sandybrown": (244, 164, 96),
    "seagreen": (46, 139, 87),
    "seashell": (255, 245, 238),
    "sienna": (160, 82, 45),
    "silver": (192, 192, 192),
    "skyblue": (135, 206, 235),
    "slateblue": (106, 90, 205),
    "slategray": (112, 128, 144),
    "slategrey": (112, 128, 144),
    "snow": (255, 250, 250),
    "springgreen": (0, 255, 127),
    "steelblue": (70, 130, 180),
    "tan": (210, 180, 140),
    "teal": (0, 128, 128),
    "thistle": (216, 191, 216),
    "tomato": (255, 99, 71),
    "turquoise": (64, 224, 208),
    "violet": (238, 130, 238),
    "wheat": (245, 222, 179),
    "white": (255, 255, 255),
    "whitesmoke": (245, 245, 245),
    "yellow": (255, 255, 0),
    "yellowgreen": (154, 205, 50),
}


def parse_color(text: str, current: tuple[float, float, float, float] | None = None):
    """Read a CSS colour into ``(r, g, b, a)`` with components in [0, 1]; None if it is not one.

    Accepts ``#rgb``, ``#rgba``, ``#rrggbb``, ``#rrggbbaa``, ``rgb()``/``rgba()`` (numbers or
    percentages, commas or spaces, ``/ alpha``), ``hsl()``/``hsla()``, the named colours,
    ``transparent`` and ``currentColor`` (``current``, black if not given).
    """
    t = text.strip()
    low = t.lower()
    if low.startswith("#"):
        return _hex_color(low[1:])
    if low == "currentcolor":
        return current if current is not None else (0.0, 0.0, 0.0, 1.0)
    if low == "transparent":
        return (0.0, 0.0, 0.0, 0.0)
    if low in NAMED_COLORS:
        r, g, b = NAMED_COLORS[low]
        return (r / 255.0, g / 255.0, b / 255.0, 1.0)
    open_at = low.find("(")
    if open_at < 0 or not low.endswith(")"):
        return None
    func = low[:open_at].strip()
    inner = low[open_at + 1 : -1]
    if func in ("rgb", "rgba"):
        return _functional(inner, rgb=True)
    if func in ("hsl", "hsla"):
        return _functional(inner, rgb=False)
    return None


def _hex_color(h: str):
    if not all(c in "0123456789abcdef" for c in h):
        return None
    if len(h) in (3, 4):
        vals = [int(c * 2, 16) for c in h]
    elif len(h) in (6, 8):
        vals = [int(h[i : i + 2], 16) for i in range(0, len(h), 2)]
    else:
        return None
    if len(vals) == 3:
        vals.append(255)
    return (vals[0] / 255.0, vals[1] / 255.0, vals[2] / 255.0, vals[3] / 255.0)


def _component(text: str) -> tuple[float, bool] | None:
    """Read a number or percentage; return (value, is_percentage)."""
    t = text.strip()
    pct = t.endswith("%")
    v = parse_number(t[:-1] if pct else t)
    return None if v is None else (v, pct)


def _functional(inner: str, rgb: bool):
    """Read the arguments of ``rgb()``/``hsl()`` (legacy commas or modern spaces and ``/``)."""
    alpha_text = None
    if "/" in inner:
        inner, _, alpha_text = inner.partition("/")
        parts = inner.split()
    elif "," in inner:
        parts = [p for p in inner.split(",")]
        if len(parts) == 4:
            alpha_text = parts.pop()
    else:
        parts = inner.split()
    if len(parts) != 3:
        return None
    comps = [_component(p.removesuffix("deg") if i == 0 and not rgb else p) for i, p in enumerate(parts)]
    if any(c is None for c in comps):
        return None
    alpha = 1.0
    if alpha_text is not None:
        a = _component(alpha_text)
        if a is None:
            return None
        alpha = a[0] / 100.0 if a[1] else a[0]
    alpha = min(max(alpha, 0.0), 1.0)
    if rgb:
        out = [(v * 2.55 if pct else v) for v, pct in comps]  # type: ignore[misc]
        r, g, b = (min(max(round(x), 0), 255) / 255.0 for x in out)
        return (r, g, b, alpha)
    (h, _), (s, _), (l, _) = comps  # type: ignore[misc]
    s = min(max(s / 100.0, 0.0), 1.0)
    l = min(max(l / 100.0, 0.0), 1.0)
    r, g, b = colorsys.hls_to_rgb((h % 360.0) / 360.0, l, s)
    return (round(r * 255) / 255.0, round(g * 255) / 255.0, round(b * 255) / 255.0, alpha)


def hex_of(color: tuple[float, float, float, float]) -> str:
    """Write the opaque part of a colour as ``#rrggbb``."""
    r, g, b = (min(max(round(c * 255), 0), 255) for c in color[:3])
    return f"#{r:02x}{g:02x}{b:02x}"


# ---------------------------------------------------------------------------
# Transforms and viewports
