"""The parametric L-system: model, ``.lsys`` text, validation and named parameters.

>>> from lsys_core.grammar import parse_grammar, list_params, set_param   # doctest: +SKIP
"""

from __future__ import annotations

from lsys_core.grammar.model import (
    COND_EQ0,
    COND_GT0,
    Case,
    Count,
    Grammar,
    Linear,
    Module,
    NamedStyle,
    Paint,
    Pop,
    Push,
    Randomize,
    Rule,
    Symbol,
    Terminal,
    Turtle,
)
from lsys_core.grammar.params import Param, list_params, set_param, set_params
from lsys_core.grammar.text import format_grammar, parse_grammar
from lsys_core.grammar.validate import validate

__all__ = [
    "COND_EQ0",
    "COND_GT0",
    "Case",
    "Count",
    "Grammar",
    "Linear",
    "Module",
    "NamedStyle",
    "Paint",
    "Param",
    "Pop",
    "Push",
    "Randomize",
    "Rule",
    "Symbol",
    "Terminal",
    "Turtle",
    "format_grammar",
    "list_params",
    "parse_grammar",
    "set_param",
    "set_params",
    "validate",
]
