"""Similarity transforms as pairs of complex numbers, and turtle conventions.

A 2D similarity (rotation, uniform scale, translation) maps a point ``z = x + iy``
to ``a * z + b`` with complex ``a = s * exp(i*phi)`` and ``b``.  SVG coordinates
are used throughout (y points down), so a positive angle turns from +x towards +y,
which is the turtle's ``+(delta)``.  Composition is vectorised over numpy arrays.

The paper's transformation ``T = +(alpha) f(d) *(s) +(beta)`` relative to a frame
``(a, b)`` gives the frame ``(a * A, b + a * B)`` with ``B = d * exp(i*alpha)`` and
``A = s * exp(i*(alpha + beta))``.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "compose",
    "frames_to_matrices",
    "invert",
    "rel_from_t4",
    "relative",
    "t4_from_rel",
    "wrap_deg",
]

DEG = np.pi / 180.0


def compose(a1, b1, a2, b2):
    """Return the frame ``(a1, b1) ∘ (a2, b2)`` (apply the second, then the first)."""
    return a1 * a2, a1 * b2 + b1


def invert(a, b):
    """Return the inverse frame of ``(a, b)``."""
    ia = 1.0 / a
    return ia, -b * ia


def relative(a1, b1, a2, b2):
    """Return ``(A, B)`` with ``(a2, b2) = (a1, b1) ∘ (A, B)``: frame 2 seen from frame 1."""
    return a2 / a1, (b2 - b1) / a1


def t4_from_rel(A, B):
    """Decompose a relative frame into the paper's ``(alpha, d, s, beta)`` (degrees).

    Parameters
    ----------
    A, B : complex or ndarray of complex
        Relative frame as returned by :func:`relative`.

    Returns
    -------
    tuple of ndarray
        ``alpha`` and ``beta`` in degrees wrapped to (-180, 180], ``d >= 0`` and ``s > 0``.
    """
    A = np.asarray(A, dtype=complex)
    B = np.asarray(B, dtype=complex)
    d = np.abs(B)
    alpha = np.where(d > 0, np.angle(B, deg=True), 0.0)
    s = np.abs(A)
    beta = wrap_deg(np.angle(A, deg=True) - alpha)
    return alpha, d, s, beta


def rel_from_t4(alpha, d, s, beta):
    """Compose ``+(alpha) f(d) *(s) +(beta)`` (degrees) into a relative frame ``(A, B)``."""
    alpha = np.asarray(alpha, dtype=float)
    B = np.asarray(d, dtype=float) * np.exp(1j * alpha * DEG)
    A = np.asarray(s, dtype=float) * np.exp(1j * (alpha + np.asarray(beta, dtype=float)) * DEG)
    return A, B


def wrap_deg(x):
    """Wrap angles in degrees to the interval (-180, 180]."""
    x = np.asarray(x, dtype=float)
    y = np.mod(x + 180.0, 360.0) - 180.0
    return np.where(y == -180.0, 180.0, y)


def frames_to_matrices(a, b) -> np.ndarray:
    """Return ``(n, 3, 3)`` affine matrices for frames ``a``, ``b`` (complex arrays)."""
    a = np.atleast_1d(np.asarray(a, dtype=complex))
    b = np.atleast_1d(np.asarray(b, dtype=complex))
    m = np.zeros((a.size, 3, 3))
    m[:, 0, 0] = a.real
    m[:, 0, 1] = -a.imag
    m[:, 1, 0] = a.imag
    m[:, 1, 1] = a.real
    m[:, 0, 2] = b.real
    m[:, 1, 2] = b.imag
    m[:, 2, 2] = 1.0
    return m
