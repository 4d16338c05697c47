"""The live nodes of one hierarchy level, as one typed struct of arrays (§5.6).

At the first level every input element is a node: an instance of its terminal at its pose.
Applying a rule replaces the nodes it explains by one node per application, an instance of
the new non-terminal at the pose of the application's first node, so the next level pairs
groups with groups.  Each node remembers the input elements it covers (``members``) and the
bounding circle of their geometry (for neighbourhoods and proximity).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lsys_core.hierarchy.flat import Groups, as_groups

__all__ = ["Nodes"]


@dataclass(frozen=True, eq=False)
class Nodes:
    """Live nodes: symbol, pose, bounding circle and covered input elements of each.

    Attributes
    ----------
    sym : ndarray of int64, shape (n,)
        Symbol of every node (index into the hierarchy's symbol table).
    a, b : ndarray of complex, shape (n,)
        Pose ``z -> a*z + b`` of every node.
    center : ndarray of complex, shape (n,)
        Centre of the geometry the node covers (document coordinates).
    radius : ndarray of float, shape (n,)
        Radius of that geometry about ``center``.
    members : tuple of ndarray of int
        Input elements covered by every node.
    slack : ndarray of float, shape (n,)
        How far every node may still move: the tolerance less what its elements already
        deviate (their shapes, and the rules that placed them).
    """

    sym: np.ndarray
    a: np.ndarray
    b: np.ndarray
    center: np.ndarray
    radius: np.ndarray
    members: tuple[np.ndarray, ...]
    slack: np.ndarray

    @classmethod
    def of_elements(
        cls,
        group: np.ndarray,
        a: np.ndarray,
        b: np.ndarray,
        center: np.ndarray,
        radius: np.ndarray,
        slack: np.ndarray | float = np.inf,
    ) -> Nodes:
        """Return the first level's nodes: one per input element (copies of the given arrays)."""
        n = np.asarray(a).size
        return cls(
            np.asarray(group, dtype=np.int64).copy(),
            np.asarray(a, complex).copy(),
            np.asarray(b, complex).copy(),
            np.asarray(center, complex).copy(),
            np.asarray(radius, float).copy(),
            tuple(np.array([i]) for i in range(n)),
            np.broadcast_to(np.asarray(slack, float), (n,)).copy(),
        )

    def __len__(self) -> int:
        return int(self.a.size)

    def first_members(self) -> np.ndarray:
        """Return the smallest input element index each node covers (the order it was drawn in).

        One ``minimum.reduceat`` over all members (a ``min`` per node took 56 ms of a
        50,052-leaf grid's first level; this takes 6 ms).
        """
        if not self.members:
            return np.zeros(0, np.int64)
        sizes = np.fromiter(map(len, self.members), np.int64, len(self.members))
        flat = np.concatenate(self.members).astype(np.int64, copy=False)
        return np.minimum.reduceat(flat, np.cumsum(sizes) - sizes)

    def merge(
        self,
        groups: Groups | list[np.ndarray],
        syms: list[int],
        slack: list[float] | None = None,
        starts: tuple[tuple[complex, complex], ...] | None = None,
    ) -> tuple[Nodes, np.ndarray]:
        """Replace every group of nodes by one node of symbol ``syms[k]`` at its first node's pose.

        Parameters
        ----------
        groups : Groups or list of ndarray of int
            Disjoint groups of node indices, each with its first node first.
        syms : list of int
            The new node's symbol for every group.
        slack : list of float, optional
            The new node's slack for every group (default: the smallest of its nodes').
        starts : tuple of (a, b), optional
            The new node's pose for every group (default: its first node's).

        Returns
        -------
        nodes : Nodes
            The kept nodes in their order, then the new nodes in the order of ``groups``.
        mapping : ndarray of int, shape (len(self),)
            New index of every kept node; -1 for the merged ones.
        """
        n = len(self)
        keep = np.ones(n, bool)
        if not len(groups):
            return self, np.arange(n)
        groups = as_groups(groups)
        flat, owner = groups.nodes, groups.owner()
        keep[flat] = False
        counts = np.bincount(owner, minlength=len(groups))
        cen = (
            np.bincount(owner, self.center[flat].real, len(groups))
            + 1j * np.bincount(owner, self.center[flat].imag, len(groups))
        ) / counts
        rad = np.zeros(len(groups))
        np.maximum.at(rad, owner, np.abs(self.center[flat] - cen[owner]) + self.radius[flat])
        first = groups.firsts
        kept = np.flatnonzero(keep)
        if slack is None:
            new_slack = np.full(len(groups), np.inf)
            np.minimum.at(new_slack, owner, self.slack[flat])
        else:
            new_slack = np.asarray(slack, float)
        nodes = Nodes(
            np.concatenate([self.sym[kept], np.asarray(syms, np.int64)]),
            np.concatenate([self.a[kept], self.a[first] if starts is None else [p[0] for p in starts]]),
            np.concatenate([self.b[kept], self.b[first] if starts is None else [p[1] for p in starts]]),
            np.concatenate([self.center[kept], cen]),
            np.concatenate([self.radius[kept], rad]),
            tuple(self.members[i] for i in kept)
            + tuple(np.concatenate([self.members[i] for i in g]) for g in groups),
            np.concatenate([self.slack[kept], new_slack]),
        )
        mapping = np.full(n, -1)
        mapping[kept] = np.arange(kept.size)
        return nodes, mapping
