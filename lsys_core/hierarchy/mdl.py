"""Description length of grammars, in bits (minimum description length, MDL).

The inference keeps a rule only when the grammar with it is *shorter* than the grammar
without it — Rissanen's minimum description length principle (J. Rissanen, "Modeling by
shortest data description", Automatica 14, 1978), which inverse procedural modeling uses to
choose among grammars (e.g. Talton et al., "Learning design patterns with Bayesian grammar
induction", UIST 2012; Martinović and Van Gool, "Bayesian grammar learning for inverse
procedural modeling", CVPR 2013).  A rule that merely restates chance coincidences does not
shorten the description and is not written.

The code used here counts what a grammar must say, at the precision the user's tolerance
``eps`` (a length) implies:

* a number is worth ``log2(range / precision)`` bits: a distance ``log2(2·D/eps)`` (``D`` the
  drawing's diagonal), an angle ``log2(2π·D/eps)`` (a turn moves the far end of the drawing
  by at most ``eps``), a scale ``log2(2·ln 100·D/eps)``; a counter ``m`` costs ``2·log2(m+1)+1``
  (Elias' gamma code); naming a symbol costs ``log2 K`` bits, ``K`` the size of the alphabet
  (symbols plus turtle commands), a turtle command 2 bits;
* a rule of one of the paper's kinds (a pair ``X T Y``, a sequence r1/r2, a branching r3/r4) is
  coded by its kind, the symbols it repeats and its transform's numbers; any other rule token
  by token;
* elements placed one by one (the catch-all rule) are coded as *sets*: ``N`` placements of
  one symbol among the ``C = area/eps²`` cells of the drawing cost ``log2 binom(C, N)``
  (their order carries no information), plus a heading and a scale each when they vary
  within the set.  With this code ``N`` random placements cannot be shortened by chance
  pairs: coding the pairs as a set of their own costs more than they save.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.special import gammaln

__all__ = [
    "COMMANDS",
    "KIND_BITS",
    "OP_BITS",
    "Precision",
    "angle_value_bits",
    "count_bits",
    "log2_binom",
    "placement_set_bits",
    "pose_bits",
    "shape_bits",
    "stack_table",
    "table_bits",
    "token_bits",
    "transform_bits",
]

#: Tokens besides symbols: the turtle commands ``f + - *``, brackets and the two conditions.
COMMANDS = 8
#: Bits naming the kind of a rule (pair, sequence, branching, other).
KIND_BITS = 2.0
#: Bits of a turtle command's operator, of a bracket, of a condition and of a self-reference ``P(m-1)``.
OP_BITS = 2.0
#: Scales are coded as ``ln s`` in ``[-ln 100, ln 100]``.
_LOG_SCALE_RANGE = 2.0 * math.log(100.0)
#: A placement's heading or scale "varies" within a set when it moves the shape's rim by more than
#: this share of the tolerance.
_VARY = 0.5


@dataclass(frozen=True)
class Precision:
    """The precision a description is written at: the tolerance ``eps`` in a drawing of a given size.

    Attributes
    ----------
    eps : float
        The tolerance, a length in document units (> 0).
    diagonal : float
        Diagonal of the drawing's bounding box.
    area : float
        Area of the drawing's bounding box.
    """

    eps: float
    diagonal: float
    area: float

    @classmethod
    def of_box(cls, lo: complex, hi: complex, eps: float) -> Precision:
        """The precision for a drawing whose bounding box has corners ``lo`` and ``hi``."""
        w, h = float(hi.real - lo.real), float(hi.imag - lo.imag)
        diag = max(math.hypot(w, h), 1e-12)
        eps = min(max(float(eps), 1e-9 * diag), diag)
        return cls(eps, diag, max(w, eps) * max(h, eps))

    @classmethod
    def of_circles(cls, center: np.ndarray, radius: np.ndarray, eps: float) -> Precision:
        """The precision for a drawing given as bounding circles of its elements."""
        lo = complex(np.min(center.real - radius), np.min(center.imag - radius))
        hi = complex(np.max(center.real + radius), np.max(center.imag + radius))
        return cls.of_box(lo, hi, eps)

    def relaxed(self, eps: float) -> Precision:
        """The same drawing at another tolerance."""
        return Precision(min(max(float(eps), 1e-9 * self.diagonal), self.diagonal), self.diagonal, self.area)

    @property
    def cells(self) -> float:
        """Places an element can be put at: the drawing's area in ``eps``-sized cells."""
        return max(self.area / self.eps**2, 2.0)

    @property
    def length_bits(self) -> float:
        """Bits of a signed distance."""
        return math.log2(2.0 * self.diagonal / self.eps + 1.0)

    def angle_bits(self, lever: float | None = None) -> float:
        """Bits of an angle: its turn moves points ``lever`` away (default: the diagonal) by ``eps`` at most."""
        return math.log2(2.0 * math.pi * (self.diagonal if lever is None else lever) / self.eps + 1.0)

    def scale_bits(self, lever: float | None = None) -> float:
        """Bits of a scale factor (coded as its logarithm), for shapes of radius ``lever``."""
        return math.log2(_LOG_SCALE_RANGE * (self.diagonal if lever is None else lever) / self.eps + 1.0)

    def cell_ids(self, z: np.ndarray) -> np.ndarray:
        """The ``eps``-sized grid cell of every point ``z`` (one integer each)."""
        z = np.asarray(z, complex) / self.eps
        q = np.column_stack([np.floor(z.real), np.floor(z.imag)])
        return np.unique(q, axis=0, return_inverse=True)[1].ravel()

    def varies(self, a: np.ndarray, lever: np.ndarray) -> tuple[bool, bool]:
        """Whether the headings and the scales of poses ``a`` differ visibly (shapes of radius ``lever``)."""
        if a.size < 2:
            return False, False
        unit = a / np.maximum(np.abs(a), 1e-300)
        mean = np.mean(unit)
        mean = mean / abs(mean) if abs(mean) > 1e-12 else 1.0
        turn = float(np.max(np.abs(unit - mean) * lever))
        ls = np.log(np.maximum(np.abs(a), 1e-300))
        scale = float(np.max(np.abs(ls - np.mean(ls)) * lever))
        return turn > _VARY * self.eps, scale > _VARY * self.eps

    def pose_model(self, a: np.ndarray, lever: np.ndarray) -> tuple[float, float]:
        """How the headings and scales of poses ``a`` (shapes reaching ``lever`` from their origin) are coded.

        Returns the number of distinguishable headings (0 when all are alike, so none is
        written) and the bits of every scale (0 when all are alike).
        """
        turns, scales = self.varies(a, lever)
        size = float(np.median(lever)) if np.size(lever) else 0.0
        headings = 2.0 * math.pi * size / self.eps + 1.0 if turns else 0.0
        return headings, (self.scale_bits(size) if scales else 0.0)


