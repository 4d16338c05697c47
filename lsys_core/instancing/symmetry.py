"""Rotational symmetry of a shape, and pose rotations reduced by it (helpers of §4.1–4.2).

A square turned by 90° is the same square: the rotation of its instances is only known modulo
the shape's symmetry, and the similarity stage reports the equivalent rotation of smallest
angle.  Shapes that match themselves at any angle (circles) carry no rotation at all.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["canonical", "symmetry_order"]


def _rotate_residuals(probe, dense, normals, tree: cKDTree, angles: np.ndarray, tol: float) -> np.ndarray:
    """Return, per angle, the largest distance of the rotated ``probe`` from the outline of ``dense``.

    Distances are point-to-line at the nearest dense sample (and at least a tenth of the
    point distance, so a probe that lands on nothing still counts); probes farther than
    ``20 * tol`` from every sample count as infinitely far.
    """
    x = (probe[None, :] * np.exp(1j * np.asarray(angles))[:, None]).ravel()
    dist, nn = tree.query(np.column_stack([x.real, x.imag]), distance_upper_bound=20 * tol)
    nn = np.minimum(nn, dense.size - 1)
    line = np.abs(((x - dense[nn]) * np.conj(normals[nn])).real)
    return np.maximum(line, 0.1 * dist).reshape(len(angles), -1).max(axis=1)


def symmetry_order(dense: np.ndarray, normals: np.ndarray, tol: float = 0.01) -> tuple[int, int]:
    """Detect the rotational symmetry of a shape from dense samples about its centroid.

    Every ``k`` up to 12 is tried by rotating a subset of the samples by ``360°/k`` and
    measuring how far they land from the outline; higher orders (regular polygons with
    many sides) are found from the angular moments ``mean(z**m)``, which vanish unless
    ``k`` divides ``m``; a shape that matches itself at arbitrary angles is continuous.

    Parameters
    ----------
    dense : ndarray of complex
        Arc-length uniform samples, in order, centred on their mean and scaled to RMS radius 1.
    normals : ndarray of complex
        Unit normals at the samples.
    tol : float
        Largest deviation (in RMS radii) of the rotated shape from itself.

    Returns
    -------
    tuple of int
        ``(order, period)``: ``order`` is 1 (none), ``k`` (k-fold, k ≤ 12) or 0 (continuous,
        or more than 12-fold); ``period`` is the ``k`` to reduce pose angles by (0: any angle).
    """
    tree = cKDTree(np.column_stack([dense.real, dense.imag]))
    probe = dense[:: max(1, dense.size // 96)]
    low = np.arange(12, 1, -1)
    generic = np.array([0.7137, 2.0911, 3.3])
    res = _rotate_residuals(probe, dense, normals, tree, np.concatenate([generic, 2 * np.pi / low]), tol)
    if (res[:3] < tol).all():
        return 0, 0
    ms = np.arange(13, 65)
    powers = np.empty((ms.size, dense.size), complex)
    powers[0] = dense**13
    powers[1:] = dense
    with np.errstate(over="ignore", invalid="ignore"):
        powers = np.cumprod(powers, axis=0)  # dense ** m for every m
        num = np.abs(powers.mean(axis=1))
        den = np.mean(np.abs(powers), axis=1)
    strength = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
    for k in ms[strength > 0.02][::-1]:  # candidate high orders, largest first
        alone = (strength[ms % k != 0] < 0.02).all()
        if alone and _rotate_residuals(probe, dense, normals, tree, np.array([2 * np.pi / k]), tol)[0] < tol:
            return 0, int(k)
    fitting = low[res[3:] < tol]
    return (int(fitting[0]), int(fitting[0])) if fitting.size else (1, 1)


def canonical(a: np.ndarray, period: int) -> np.ndarray:
    """Reduce pose rotations to the equivalent one of smallest angle under k-fold symmetry."""
    if period == 1:
        return a
    if period == 0:
        return np.abs(a).astype(complex)
    step = 2 * np.pi / period
    ang = np.angle(a)
    red = ang - np.round(ang / step) * step
    red = np.where(red <= -np.pi / period + 1e-12, red + step, red)
    return np.abs(a) * np.exp(1j * red)
