"""Find similar elements and replace them by terminal symbols with poses (paper §4.1–§4.2).

Two elements are similar when one is the image of the other under a similarity
(translation, rotation, uniform scale) up to the similarity threshold ``φ``, and they are
drawn with the same style.  Each group of similar elements becomes one terminal symbol:
the shape of a representative element in a local frame centred on its centroid, and a
pose ``z -> a*z + b`` per element.  Mirror images form their own group, linked by
``mirrored_of`` (the flips of §5.4).

Elements are not compared pairwise: cheap invariant descriptors (sorted radial distances,
perimeter over radius, style) pick the candidates of each new representative, and the
candidates are matched against it in vectorised batches (:mod:`.similarity_match`).
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np
from scipy.spatial import cKDTree

from lsys_core.cancel import CancelToken, Progress, check, report
from lsys_core.errors import InferenceError
from lsys_core.grammar.model import Terminal
from lsys_core.instancing.exact import EXACT_TOL, fit_exact, structure_ids, variants
from lsys_core.instancing.match import PERFECT, match_batch
from lsys_core.instancing.model import Instancing
from lsys_core.instancing.reference import Batch, Reference
from lsys_core.instancing.sampling import (
    Samples,
    arc_fractions,
    element_features,
    sample_all,
    sample_elements,
)
from lsys_core.instancing.symmetry import canonical, symmetry_order
from lsys_core.parallel import pmap
from lsys_core.svg.model import Element, Scene

__all__ = ["detect_similarity", "symmetry_order", "terminal_name", "terminal_similarity"]

#: Samples per element for voting, ICP and φ; the representative gets ``_DENSE`` times more.
_SAMPLES = 96
_DENSE = 9
_CHUNK = 1024
_STAGE = "similarity"


def terminal_name(index: int) -> str:
    """Return the name of the ``index``-th terminal: ``A`` … ``Z``, ``AA`` … ``ZZ``, ``AAA`` ….

    Terminal names are capital letters only; rule names carry a digit (``P1``), so the two
    never meet, and the hierarchy's catch-all rule ``Z`` takes another name when a terminal
    is called ``Z`` (see ``SymbolTable.new_name``).
    """
    name = ""
    index += 1
    while index > 0:
        index, r = divmod(index - 1, 26)
        name = chr(ord("A") + r) + name
    return name


def _path_data(element: Element, origin: complex) -> str:
    """Return the element's path data translated by ``-origin``."""
    from lsys_core.geometry.paths import d_from_cubics

    cubics = np.asarray(element.cubics, dtype=complex).reshape(-1, 4) - origin
    return d_from_cubics(cubics, np.asarray(element.subpaths), tuple(element.closed))


def _style_key(style: str) -> str:
    """Return the key elements are grouped by: none, a terminal is geometry only.

    Styles travel with the instances (the pipeline gives every placed instance its own
    fill, stroke, widths and opacity), so shapes that differ only in style are one terminal.
    """
    return ""


def _next_free(group: np.ndarray, cursor: int) -> int:
    """The first element from ``cursor`` on in no group yet (``group < 0``), or ``group.size``.

    Runs of grouped elements are skipped in slices of growing length (one by one in Python,
    the 50,051 copies of a leaf took 10 ms).
    """
    n = group.size
    if cursor >= n or group[cursor] < 0:
        return cursor
    step = 64
    while cursor < n:
        free = np.flatnonzero(group[cursor : cursor + step] < 0)
        if free.size:
            return cursor + int(free[0])
        cursor += step
        step = min(2 * step, 1 << 16)
    return n


class _Rep:
    """A representative: its element index, local origin (centroid), size and reference."""

    def __init__(self, element: Element, index: int, coarse: Samples):
        # (k + 0.5) / m with an odd factor: unbiased, and the coarse samples are among them
        fractions = arc_fractions(_SAMPLES * _DENSE)
        dense = sample_elements([element], fractions)
        self.index = index
        self.origin = complex(dense.points[0].mean())
        rel = dense.points[0] - self.origin
        self.radius = float(np.sqrt(np.mean(np.abs(rel) ** 2)))
        row = coarse.rows(slice(index, index + 1))
        open_path = len(element.closed) == 1 and not element.closed[0]
        self.ref = Reference.build(row, dense, fractions, element.cubics, self.origin, self.radius, open_path)
        self.control = np.asarray(element.cubics, dtype=complex).ravel()
        self.orders = variants(element)


