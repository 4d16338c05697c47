"""A representative shape and candidate shapes in their normalised frames (inputs of matching, §4.1).

Both are centred on their centroids and normalised by their RMS radius (the paper normalises
by the largest sample distance; the RMS radius is as cheap and steadier under resampling).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from lsys_core.instancing.sampling import Samples

__all__ = ["Batch", "Reference"]


@dataclass(frozen=True, eq=False)
class Reference:
    """A representative shape in its normalised local frame (centroid 0, RMS radius 1).

    ``points``/``normals``/``curvature`` are its coarse samples, used for voting.  The
    dense samples (``dense``, ``dense_normals``; at arc-length fractions ``dense_frac``, in
    order, on cubic ``dense_seg`` of ``cubics`` at parameter ``dense_t``) serve ICP and
    scoring through ``tree``; ``dense_step`` is the arc length between them.
    ``open_path`` says whether the shape is a single open subpath.
    """

    points: np.ndarray
    normals: np.ndarray
    curvature: np.ndarray
    dense: np.ndarray
    dense_normals: np.ndarray
    dense_frac: np.ndarray
    dense_seg: np.ndarray
    dense_t: np.ndarray
    cubics: np.ndarray
    dense_step: float
    open_path: bool
    tree: cKDTree
    order: np.ndarray
    radius_sorted: np.ndarray

    @classmethod
    def build(
        cls,
        coarse: Samples,
        dense: Samples,
        dense_frac: np.ndarray,
        cubics: np.ndarray,
        origin: complex,
        radius: float,
        open_path: bool,
    ) -> Reference:
        """Build a reference from one element's coarse and dense samples (row 0 of each).

        ``origin`` and ``radius`` define the normalised frame ``(z - origin) / radius``.
        """
        inv = 1.0 / radius
        points = (coarse.points[0] - origin) * inv
        rho = np.abs(points)
        order = np.argsort(rho, kind="stable")
        pts = (dense.points[0] - origin) * inv
        local = np.asarray(cubics, dtype=complex).reshape(-1, 4) - origin
        local *= inv
        return cls(
            points=points,
            normals=coarse.normals[0],
            curvature=coarse.curvature[0] * radius,
            dense=pts,
            dense_normals=dense.normals[0],
            dense_frac=dense_frac,
            dense_seg=dense.segment[0],
            dense_t=dense.param[0],
            cubics=local,
            dense_step=float(dense.length[0]) * inv / pts.size,
            open_path=open_path,
            tree=cKDTree(np.column_stack([pts.real, pts.imag])),
            order=order,
            radius_sorted=rho[order],
        )


@dataclass(frozen=True, eq=False)
class Batch:
    """Candidates in their own normalised frames: ``points``, ``normals``, ``curvature`` (b, s)."""

    points: np.ndarray
    normals: np.ndarray
    curvature: np.ndarray

    def mirrored(self) -> Batch:
        """Return the candidates flipped about their x axis."""
        return Batch(np.conj(self.points), np.conj(self.normals), self.curvature)
