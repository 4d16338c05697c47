"""Candidate rules of one level (§5.3) as frozen values, and helpers shared by their finders.

A candidate names the live nodes every application of a rule would explain, the rule's
transform(s) and the terms of its importance (§5.4).  The kinds are the paper's sequences
(r1/r2, :class:`SeqCandidate`, and with parameters linear in m, :class:`LinearCandidate`),
branchings (r3/r4, :class:`BranchCandidate`) and pairs of nodes (:class:`PairCandidate`).
They are found by :mod:`lsys_core.hierarchy.analysis`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property
from typing import Protocol

import numpy as np

from lsys_core.hierarchy.flat import Groups, as_groups
from lsys_core.hierarchy.spaces import PairSpace

__all__ = [
    "NEAR_BAND",
    "BranchCandidate",
    "Candidate",
    "ConstantCluster",
    "Context",
    "LinearCandidate",
    "PairCandidate",
    "SeqCandidate",
    "cluster_means",
    "mean_rel",
    "proximity",
    "space_key",
]

#: Pairs up to this factor farther apart than a node's nearest neighbour have proximity 1.
NEAR_BAND = 1.25


class Context(Protocol):
    """What candidate finding needs from the hierarchy: bandwidths, symbol sizes, similarity."""

    @property
    def tol(self): ...  # a Tolerance: xy (relative to size), angle (degrees), scale (log)

    @property
    def n_terminals(self) -> int: ...  # symbols 0 … n_terminals-1 are terminals

    def sizes(self) -> np.ndarray: ...

    def phi(self, si: int, sj: int) -> float: ...


@dataclass(frozen=True, eq=False, kw_only=True)
class Candidate:
    """A candidate rule of one level and the terms of its importance ``n, h, φ, l`` (§5.4).

    Attributes
    ----------
    space : tuple of int
        The pair of symbols ``(first, second)`` whose transformation space it came from.
    groups : Groups
        The live nodes of every application, its first node first (any sequence of integer
        sequences is taken and held flat: a level of 100,000 nodes has millions of groups).
    h, phi, l : float
        Proximity, similarity and (relative) sequence length of the importance.
    start : tuple of float
        Mean input order of the applications' first elements, then of their second ones (ties
        go to the drawing order: of a ring read either way from one element, the way the art
        was drawn).
    slack : tuple of float
        Per application, how much farther its elements may still move within the tolerance
        once the rule places them (set when the candidate is accepted).
    starts : tuple of complex pairs
        Per application, the pose it starts from when that is not its first node's pose
        (set when the candidate is accepted).
    gain : float
        Bits the rule saves (set when the candidate is accepted).
    """

    space: tuple[int, int]
    groups: Groups
    h: float
    phi: float
    l: float
    start: tuple[float, float] = (0.0, 0.0)
    slack: tuple[float, ...] = ()
    starts: tuple[tuple[complex, complex], ...] = ()
    gain: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "groups", as_groups(self.groups))

    @property
    def covered(self) -> int:
        """Number of live nodes the candidate explains."""
        return int(self.groups.nodes.size)

    @property
    def repeats(self) -> int:
        """Number of repetitions of the candidate's transform(s)."""
        return len(self.groups)

    def nodes(self) -> np.ndarray:
        """All live nodes the candidate explains (read-only: made once, the choice asks often)."""
        return self._nodes

    @cached_property
    def _nodes(self) -> np.ndarray:
        out = self.groups.nodes.view()
        out.setflags(write=False)
        return out

    def remapped(self, mapping: np.ndarray) -> Candidate:
        """Return the candidate with node indices renumbered by ``mapping`` (after another was applied)."""
        return replace(self, groups=Groups(np.asarray(mapping)[self.groups.nodes], self.groups.offsets))


@dataclass(frozen=True, eq=False, kw_only=True)
class SeqCandidate(Candidate):
    """Sequences ``A T A T …`` of one symbol with a constant transform ``T = (A, B)`` (r1/r2)."""

    A: complex
    B: complex

    @property
    def repeats(self) -> int:
        return self.covered - len(self.groups)


@dataclass(frozen=True, eq=False, kw_only=True)
class PairCandidate(Candidate):
    """Pairs ``X T Y`` with one transform ``T = (A, B)``: repetitions that are no longer sequence."""

    A: complex
    B: complex


@dataclass(frozen=True, eq=False, kw_only=True)
class BranchCandidate(Candidate):
    """Full binary trees ``R -> [A] [T1 R] T2 R`` (r3/r4); ``depths`` per tree, groups root first."""

    first: tuple[complex, complex]
    second: tuple[complex, complex]
    depths: tuple[int, ...]


