"""Geometric comparison helpers for tests and scripts (like ``shapely.testing``).

Two scenes are compared the way the evaluation of the method does (paper 002): the
symmetric Hausdorff distance between points sampled along all elements, relative to the
first scene's bounding-box diagonal, and the spread of nearest-neighbour spacing.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from lsys_core.derive.model import Drawing
from lsys_core.svg.model import Scene

__all__ = ["assert_scenes_close", "drawing_scene", "hausdorff_rel", "regularity", "scene_points"]


def scene_points(scene: Scene, per_segment: int = 8) -> np.ndarray:
    """Return points sampled along every element of ``scene`` as an ``(n, 2)`` array."""
    from lsys_core.geometry.bezier import sample_cubics

    cubics = np.concatenate([e.cubics for e in scene.elements])
    pts = sample_cubics(cubics, per_segment)
    return np.column_stack([pts.real, pts.imag])


def hausdorff_rel(a: Scene, b: Scene) -> float:
    """Return the symmetric Hausdorff distance of two scenes over ``a``'s bounding-box diagonal."""
    pa, pb = scene_points(a), scene_points(b)
    diag = float(np.linalg.norm(pa.max(0) - pa.min(0)))
    h = max(cKDTree(pb).query(pa)[0].max(), cKDTree(pa).query(pb)[0].max())
    return float(h / max(diag, 1e-300))


def regularity(scene: Scene) -> float:
    """Return the spread (std / mean) of nearest-neighbour distances between element centres."""
    c = np.array([e.cubics.mean() for e in scene.elements])
    xy = np.column_stack([c.real, c.imag])
    d, _ = cKDTree(xy).query(xy, k=2)
    return float(d[:, 1].std() / d[:, 1].mean())


def drawing_scene(drawing: Drawing) -> Scene:
    """Return ``drawing`` as the SVG importer reads it back (what a user's other tools see)."""
    from lsys_core.render.svg import drawing_to_svg
    from lsys_core.svg.parse import parse_svg

    return parse_svg(drawing_to_svg(drawing))


def assert_scenes_close(a: Scene, b: Scene, tol: float = 0.005) -> None:
    """Assert same element count and Hausdorff distance ≤ ``tol`` of ``a``'s diagonal."""
    assert len(a.elements) == len(b.elements), f"{len(a.elements)} elements vs {len(b.elements)}"
    h = hausdorff_rel(a, b)
    assert h <= tol, f"Hausdorff distance {h:.6f} of the diagonal > {tol}"
