"""lsys_core: inverse procedural modelling of vector art with parametric L-systems.

The library has no Qt dependency.  The main entry points are re-exported here:

>>> from lsys_core import parse_grammar, format_grammar, derive   # doctest: +SKIP
"""

from __future__ import annotations

__version__ = "0.1.0"