class _Matcher:
    """Per-element data shared by all rounds, and the matching of a chunk against a representative."""

    def __init__(self, elements: tuple[Element, ...], coarse: Samples, centroid, radius):
        self.elements = elements
        self.coarse = coarse
        self.centroid = centroid
        self.radius = radius
        self.structure = structure_ids(elements)

    def match(self, rep: _Rep, chunk: np.ndarray, threshold: float, mirrored: bool):
        """Match ``chunk`` against ``rep`` (flipped first if ``mirrored``).

        Exact copies of the representative's control points are recognised in closed form;
        the others go through voting and ICP.

        Returns
        -------
        ok : ndarray of bool
            Which candidates are similar (``φ >= threshold``).
        phi, gap : ndarray of float
            Similarity and fit gap (RMS distance in RMS radii) of each candidate.
        a, b : ndarray of complex
            The poses ``element = a * local + b`` (meaningless where not ``ok`` or mirrored).
        """
        m = chunk.size
        phi = np.zeros(m)
        gap = np.full(m, np.inf)
        a = np.ones(m, complex)
        b = np.zeros(m, complex)
        flip = np.conj if mirrored else (lambda z: z)
        same = self.structure[chunk] == self.structure[rep.index]
        if rep.orders is not None and same.any():
            sel = np.flatnonzero(same)
            ctrl = np.stack([np.asarray(self.elements[i].cubics, dtype=complex).ravel() for i in chunk[sel]])
            ea, eb, misfit = fit_exact(rep.control, rep.orders, flip(ctrl))
            exact = misfit < EXACT_TOL
            sel = sel[exact]
            a[sel], b[sel] = ea[exact], eb[exact] + ea[exact] * rep.origin
            phi[sel], gap[sel] = 1.0, misfit[exact]
        rest = np.flatnonzero(phi < 1.0)
        if rest.size:
            sub = chunk[rest]
            r = self.radius[sub]
            batch = Batch(
                flip((self.coarse.points[sub] - self.centroid[sub, None]) / r[:, None]),
                flip(self.coarse.normals[sub]),
                self.coarse.curvature[sub] * r[:, None],
            )
            res = match_batch(rep.ref, batch, self.coarse.length[sub] / r, threshold=threshold)
            # rep ≈ c * cand + d (normalised)  =>  element = a * local + b
            a[rest] = r / (rep.radius * res.c)
            b[rest] = flip(self.centroid[sub]) - a[rest] * rep.radius * res.d
            phi[rest], gap[rest] = res.phi, res.gap
        return phi >= threshold, phi, gap, a, b

    def prefer_mirror(self, rep: _Rep, chunk: np.ndarray, threshold: float, ok, phi, gap) -> np.ndarray:
        """Return which candidates are mirror images of ``rep`` rather than (imperfect) copies.

        A candidate is a mirror image when it matches the flipped representative and that
        match is clearly better than the direct one, so mirror-symmetric shapes stay copies.
        """
        test = np.flatnonzero(~ok | (gap > PERFECT) | (phi < 1.0))
        result = np.zeros(chunk.size, bool)
        if test.size == 0:
            return result
        mok, mphi, mgap, _, _ = self.match(rep, chunk[test], threshold, mirrored=True)
        # φ moves by a few samples with noise: only a clear margin, or a much tighter fit, counts
        better = (mphi >= phi[test] + 0.1) | ((mphi >= phi[test] - 0.02) & (mgap < 0.5 * gap[test]))
        result[test] = mok & (~ok[test] | better)
        return result


