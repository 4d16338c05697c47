"""Sample many elements at once by arc length, with normals, curvature and shape descriptors.

Helpers of :mod:`lsys_core.instancing.similarity` (§4.1 of the paper, steps 1–4).  All elements
are stacked into one array of cubic segments so that sampling 10,000 elements is a
handful of numpy operations.  Points are complex numbers ``x + iy``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lsys_core.cancel import CancelToken, check
from lsys_core.geometry.paths import collinear_thirds, consecutive
from lsys_core.parallel import pmap
from lsys_core.svg.model import Element

__all__ = [
    "FEATURES",
    "ROWS",
    "ArcTable",
    "Samples",
    "arc_fractions",
    "arc_table",
    "bezier",
    "element_features",
    "empty_samples",
    "sample_all",
    "sample_elements",
    "sample_rows",
]

#: Sub-intervals per cubic of the arc-length table; each is integrated by Gauss–Legendre.
_TABLE = 8
_CHUNK = 1 << 14  # cubics per block of the arc-length table
#: Elements sampled at once (:func:`sample_elements`, a task of :func:`sample_all`): about a
#: hundred tasks for the workers at 50,000 elements, with temporaries of 800 KB at 96 samples.
#: The size hardly changes the time of one worker (128 to 4,096: within 15 %).
ROWS = 512
#: Entries of the descriptor of :func:`element_features`.
FEATURES = 14
#: Bytes of cubics :func:`_stack` copies without looking for the array they are pieces of.
_SMALL_COPY = 32 << 20
_GL_X, _GL_W = np.polynomial.legendre.leggauss(3)
_GL_X = (_GL_X + 1.0) / 2.0
_GL_W = _GL_W / 2.0


@dataclass(frozen=True, eq=False)
class Samples:
    """Arc-length uniform samples of several elements.

    Attributes
    ----------
    points : ndarray of complex, shape (n, s)
        Sample positions.
    normals : ndarray of complex, shape (n, s)
        Unit normals (the tangent turned by +90°; the sign follows the drawing direction).
    curvature : ndarray of float, shape (n, s)
        Unsigned curvature ``|κ|`` at the samples.
    length : ndarray of float, shape (n,)
        Total arc length of every element.
    segment, param : ndarray, shape (n, s)
        Index of the element's cubic each sample lies on, and the curve parameter there.
    """

    points: np.ndarray
    normals: np.ndarray
    curvature: np.ndarray
    length: np.ndarray
    segment: np.ndarray
    param: np.ndarray

    def rows(self, which: slice) -> Samples:
        """The samples of the elements ``which`` (views)."""
        return Samples(
            self.points[which],
            self.normals[which],
            self.curvature[which],
            self.length[which],
            self.segment[which],
            self.param[which],
        )


def arc_fractions(count: int, offset: float = 0.5) -> np.ndarray:
    """Return ``count`` evenly spaced arc-length fractions ``(j + offset) / count`` in [0, 1)."""
    return (np.arange(count) + offset) / count


def _stack(elements: list[Element] | tuple[Element, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Stack all cubics into one ``(K, 4)`` array and return it with each segment's element index."""
    counts = np.array([e.cubics.shape[0] for e in elements], dtype=np.int64)
    if counts.sum() == 0:
        return np.zeros((0, 4), complex), np.zeros(0, np.int64)
    arrays = [np.asarray(e.cubics, dtype=complex).reshape(-1, 4) for e in elements]
    # a scene's elements are pieces of one array: a large one is used as it is, without a copy
    # (telling so costs 3 microseconds an element, 15 times the copy of a small element)
    cubics = consecutive(arrays) if int(counts.sum()) * 64 > _SMALL_COPY else None
    if cubics is None:
        cubics = np.concatenate(arrays)
    owner = np.repeat(np.arange(len(elements)), counts)
    return cubics, owner


