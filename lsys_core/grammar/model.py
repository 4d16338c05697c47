"""The parametric context-free L-system of the paper (§3, §5.1–§5.2), as immutable values.

Modules
-------
``f(Δ)``, ``+(δ)``, ``-(δ)``, ``*(s)``, ``z(Δ)``, ``~(t)``
    :class:`Turtle` commands; their value is linear in the rule's counter ``m``:
    ``t(m) = t0 + tΔ·m`` (:class:`Linear`).  ``z`` moves the turtle in paint order (later
    terminals with a larger ``z`` are drawn on top).  ``~`` adds to the turtle's *stretch*
    (format version 4): a terminal drawn with stretch ``t`` is cut along its local x axis
    (the line ``y = 0`` through its origin) and its two halves pulled apart by ``t``: every
    point with ``y > 0`` moves by ``+t/2`` along the local y axis, every point with ``y < 0``
    by ``-t/2`` (a piecewise translation, not a scale, so rounded corners and stroke widths
    stay as they are; exact for shapes whose segments crossing the cut are straight).  The
    stretch is in the terminal's own units, is saved by ``[`` and restored by ``]`` like the
    rest of the turtle state, starts at 0 and is summed like ``z``: a bar chart's bars of one
    width are one terminal, ``P(m) -> [ ~([16, 40, 8]) A ] f(22) P(m-1)``, and bars that grow
    by 16 per step are ``P(m): m > 0 -> A ~(16) f(22) P(m-1)``.
``[`` ``]``
    :class:`Push` / :class:`Pop` of the turtle state.
``A``, ``P(m-1)``, ``Q(3)``
    :class:`Symbol`: a terminal (draws its element at the turtle's pose, optionally with a
    :class:`Paint`: ``A{s2, opacity: 0.1*m}``) or a non-terminal, which may take an
    integer counter argument ``k0 + k1·m`` (:class:`Count`).

A :class:`Rule` rewrites one non-terminal; it has one or more :class:`Case` s with a
condition ``m > 0``, ``m == 0`` or none.  A :class:`Grammar` holds terminals (their SVG
path data and base style, in their own local frame), named styles, rules, the axiom, and
optional per-instance tables (styles and paint order of the derived instances).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Final, Literal

import numpy as np

__all__ = [
    "COND_EQ0",
    "COND_GT0",
    "PAINT_PROPS",
    "Case",
    "Count",
    "Grammar",
    "Linear",
    "Module",
    "NamedStyle",
    "Paint",
    "Pop",
    "Push",
    "Randomize",
    "Rule",
    "Symbol",
    "Terminal",
    "Turtle",
    "Verbatim",
]

COND_GT0: Final = "m > 0"
COND_EQ0: Final = "m == 0"
#: The condition of a case of a parametric rule.
CaseCondition = Literal["m > 0", "m == 0"]
Condition = CaseCondition | None
TurtleOp = Literal["f", "+", "-", "*", "z", "~"]
Jitter = Literal["cumulative", "instance"]
JITTERS: tuple[Jitter, ...] = ("cumulative", "instance")

#: Properties a :class:`Paint` may set to a value linear in ``m``: style numbers, ``hue``
#: (turns the fill and stroke colours, degrees) and ``z`` (added to the paint-order value).
PAINT_PROPS = ("opacity", "fill-opacity", "stroke-opacity", "stroke-width", "hue", "z")


@dataclass(frozen=True)
class Linear:
    """A value linear in the counter, ``c0 + cd * m``, or a table of values indexed by it.

    With a non-empty ``table`` (written ``[v0, v1, ...]``) the value at counter ``m`` is
    ``table[m mod len(table)]``: a sequence whose steps repeat one shape and one move while
    one number varies freely (the radii of concentric circles, the data offsets of a dot plot)
    or cycles (alternating sizes).  Tables stand in turtle values of rules with a counter;
    ``c0`` is then ``table[0]`` and ``cd`` 0, so code that reads only ``c0`` sees a value.
    """

    c0: float
    cd: float = 0.0
    table: tuple[float, ...] = ()

    @classmethod
    def of_table(cls, values) -> Linear:
        """Return the table value of ``values`` (at least one)."""
        table = tuple(float(v) for v in values)
        return cls(table[0], 0.0, table)

    def at(self, m):
        """Return the value at counter(s) ``m`` (an int or an integer numpy array)."""
        if self.table:
            return np.asarray(self.table)[np.asarray(m) % len(self.table)]
        return self.c0 + self.cd * m


@dataclass(frozen=True)
class Count:
    """An integer counter argument ``k0 + k1 * m`` (``m - 1`` is ``Count(-1, 1)``)."""

    k0: int
    k1: int = 0


@dataclass(frozen=True)
class Turtle:
    """A turtle command ``f``, ``+``, ``-``, ``*``, ``z`` or ``~`` with a value linear in ``m``."""

    op: TurtleOp
    value: Linear


@dataclass(frozen=True)
class Push:
    """``[``: push the turtle state."""


@dataclass(frozen=True)
class Pop:
    """``]``: pop the turtle state."""


@dataclass(frozen=True)
class Paint:
    """How one terminal occurrence is painted, over its terminal's base style.

    ``style`` names a :class:`NamedStyle` whose declarations override the terminal's;
    ``props`` set :data:`PAINT_PROPS` to values linear in the rule's counter (applied last).
    """

    style: str | None = None
    props: tuple[tuple[str, Linear], ...] = ()


@dataclass(frozen=True)
class Symbol:
    """A terminal or non-terminal symbol; ``arg`` is the counter passed to a parametric one.

    ``paint`` (terminals only) overrides the terminal's style for this occurrence.
    """

    name: str
    arg: Count | None = None
    paint: Paint | None = None


Module = Turtle | Push | Pop | Symbol


@dataclass(frozen=True)
class Case:
    """One production of a rule: ``cond`` (``"m > 0"``, ``"m == 0"`` or ``None``) and its body."""

    cond: Condition
    body: tuple[Module, ...]


@dataclass(frozen=True)
class Rule:
    """The productions of one non-terminal; ``parametric`` rules take a counter ``m``."""

    name: str
    parametric: bool
    cases: tuple[Case, ...]


@dataclass(frozen=True)
class Terminal:
    """A terminal symbol: an element's SVG path data and CSS style in its local frame.

    ``mirror_of`` names the terminal this one is a mirror image of (informative: the
    path data already is the mirrored shape).  Stroke widths and dashes of the style are in
    canvas units whatever the instance's scale, unless ``scaled`` (format version 1's
    meaning: they scale with the turtle).
    """

    name: str
    path: str
    style: str = ""
    mirror_of: str | None = None
    scaled: bool = False


@dataclass(frozen=True)
class NamedStyle:
    """A named set of CSS declarations, referenced by terminal occurrences (``A{s1}``)."""

    name: str
    css: str


@dataclass(frozen=True)
class Verbatim:
    """Input content kept as is, not turned into rules (``<text>``, ``<image>``, unknown elements).

    ``order`` is its place in the document's paint order, numbered like the input's drawable
    elements (see :attr:`lsys_core.svg.model.Element.order`); ``xml`` its self-contained SVG
    markup in document coordinates (ancestor transforms and inherited styles applied, e.g. by a
    wrapping ``<g>``); ``what`` a short description for reports ("<text> 'Hello'").
    """

    order: int
    xml: str
    what: str = ""


@dataclass(frozen=True)
class Randomize:
    """Seeded random perturbation of a derivation (the ``randomize`` line of an ``.lsys`` file).

    ``jitter="cumulative"``: every application of ``+``/``-`` in a rule gets ``U(-angle, angle)``
    degrees added, every ``f`` is multiplied by ``1 + U(-distance, distance)`` and every ``*`` by
    ``1 + U(-scale, scale)``; the turtle carries each perturbation on, so it accumulates along a
    sequence (a row drifts).  ``jitter="instance"``: every instance drawn by a rule is turned by
    ``U(-angle, angle)`` degrees about its origin, scaled by ``1 + U(-scale, scale)`` and moved
    by up to ``distance`` times the gap to its nearest neighbour along and across its heading;
    the next instance is placed as without noise.  The axiom is not perturbed.  The same seed
    gives the same drawing.
    """

    angle: float = 0.0
    distance: float = 0.0
    scale: float = 0.0
    seed: int = 0
    jitter: Jitter = "cumulative"

    @property
    def active(self) -> bool:
        """Whether any amount is non-zero."""
        return bool(self.angle or self.distance or self.scale)


@dataclass(frozen=True)
class Grammar:
    """A complete L-system: terminals, rules, axiom and the SVG canvas it draws on.

    ``viewbox`` is ``(x, y, width, height)`` of the SVG the grammar came from (None: fit);
    ``size`` the SVG's ``width`` and ``height`` attributes as written (or None).
    """

    terminals: tuple[Terminal, ...]
    rules: tuple[Rule, ...]
    axiom: tuple[Module, ...]
    viewbox: tuple[float, float, float, float] | None = None
    size: tuple[str, str] | None = None
    comments: tuple[str, ...] = field(default=(), compare=False)
    #: SVG markup the terminals' and instances' styles refer to by ``url(#id)`` (gradients,
    #: patterns, clip paths, masks, filters, markers): written into the output's ``<defs>``.
    defs: str = ""
    #: Content carried through verbatim.  In a grammar, a verbatim item's ``order`` is the
    #: number of derived instances (in paint order) drawn before it.
    verbatim: tuple[Verbatim, ...] = ()
    #: Named styles that terminal occurrences refer to (``A{s1}``) and :attr:`paint` lists.
    styles: tuple[NamedStyle, ...] = ()
    #: Per-instance named style (``None``: as the rules paint it) of the derived instances,
    #: in derivation order; instances past the end are painted as the rules say.
    paint: tuple[str | None, ...] = ()
    #: Per-instance paint-order offset added to the ``z`` of the derived instances, in
    #: derivation order; instances past the end get 0.
    order: tuple[float, ...] = ()
    #: The random perturbation the derivation applies (None: none).
    randomize: Randomize | None = None

    def terminal(self, name: str) -> Terminal | None:
        """Return the terminal called ``name``, or None."""
        for t in self.terminals:
            if t.name == name:
                return t
        return None

    def style(self, name: str) -> NamedStyle | None:
        """Return the named style called ``name``, or None."""
        for s in self.styles:
            if s.name == name:
                return s
        return None

    def rule(self, name: str) -> Rule | None:
        """Return the rule of non-terminal ``name``, or None."""
        for r in self.rules:
            if r.name == name:
                return r
        return None

    @property
    def production_count(self) -> int:
        """Number of productions, the ``m > 0`` and ``m == 0`` cases counted separately."""
        return sum(len(r.cases) for r in self.rules)