def detect_similarity(
    scene: Scene,
    *,
    threshold: float = 0.6,
    flips: bool = True,
    cancel: CancelToken | None = None,
    progress: Progress | None = None,
) -> Instancing:
    """Group similar elements into terminals and recover every element's pose.

    Parameters
    ----------
    scene : Scene
        The imported elements.
    threshold : float
        Smallest similarity ``φ`` (share of matching samples, in [0, 1]) for two elements
        to be grouped (the paper's default is 0.6).
    flips : bool
        Detect mirror images as separate, linked groups; when False a mirror image is
        just another shape.
    cancel : CancelToken, optional
        Checked between batches.
    progress : Progress, optional
        Called as ``progress("similarity", fraction)``.

    Returns
    -------
    Instancing
        Group, pose ``(a, b)`` of every element, one terminal per group (path data in the
        representative's frame: origin at its centroid, orientation and size as drawn),
        rotational symmetry orders and mirror links.

    Raises
    ------
    InferenceError
        If ``threshold`` is outside [0, 1].
    """
    if not (0.0 <= threshold <= 1.0) or math.isnan(threshold):
        raise InferenceError(f"similarity threshold must be between 0 and 1, got {threshold}")
    elements = tuple(scene.elements)
    n = len(elements)
    report(progress, _STAGE, 0.0)
    if n == 0:
        empty = np.zeros(0, dtype=int)
        return Instancing(empty, np.zeros(0, complex), np.zeros(0, complex), (), empty, empty.copy())
    # arc length tabulated per 4,096 elements: the same samples for any number of workers
    coarse, centroid, radius, desc, degenerate = sample_all(
        elements, arc_fractions(_SAMPLES), 4 * _CHUNK, cancel
    )
    report(progress, _STAGE, 0.1)
    parsed = {st: _style_key(st) for st in {e.style for e in elements}}
    if len(set(parsed.values())) == 1:  # one key (as _style_key gives): no pass over the elements
        key_ids = dict.fromkeys(parsed.values(), 0)
        key_of = np.zeros(n, int)
    else:
        key_ids = {k: i for i, k in enumerate(dict.fromkeys(parsed[e.style] for e in elements))}
        key_of = np.array([key_ids[parsed[e.style]] for e in elements])
    trees = {}
    for k in range(len(key_ids)):
        members = np.flatnonzero((key_of == k) & ~degenerate)
        if members.size:
            trees[k] = (members, cKDTree(desc[members]))
    tol = 0.06 + 0.15 * (1.0 - threshold)
    matcher = _Matcher(elements, coarse, centroid, np.where(degenerate, 1.0, radius))
    group = np.full(n, -1, dtype=int)
    a = np.ones(n, complex)
    b = np.where(degenerate, coarse.points[:, 0], centroid)
    reps: list[_Rep | None] = []
    rep_index: list[int] = []
    mirror_of: list[int] = []
    pending: deque[tuple[int, int]] = deque()
    cursor = 0
    done = 0  # elements in a group (counted as they join: counting the array each time is quadratic)
    while True:
        check(cancel)
        if pending:
            r, mirror = pending.popleft()
            if group[r] >= 0:
                continue
        else:
            cursor = _next_free(group, cursor)
            if cursor >= n:
                break
            r, mirror = cursor, -1
        g = len(rep_index)
        rep_index.append(r)
        mirror_of.append(mirror)
        group[r] = g
        done += 1
        if degenerate[r]:
            alike = degenerate & (key_of == key_of[r]) & (group < 0)
            group[alike] = g
            done += int(np.count_nonzero(alike))
            reps.append(None)
            continue
        rep = _Rep(elements[r], r, coarse)
        reps.append(rep)
        b[r] = rep.origin
        members, tree = trees[key_of[r]]
        cands = members[np.array(tree.query_ball_point(desc[r], tol, p=np.inf), dtype=int)]
        cands = np.sort(cands[group[cands] < 0])
        flipped: list[np.ndarray] = []

        def verify(chunk: np.ndarray, rep=rep, mirror=mirror):
            """Match one chunk of candidates against the representative (chunks are independent)."""
            check(cancel)
            ok, phi, gap, pa, pb = matcher.match(rep, chunk, threshold, mirrored=False)
            mirrored = np.zeros(chunk.size, bool)
            if flips and mirror < 0:
                mirrored = matcher.prefer_mirror(rep, chunk, threshold, ok, phi, gap)
            return ok & ~mirrored, mirrored, pa, pb

        chunks = [cands[lo : lo + _CHUNK] for lo in range(0, cands.size, _CHUNK)]
        for chunk, (ok, mirrored, pa, pb) in zip(chunks, pmap(verify, chunks), strict=True):
            flipped.append(chunk[mirrored])
            group[chunk[ok]] = g
            done += int(np.count_nonzero(ok))
            a[chunk[ok]], b[chunk[ok]] = pa[ok], pb[ok]
            report(progress, _STAGE, 0.1 + 0.85 * done / n)
        found = np.concatenate(flipped) if flipped else np.zeros(0, int)
        if found.size:
            pending.append((int(found.min()), g))
        report(progress, _STAGE, 0.1 + 0.85 * done / n)
    symmetry = np.ones(len(rep_index), dtype=int)
    terminals = []
    for g, (r, rep_g) in enumerate(zip(rep_index, reps, strict=True)):
        origin = rep_g.origin if rep_g is not None else complex(b[r])
        name = terminal_name(g)
        other = terminal_name(mirror_of[g]) if mirror_of[g] >= 0 else None
        terminals.append(Terminal(name, _path_data(elements[r], origin), elements[r].style, other))
        if rep_g is None:
            symmetry[g] = 0
            continue
        order, period = symmetry_order(rep_g.ref.dense, rep_g.ref.dense_normals)
        symmetry[g] = order
        sel = group == g
        a[sel] = canonical(a[sel], period)
        a[r], b[r] = 1.0, origin
    report(progress, _STAGE, 1.0)
    return Instancing(group, a, b, tuple(terminals), symmetry, np.array(mirror_of, dtype=int))


