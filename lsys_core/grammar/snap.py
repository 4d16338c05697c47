"""Clean numbers: the simplest value within a tolerance (0° over 0.44°, 1 over 1.0000001).

Inferred rules carry measurement noise: ``*(1.0000001)``, ``+(0.44)``, ``18.503999999999998``.
Within the tolerance the inference worked with, the simplest value is as true as the measured
one and reads (and compresses) better.  "Simplest" follows a ladder of steps, coarse to fine:

angles
    multiples of 90°, 45°, 30°, 15°, 10°, 5°; then exact fractions of 360° (``360/7``: a ring of
    seven closes exactly; a known ring count is tried first); then 1°, 0.5°, 0.1°, 0.05°, …
scales and other factors
    1, then values with one, two, three … decimals
distances and the rest
    multiples of 10, 5, 1, 0.5, then one, two, three … decimals

:func:`snap` returns the first ladder value within the tolerance (the value itself when none is),
:func:`snap_params` cleans every parameter of a grammar at once, and :func:`decimals_for` says
how many decimals a value needs to be shown at a precision.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping

from lsys_core.grammar.model import Grammar
from lsys_core.grammar.params import list_params, set_params

__all__ = ["DEFAULT_TOLERANCES", "decimals_for", "snap", "snap_params"]

#: Tolerance per parameter kind used by :func:`snap_params` when none is given: degrees for
#: angles, a relative amount for scales, an absolute amount for distances (document units).
DEFAULT_TOLERANCES: dict[str, float] = {
    "angle": 0.5,
    "angle_delta": 0.05,
    "scale": 0.0005,
    "scale_delta": 0.00005,
    "distance": 0.05,
    "distance_delta": 0.005,
}
_ANGLE_STEPS = (90.0, 45.0, 30.0, 15.0, 10.0, 5.0)
_RING_COUNTS = tuple(n for n in range(7, 37) if 360 % n)  # those 360/n that are not whole degrees


def _decimal_steps(start: int) -> Iterator[float]:
    """Yield ``10**start``, ``10**(start-1)``, … down to ``1e-12``."""
    for e in range(start, -13, -1):
        yield 10.0**e


def _ladder(kind: str, ring: int | None) -> Iterator[float]:
    """Yield the steps of the ladder for a parameter ``kind`` (see the module docstring)."""
    if kind.startswith("angle"):
        if ring:
            yield 360.0 / ring
        yield from _ANGLE_STEPS
        for n in _RING_COUNTS:
            yield 360.0 / n
        yield 1.0
        for step in _decimal_steps(-1):
            yield 5 * step
            yield step
    elif kind.startswith("scale"):
        yield from _decimal_steps(0)
    elif kind == "count":
        yield 1.0
    else:
        yield from (10.0, 5.0, 1.0, 0.5)
        yield from _decimal_steps(-1)


def snap(value: float, tolerance: float, kind: str = "distance", *, ring: int | None = None) -> float:
    """Return the simplest value within ``tolerance`` of ``value`` (``value`` itself if none is).

    Parameters
    ----------
    value : float
        The measured value.
    tolerance : float
        Largest change allowed (absolute, in the value's unit; for ``scale`` kinds relative to
        the value).  0 keeps the value.
    kind : str
        A :data:`lsys_core.grammar.params.KINDS` kind: ``angle``, ``scale``, ``distance``, their
        ``_delta`` forms or ``count``.
    ring : int, optional
        The count of a ring: ``360/ring`` (and its multiples) come first for angles.

    Returns
    -------
    float
        A multiple of the coarsest ladder step that lies within the tolerance, rounded to
        the shortest decimal text that stands for it exactly enough (``0.1``, not
        ``0.30000000000000004``).
    """
    if not math.isfinite(value) or tolerance <= 0:
        return value
    tol = abs(value) * tolerance if kind == "scale" else tolerance
    if kind == "count":
        return float(round(value)) if abs(value - round(value)) <= max(tol, 0.5) else value
    for step in _ladder(kind, ring):
        if step < tol * 1e-6:
            break
        candidate = round(value / step) * step
        if abs(candidate - value) <= tol:
            return _tidy(candidate, step)
    return value


def _tidy(x: float, step: float) -> float:
    """Return ``x`` with the float noise of ``k * step`` removed (``0.1 * 3`` → ``0.3``)."""
    if x == 0:
        return 0.0
    digits = max(0, -math.floor(math.log10(step)) + 1) if step < 1 else 0
    tidy = round(x, digits + 6)
    return float(f"{tidy:.{min(17, digits + 12)}g}") if abs(tidy - x) <= abs(step) * 1e-9 else x


def decimals_for(value: float, precision: float) -> int:
    """Return how many decimals show ``value`` to within ``precision`` (0 to 9)."""
    for d in range(10):
        if abs(round(value, d) - value) <= precision:
            return d
    return 9


def snap_params(grammar: Grammar, tolerances: Mapping[str, float] | None = None) -> Grammar:
    """Return ``grammar`` with every turtle value snapped to its simplest value within tolerance.

    Parameters
    ----------
    grammar : Grammar
        The grammar to clean (left untouched).
    tolerances : mapping, optional
        Tolerance per parameter kind (default :data:`DEFAULT_TOLERANCES`); counts are kept.

    Returns
    -------
    Grammar
        The cleaned grammar (the same object when nothing changed).
    """
    tol = dict(DEFAULT_TOLERANCES if tolerances is None else tolerances)
    changes = {}
    for p in list_params(grammar):
        if p.kind == "count" or p.kind not in tol:
            continue
        new = snap(p.value, tol[p.kind], p.kind)
        if p.kind == "scale" and new <= 0:
            continue
        if new != p.value:
            changes[p.key] = new
    return set_params(grammar, changes) if changes else grammar
