"""Stage 1, input: read an SVG file safely into a :class:`Scene` of :class:`Element` s.

>>> from lsys_core.svg import load_svg   # doctest: +SKIP
>>> scene = load_svg("flag.svg")          # doctest: +SKIP
"""

from __future__ import annotations

from lsys_core.svg.model import Element, Scene
from lsys_core.svg.parse import load_svg, parse_svg

__all__ = ["Element", "Scene", "load_svg", "parse_svg"]