def terminal_similarity(
    terminals: tuple[Terminal, ...] | list[Terminal], *, flips: bool = True, cancel: CancelToken | None = None
) -> np.ndarray:
    """Return the shape similarity ``φ`` between every pair of terminals (paper §5.4).

    The importance of a cluster weighs how alike its elements are; for elements of
    different terminals that is the §4.1 similarity of their shapes, taken as the better
    of the shape and its mirror image ("we also flip the sets") when ``flips`` is set.
    Styles are ignored.

    Parameters
    ----------
    terminals : sequence of Terminal
        Terminals with SVG path data (e.g. ``Instancing.terminals``).
    flips : bool
        Also compare with the mirror images.
    cancel : CancelToken, optional
        Checked between terminals.

    Returns
    -------
    ndarray of float, shape (k, k)
        Symmetric, 1 on the diagonal; 0 between a drawable shape and an empty one.
    """
    from lsys_core.geometry.shapes import shape_arrays

    k = len(terminals)
    elements = tuple(Element(*shape_arrays(t.path)) for t in terminals)
    sim = np.eye(k)
    if k < 2:
        return sim
    coarse = sample_elements(elements, arc_fractions(_SAMPLES))
    centroid, radius, _ = element_features(coarse)
    span = np.maximum(np.abs(coarse.points).max(axis=1), 1.0)
    good = np.flatnonzero((coarse.length > 1e-9 * span) & (radius > 1e-9 * span))
    matcher = _Matcher(elements, coarse, centroid, np.where(radius > 0, radius, 1.0))
    for i in good:
        check(cancel)
        others = good[good != i]
        if others.size == 0:
            continue
        rep = _Rep(elements[i], int(i), coarse)
        _, phi, _, _, _ = matcher.match(rep, others, 1.0, mirrored=False)
        if flips:
            phi = np.maximum(phi, matcher.match(rep, others, 1.0, mirrored=True)[1])
        sim[i, others] = phi
    sim = np.maximum(sim, sim.T)
    return sim
