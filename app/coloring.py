"""Colouring the drawing by similarity group or by rule, and the legend of those colours.

The canvas shows a copy of the derived drawing whose instances are recoloured
(:func:`recolor`), made on the render worker; the legend (:func:`legend`) says which colour
is which terminal or rule.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

__all__ = ["PALETTE", "group_color", "legend", "recolor", "rule_color"]

#: Colours cycled for the colour-by-group / colour-by-rule modes.
PALETTE = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#d62728",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#7f7f7f",
    "#bcbd22",
    "#17becf",
    "#393b79",
    "#e7ba52",
    "#637939",
    "#ad494a",
    "#7b4173",
    "#3182bd",
)


def _style_with_color(style: str, color: str) -> str:
    """Return CSS declarations with fill and stroke (where painted) set to ``color``."""
    decls = {}
    for part in style.split(";"):
        if ":" in part:
            k, v = part.split(":", 1)
            decls[k.strip()] = v.strip()
    if decls.get("fill", "black") != "none":
        decls["fill"] = color
    if decls.get("stroke", "none") != "none":
        decls["stroke"] = color
    return ";".join(f"{k}:{v}" for k, v in decls.items())


def group_color(terminal: int) -> str:
    """Return the colour of terminal index ``terminal`` (a similarity group) in colour-by-group mode."""
    return PALETTE[terminal % len(PALETTE)]


def rule_color(rule: int) -> str:
    """Return the colour of rule index ``rule`` (-1: the axiom) in colour-by-rule mode."""
    return PALETTE[(rule + 1) % len(PALETTE)]


def legend(grammar: Any, mode: str) -> list[tuple[str, str]]:
    """Return ``(colour, what)`` for every colour the canvas uses in ``mode`` (none: empty)."""
    if grammar is None or mode == "none":
        return []
    if mode == "group":
        return [(group_color(i), f"terminal {t.name}") for i, t in enumerate(grammar.terminals)]
    return [(rule_color(-1), "Start (axiom)")] + [
        (rule_color(i), r.name) for i, r in enumerate(grammar.rules)
    ]


def recolor(drawing: Any, mode: str) -> Any:
    """Return ``drawing`` with its instances' styles coloured by similarity group or by rule.

    ``mode`` is ``"none"`` (unchanged), ``"group"`` (one colour per terminal symbol, i.e. per
    similarity group) or ``"rule"`` (one colour per rule that emitted the instance).  Each
    instance keeps its own style (opacity, stroke width, …) with fill and stroke recoloured.
    """
    if mode == "none" or drawing is None or len(drawing) == 0:
        return drawing
    styles, style = drawing.instance_styles()
    key = np.asarray(drawing.base_symbol() if mode == "group" else drawing.rule, np.int64)
    color = group_color if mode == "group" else rule_color
    pairs, inverse = np.unique(np.stack([style, key], axis=1), axis=0, return_inverse=True)
    styled = tuple(_style_with_color(styles[s], color(k)) for s, k in pairs.tolist())
    return dataclasses.replace(drawing, styles=styled, style=inverse.reshape(-1).astype(np.int32))