def pose_bits(headings: float, scale: float, stacks) -> float:
    """Bits of the headings and scales of placements stacked ``stacks[i]`` to a cell.

    Placements at one place are told apart by their headings alone, so those form a set:
    ``log2 C(headings, k)`` for a stack of ``k`` (its order carries no information).
    """
    k = np.asarray(stacks, dtype=float)
    bits = float(np.sum(k)) * scale
    if headings > 0:
        bits += float(np.sum(log2_binom(np.maximum(headings, k), k)))
    return bits


def stack_table(headings: float, kmax: int) -> np.ndarray:
    """``log2 C(max(headings, k), k)`` for the stacks ``k = 0 … kmax``: what :func:`pose_bits` sums.

    ``table[stacks].sum()`` is bit for bit ``pose_bits``' sum of the same terms (the same values
    in the same order), without a ``gammaln`` per cell; a ledger weighs each term by the cells
    of that height (see :class:`~lsys_core.hierarchy.gain.Ledger`).
    """
    k = np.arange(int(kmax) + 1, dtype=float)
    return log2_binom(np.maximum(headings, k), k)


def log2_binom(n: float, k):
    """``log2`` of the binomial coefficient ``C(n, k)`` (real ``n``; ``k`` scalar or array)."""
    k = np.asarray(k, dtype=float)
    return (gammaln(n + 1.0) - gammaln(k + 1.0) - gammaln(n - k + 1.0)) / math.log(2.0)


@lru_cache(maxsize=1 << 16)
def _log2_binom_scalar(n: float, k: float) -> float:
    """:func:`log2_binom` of one ``(n, k)``, remembered: the same few counts come back at every candidate."""
    return float(log2_binom(n, k))


def count_bits(m) -> np.ndarray:
    """Bits of counters ``m >= 0``: Elias' gamma code of ``m + 1``, ``2·floor(log2(m+1)) + 1``."""
    return 2.0 * np.floor(np.log2(np.asarray(m, dtype=float) + 1.0)) + 1.0


def token_bits(n_symbols: int) -> float:
    """Bits naming one symbol of an alphabet of ``n_symbols`` terminals and non-terminals."""
    return math.log2(n_symbols + COMMANDS)