@dataclass(frozen=True, eq=False, kw_only=True)
class LinearCandidate(Candidate):
    """Sequences whose ``+(α) f(d) *(s) +(β)`` turns change by ``d_alpha``, ``d_beta`` per step.

    ``alpha0``/``beta0`` are the turns of the first step and ``steps`` the length the
    parameters are written for (the rule counts down from it).
    """

    alpha0: float
    d: float
    s: float
    beta0: float
    d_alpha: float
    d_beta: float
    steps: int


def mean_rel(A: np.ndarray, B: np.ndarray) -> tuple[complex, complex]:
    """Average relative frames: geometric mean of ``A`` (log space), arithmetic mean of ``B``."""
    la = np.log(A)
    ang = np.angle(np.mean(np.exp(1j * la.imag)))
    return complex(np.exp(np.mean(la.real) + 1j * ang)), complex(np.mean(B))


def cluster_means(
    A: np.ndarray, B: np.ndarray, h: np.ndarray, members: list[np.ndarray]
) -> list[tuple[complex, complex, float] | None]:
    """``mean_rel(A[m], B[m])`` and ``float(np.mean(h[m]))`` of every ``m`` in ``members`` (None when empty).

    The same values as one call per cluster, with a few numpy calls per cluster *length*:
    the logarithms and unit turns are taken per pair (the same per element), and the members
    of all clusters of one length are stacked as rows whose means (``axis=1``: each row reduced
    as one array, pairwise) are those of the rows alone.  Only the turn of each mean is taken
    one by one, on its scalar, as :func:`mean_rel` does.  A 1,200-leaf grid has ~800 clusters
    of a few dozen lengths: one ``mean_rel`` each was 3 % of its ``lsys infer`` (sampled).
    """
    out: list[tuple[complex, complex, float] | None] = [None] * len(members)
    sizes = np.array([m.size for m in members], np.int64)
    keep = np.flatnonzero(sizes > 0)
    if keep.size == 0:
        return out
    flat = np.concatenate([members[k] for k in keep.tolist()])
    la = np.log(A[flat])
    unit = np.exp(1j * la.imag)
    log_abs, b, near = la.real, B[flat], h[flat]
    start = np.cumsum(sizes[keep]) - sizes[keep]
    by_size = keep[np.argsort(sizes[keep], kind="stable")]
    pos = np.empty(len(members), np.int64)
    pos[keep] = start
    cuts = np.flatnonzero(np.diff(sizes[by_size])) + 1
    for group in np.split(by_size, cuts):
        rows = pos[group][:, None] + np.arange(int(sizes[group[0]]))
        turn, scale = np.mean(unit[rows], axis=1), np.mean(log_abs[rows], axis=1)
        shift, hs = np.mean(b[rows], axis=1), np.mean(near[rows], axis=1)
        for j, k in enumerate(group.tolist()):
            ang = np.angle(turn[j])
            out[k] = (complex(np.exp(scale[j] + 1j * ang)), complex(shift[j]), float(hs[j]))
    return out


def space_key(sym: np.ndarray, ps: PairSpace) -> np.ndarray:
    """One integer per pair naming its transformation space (the ordered pair of symbols)."""
    return sym[ps.src] * (int(sym.max()) + 1) + sym[ps.dst]


def proximity(ps: PairSpace, n_nodes: int, radius: np.ndarray) -> np.ndarray:
    """Per-pair proximity in (0, 1]: 1 for a node's nearest neighbour, lower for farther pairs.

    Distances are between the centres of the nodes' geometry, relative to the nearest
    neighbour of either node; neighbours up to :data:`NEAR_BAND` times farther than the
    nearest count as equally near (spacings that differ a little look alike).
    """
    nn = np.full(n_nodes, np.inf)
    np.minimum.at(nn, ps.src, ps.dist)
    eps = 0.1 * float(np.median(radius)) + 1e-12
    near = np.minimum(nn[ps.src], nn[ps.dst])
    return np.minimum(NEAR_BAND * (near + eps) / (ps.dist + eps), 1.0)


@dataclass(frozen=True, eq=False)
class ConstantCluster:
    """A cluster *C* of pairs with one transform, linked into chains (input of the other finders).

    ``pairs`` are the cluster's pair indices; the links ``src[k] → dst[k]`` are the successor
    map its chains were followed from (each node with ≤ 1 successor and predecessor).
    """

    space: tuple[int, int]
    pairs: np.ndarray
    src: np.ndarray
    dst: np.ndarray

    @cached_property
    def succ(self) -> dict[int, int]:
        """The links as a successor map."""
        return dict(zip(self.src.tolist(), self.dst.tolist(), strict=True))