def bezier(c: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Evaluate cubics ``c`` (…, 4) at ``t`` (…): position, first and second derivative."""
    p0, p1, p2, p3 = c[..., 0], c[..., 1], c[..., 2], c[..., 3]
    s = 1.0 - t
    pos = s * s * s * p0 + 3 * s * s * t * p1 + 3 * s * t * t * p2 + t * t * t * p3
    d1 = 3 * (s * s * (p1 - p0) + 2 * s * t * (p2 - p1) + t * t * (p3 - p2))
    d2 = 6 * (s * (p2 - 2 * p1 + p0) + t * (p3 - 2 * p2 + p1))
    return pos, d1, d2


def _speed(c: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Return ``|B'(t)|`` of cubics ``c`` (…, 4) at ``t`` (…)."""
    p0, p1, p2, p3 = c[..., 0], c[..., 1], c[..., 2], c[..., 3]
    s = 1.0 - t
    return np.abs(3 * (s * s * (p1 - p0) + 2 * s * t * (p2 - p1) + t * t * (p3 - p2)))


def _partial_length(c: np.ndarray, t0: np.ndarray, t1: np.ndarray) -> np.ndarray:
    """Return the arc length of cubics ``c`` (…, 4) between ``t0`` and ``t1`` (Gauss–Legendre)."""
    h = t1 - t0
    tt = t0[..., None] + h[..., None] * _GL_X
    return h * np.sum(_GL_W * _speed(c[..., None, :], tt), axis=-1)


def _chord_table(cubics: np.ndarray) -> np.ndarray:
    """Arc length of every eighth of every cubic, ``(K * T,)``, in blocks of bounded memory.

    A block of :data:`_CHUNK` cubics needs about 10 MB of temporaries; one path of 10^6
    segments computed at once needed several GiB.  Straight segments (a line's cubic has its
    control points at the thirds of its chord, so its speed is constant) get the exact eighth
    of their chord without quadrature: a path of 10^6 lines spent 8 of 22 profiled seconds of
    inference in this table.
    """
    knots = np.arange(_TABLE) / _TABLE
    out = np.empty((cubics.shape[0], _TABLE))
    for lo in range(0, cubics.shape[0], _CHUNK):
        c = cubics[lo : lo + _CHUNK]
        straight = collinear_thirds(c, 1e-12 / 3.0 * np.maximum(np.abs(c).max(axis=1), 1.0))
        out[lo : lo + c.shape[0]][straight] = (np.abs(c[straight, 3] - c[straight, 0]) / _TABLE)[:, None]
        curved = np.flatnonzero(~straight)
        if curved.size:
            k = curved.size
            out[lo + curved] = _partial_length(
                np.broadcast_to(c[curved][:, None, :], (k, _TABLE, 4)),
                np.broadcast_to(knots, (k, _TABLE)),
                np.broadcast_to(knots + 1.0 / _TABLE, (k, _TABLE)),
            )
    return out.ravel()


@dataclass(frozen=True, eq=False)
class ArcTable:
    """Arc length tabulated along the cubics of several elements (see :func:`arc_table`).

    Attributes
    ----------
    cubics : ndarray of complex, shape (K, 4)
        All elements' cubics, one after another.
    chords : ndarray of float, shape (K * T,)
        Arc length of every eighth of every cubic.
    cum : ndarray of float, shape (K * T + 1,)
        Its running sum, from 0.
    first, last : ndarray of int, shape (n,)
        Every element's first and last eighth (``last < first`` for an element without cubics).
    start, length : ndarray of float, shape (n,)
        Every element's place in ``cum`` and its arc length.
    chord : ndarray of complex, shape (K,)
        Every cubic's end less its start.
    tiny : ndarray of float, shape (K,)
        Derivatives this small are no direction on the cubic (``1e-12`` of its largest coordinate, at least ``1e-12``).
    """

    cubics: np.ndarray
    chords: np.ndarray
    cum: np.ndarray
    first: np.ndarray
    last: np.ndarray
    start: np.ndarray
    length: np.ndarray
    chord: np.ndarray
    tiny: np.ndarray

    @property
    def size(self) -> int:
        """The number of elements."""
        return int(self.first.size)


def arc_table(elements: list[Element] | tuple[Element, ...]) -> ArcTable:
    """Tabulate the arc length of ``elements`` (the part of sampling done for all of them at once).

    The running sum runs over all of them: sampling the same elements in other tables gives
    values that differ in the last bits, so callers that must give the same samples for any
    number of workers tabulate fixed groups of elements.
    """
    n = len(elements)
    cubics, owner = _stack(elements)
    chords = _chord_table(cubics)  # (K * T,) arc length of every sub-interval
    cum = np.empty(chords.size + 1)
    cum[0] = 0.0
    np.cumsum(chords, out=cum[1:])
    # Every element's first and last sub-interval (its segments' eighths are consecutive).
    first = np.searchsorted(owner, np.arange(n), side="left") * _TABLE
    last = np.searchsorted(owner, np.arange(n), side="right") * _TABLE - 1
    present = last >= first
    if chords.size:
        start = np.where(present, cum[np.minimum(first, chords.size - 1)], 0.0)
        end = np.where(present, cum[np.minimum(last, chords.size - 1) + 1], 0.0)
    else:
        start = end = np.zeros(n)
    chord = cubics[:, 3] - cubics[:, 0]
    tiny = 1e-12 * np.maximum(np.abs(cubics).max(axis=-1), 1.0) if cubics.shape[0] else np.zeros(0)
    return ArcTable(cubics, chords, cum, first, last, start, end - start, chord, tiny)


def empty_samples(n: int, s: int) -> Samples:
    """Uninitialised samples of ``n`` elements at ``s`` fractions, to be filled by :func:`sample_rows`."""
    return Samples(
        np.empty((n, s), complex),
        np.empty((n, s), complex),
        np.empty((n, s)),
        np.empty(n),
        np.empty((n, s), np.int64),
        np.empty((n, s)),
    )


def sample_rows(
    table: ArcTable, fractions: np.ndarray, precise: np.ndarray, lo: int, hi: int, out: Samples, at: int
) -> None:
    """Sample elements ``lo:hi`` of ``table`` into rows ``at:at + hi - lo`` of ``out``.

    Every row is computed on its own (the same values whatever the rows computed with it);
    ``precise`` (one flag per element of the table) says which get the Newton steps.
    """
    rows_out = slice(at, at + hi - lo)
    out.length[rows_out] = table.length[lo:hi]
    cubics, chords, cum = table.cubics, table.chords, table.cum
    if cubics.shape[0] == 0:
        out.points[rows_out], out.normals[rows_out], out.curvature[rows_out] = 0.0, 1.0, 0.0
        out.segment[rows_out], out.param[rows_out] = 0, 0.0
        return
    first, last = table.first[lo:hi], table.last[lo:hi]
    target = table.start[lo:hi, None] + fractions[None, :] * table.length[lo:hi, None]
    idx = np.searchsorted(cum, target, side="right") - 1
    idx = np.clip(idx, first[:, None], np.maximum(last, first)[:, None])
    idx = np.clip(idx, 0, chords.size - 1)
    ch = chords[idx]
    frac = np.where(ch > 0, (target - cum[idx]) / np.where(ch > 0, ch, 1.0), 0.0)
    seg = idx // _TABLE
    t_lo = (idx % _TABLE) / _TABLE
    t = t_lo + np.clip(frac, 0.0, 1.0) / _TABLE
    c_seg = cubics[seg]
    rows = np.flatnonzero(precise[lo:hi])
    if rows.size:
        cr, lo_r, tr, base = c_seg[rows], t_lo[rows], t[rows], cum[idx[rows]] - target[rows]
        for _ in range(2):  # Newton steps on the arc length within the sub-interval
            err = base + _partial_length(cr, lo_r, tr)
            sp = _speed(cr, tr)
            tr = np.clip(
                tr - np.where(sp > 0, err / np.where(sp > 0, sp, 1.0), 0.0), lo_r, lo_r + 1.0 / _TABLE
            )
        t[rows] = tr
    pos, d1, d2 = bezier(c_seg, t)
    tiny = table.tiny[seg]  # per cubic, not per sample: the same numbers
    speed = np.abs(d1)
    tangent = np.where(speed > tiny, d1, np.where(np.abs(d2) > tiny, d2, table.chord[seg]))
    cross = d1.real * d2.imag - d1.imag * d2.real
    out.curvature[rows_out] = np.where(speed > tiny, np.abs(cross) / np.maximum(speed, tiny) ** 3, 0.0)
    mag = np.abs(tangent)
    out.normals[rows_out] = np.where(mag > 0, 1j * tangent / np.where(mag > 0, mag, 1.0), 1.0)
    out.points[rows_out] = np.where((last >= first)[:, None], pos, 0.0)
    out.segment[rows_out] = seg - (first // _TABLE)[:, None]
    out.param[rows_out] = t


def sample_elements(
    elements: list[Element] | tuple[Element, ...], fractions: np.ndarray, precise: bool | np.ndarray = True
) -> Samples:
    """Sample every element at the given arc-length fractions of its total length.

    Arc length is tabulated per eighth of every cubic by Gauss–Legendre quadrature and
    inverted linearly in between; Newton steps then place the samples of the ``precise``
    elements exactly (to about 1e-9 of their size).

    Parameters
    ----------
    elements : sequence of Element
        The elements; all their subpaths count, in order.
    fractions : ndarray of float, shape (s,)
        Fractions in [0, 1) of the element's arc length (see :func:`arc_fractions`).
    precise : bool or ndarray of bool, shape (n,)
        Which elements get the Newton steps (all, none, or a mask).

    Returns
    -------
    Samples
        ``(n, s)`` points, normals and curvatures.  An element of zero length has all its
        samples at its first point, normal ``1`` and curvature 0.
    """
    n = len(elements)
    table = arc_table(elements)
    mask = np.broadcast_to(np.asarray(precise, dtype=bool), (n,))
    out = empty_samples(n, fractions.size)
    for lo in range(0, n, ROWS):
        sample_rows(table, fractions, mask, lo, min(lo + ROWS, n), out, lo)
    return out


def element_features(samples: Samples) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return centroid, RMS radius and a similarity-invariant descriptor of every element.

    The descriptor is invariant to similarities, mirroring, start point, direction and
    resampling, and moves little under small deformations.  Its 14 entries: the deciles
    (10 % … 90 %) of the radial distances from the centroid (normalised by the RMS radius);
    the log of perimeter over RMS radius (divided by 4); the elongation (minor over major
    axis of the samples' second moments); and the quartiles of ``|cos|`` of the angle
    between normal and radius.

    Returns
    -------
    centroid : ndarray of complex, shape (n,)
    radius : ndarray of float, shape (n,)
    descriptor : ndarray of float, shape (n, 14)
    """
    centroid = samples.points.mean(axis=1)
    relz = samples.points - centroid[:, None]
    rel = np.abs(relz)
    radius = np.sqrt(np.mean(rel * rel, axis=1))
    safe = np.where(radius > 0, radius, 1.0)
    desc = np.empty((rel.shape[0], FEATURES))
    desc[:, :9] = np.quantile(rel / safe[:, None], np.linspace(0.1, 0.9, 9), axis=1).T
    desc[:, 9] = np.log1p(samples.length / safe) / 4.0
    xx, yy, xy = (
        (relz.real**2).mean(axis=1),
        (relz.imag**2).mean(axis=1),
        (relz.real * relz.imag).mean(axis=1),
    )
    half = (xx + yy) / 2
    disc = np.sqrt(np.maximum(half * half - (xx * yy - xy * xy), 0.0))
    desc[:, 10] = np.sqrt(np.maximum(half - disc, 0.0) / np.where(half + disc > 0, half + disc, 1.0))
    cos = np.abs((samples.normals * np.conj(relz)).real) / np.maximum(rel, 1e-300)
    desc[:, 11:] = np.quantile(np.where(rel > 0, cos, 0.0), [0.25, 0.5, 0.75], axis=1).T
    return centroid, radius, desc


def sample_all(
    elements: list[Element] | tuple[Element, ...],
    fractions: np.ndarray,
    group: int,
    cancel: CancelToken | None = None,
) -> tuple[Samples, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Sample all elements and describe them, in blocks of rows on the workers (:func:`.pmap`).

    Arc length is tabulated for fixed groups of ``group`` elements (the same samples for any
    number of workers, see :func:`arc_table`), then every block of :data:`ROWS`
    elements is sampled and described on its own (while its samples are in the processor's
    cache) into arrays of all elements; the cancel token is checked between blocks.  Only
    single open paths are sampled precisely: their poses are pinned down by arc length (closed
    outlines are matched through foot points, where sample placement does not matter).

    Returns
    -------
    samples : Samples
    centroid, radius, descriptor : ndarray
        :func:`element_features` of every element.
    degenerate : ndarray of bool
        Elements too small or too thin for their place to be matched (:func:`_degenerate`).
    """
    n = len(elements)
    precise = np.array([len(e.closed) == 1 and not e.closed[0] for e in elements], dtype=bool)
    starts = range(0, n, group)
    tables = pmap(lambda lo: arc_table(elements[lo : lo + group]), starts)
    out = empty_samples(n, fractions.size)
    centroid, radius, desc = np.empty(n, complex), np.empty(n), np.empty((n, FEATURES))
    degenerate = np.empty(n, bool)
    blocks = [(lo, t, r) for lo, t in zip(starts, tables, strict=True) for r in range(0, t.size, ROWS)]

    def block(task: tuple[int, ArcTable, int]) -> None:
        check(cancel)
        lo, table, r = task
        hi = min(r + ROWS, table.size)
        sample_rows(table, fractions, precise[lo : lo + table.size], r, hi, out, lo + r)
        rows = slice(lo + r, lo + hi)
        centroid[rows], radius[rows], desc[rows] = element_features(out.rows(rows))
        degenerate[rows] = _degenerate(out.rows(rows), centroid[rows], radius[rows])

    pmap(block, blocks)
    return out, centroid, radius, desc, degenerate


def _degenerate(samples: Samples, centroid: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Elements of no length, no radius or no extent (relative to their coordinates' size)."""
    extent = np.abs(samples.points - centroid[:, None]).max(axis=1)
    span = np.maximum(np.abs(samples.points).max(axis=1), 1.0)
    degenerate = (samples.length <= 1e-9 * span) | (radius <= 1e-9 * span) | ~np.isfinite(radius)
    degenerate |= extent <= 1e-9 * span
    return degenerate