def placement_set_bits(prec: Precision, n, *, occupied=None, pose=0.0, counts=0.0, token: float = 0.0):
    """Bits of ``n`` placements of one symbol as a set (vectorised over arrays of ``n``).

    The placements occupy ``occupied`` distinct cells (default: ``n``, all apart); the code
    names those cells, then how many placements share each (a composition of ``n``).

    Parameters
    ----------
    prec : Precision
        The precision.
    n : int or ndarray
        Number of placements (0 costs nothing).
    occupied : int or ndarray, optional
        Number of distinct cells they occupy.
    pose : float or ndarray
        Bits of all their headings and scales (:func:`pose_bits`).
    counts : float or ndarray
        Bits of the placements' counters, if the symbol takes one.
    token : float
        Bits naming the symbol once.
    """
    if np.ndim(n) == 0 and np.ndim(occupied) == 0 and np.ndim(pose) == 0 and np.ndim(counts) == 0:
        return _placement_set_bits_scalar(prec, float(n), occupied, float(pose), float(counts), token)
    n = np.asarray(n, dtype=float)
    u = n if occupied is None else np.clip(np.asarray(occupied, dtype=float), np.minimum(n, 1.0), n)
    cells = np.maximum(prec.cells, 2.0 * u)
    stack = np.where(u < n, log2_binom(np.maximum(n - 1.0, 0.0), np.maximum(u - 1.0, 0.0)), 0.0)
    bits = token + log2_binom(cells, u) + stack + counts + pose
    out = np.where(n > 0, bits, 0.0)
    return float(out) if out.ndim == 0 else out


def _placement_set_bits_scalar(
    prec: Precision, n: float, occupied, pose: float, counts: float, token: float
) -> float:
    """:func:`placement_set_bits` of one set, in the same operations on Python floats.

    The ledger prices ~10^5 single sets for a drawing of 5,000 elements; through 0-d arrays and
    two ``gammaln`` calls each they took 10 s of its 45 s of rule choice.
    """
    u = n if occupied is None else min(max(float(occupied), min(n, 1.0)), n)
    cells = max(prec.cells, 2.0 * u)
    stack = _log2_binom_scalar(max(n - 1.0, 0.0), max(u - 1.0, 0.0)) if u < n else 0.0
    bits = token + _log2_binom_scalar(cells, u) + stack + counts + pose
    return bits if n > 0 else 0.0


def shape_bits(prec: Precision, n_segments, radius) -> np.ndarray:
    """Bits of shapes drawn with ``n_segments`` cubic segments inside a circle of ``radius``.

    Three new control points per segment, each coordinate at the precision ``eps``.
    """
    per = np.log2(2.0 * np.asarray(radius, float) / prec.eps + 2.0)
    return 6.0 * np.asarray(n_segments, float) * per


def angle_value_bits(prec: Precision, degrees: float) -> float:
    """Bits of an angle parameter of a rule: a simple fraction ``360·j/k`` of a turn is cheap.

    Designers divide the circle evenly (a ring of 5 turns by 72°); such a step costs the bits of
    its fraction (``2·log2 k + 1``) instead of the full precision, when it is the fraction to
    within the precision.
    """
    full = prec.angle_bits()
    tol = math.degrees(prec.eps / prec.diagonal)
    for k in range(1, 25):
        j = round(degrees * k / 360.0)
        if j != 0 and abs(degrees - 360.0 * j / k) <= tol:
            return min(full, 2.0 * math.log2(k) + 1.0 + math.log2(abs(j) + 1.0))
    return full


def table_bits(prec: Precision, values, op: str, lever: float | None = None) -> float:
    """Bits of a table value ``[v0, v1, …]`` of turtle command ``op``: its length, its smallest
    entry at full precision, then every entry within the table's range.

    Distances are measured in document units, scales as ``ln s`` and angles as turns, both times
    ``lever`` (the radius of what they scale or turn, default the diagonal), so each entry costs
    ``log2(range / eps + 1)``: a table of nearly equal values is cheap.
    """
    v = np.asarray(values, dtype=float)
    reach = prec.diagonal if lever is None else float(lever)
    if op == "*":
        v, first = np.log(np.maximum(v, 1e-300)) * reach, prec.scale_bits(reach)
    elif op in ("f", "~"):
        first = prec.length_bits
    else:
        v, first = np.radians(v) * reach, prec.angle_bits(reach)
    spread = float(np.ptp(v)) if v.size else 0.0
    return float(count_bits(v.size)) + first + v.size * math.log2(spread / prec.eps + 1.0)


def transform_bits(prec: Precision, A: complex, B: complex) -> float:
    """Bits of a rule's constant transform ``(A, B)``: offset, turn and scale, each with a flag.

    Components that are zero (no offset along an axis, no turn, scale 1) cost only their flag.
    """
    tiny = 1e-6 * prec.diagonal
    bits = 4.0
    for v in (B.real, B.imag):
        if abs(v) > tiny:
            bits += prec.length_bits
    turn = math.degrees(float(np.angle(A)))
    if abs(turn) > 1e-6:
        bits += angle_value_bits(prec, turn)
    if abs(math.log(max(abs(A), 1e-300))) > 1e-7:
        bits += prec.scale_bits()
    return bits
