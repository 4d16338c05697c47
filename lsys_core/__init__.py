"""lsys_core: inverse procedural modelling of vector art with parametric L-systems.

The library has no Qt dependency.  Its sub-packages are the stages of the paper's pipeline, each
importing only the ones listed before it (checked by import-linter, see ``pyproject.toml``):

``geometry`` → ``grammar`` → ``svg`` → ``instancing`` → ``hierarchy`` → ``derive`` → ``render``
→ ``pipeline``, ``cli``

>>> from lsys_core.svg import load_svg                 # doctest: +SKIP
>>> from lsys_core.pipeline import infer              # doctest: +SKIP
>>> from lsys_core.grammar import format_grammar       # doctest: +SKIP
>>> result = infer(load_svg("stars.svg"))             # doctest: +SKIP
>>> print(format_grammar(result.grammar))             # doctest: +SKIP
"""

from __future__ import annotations

__version__ = "0.1.0"
