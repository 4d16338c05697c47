"""The whole inference, from a :class:`~lsys_core.svg.model.Scene` to a :class:`Grammar`.

>>> from lsys_core.svg.parse import load_svg              # doctest: +SKIP
>>> result = infer(load_svg("helix.svg"))                 # doctest: +SKIP
>>> print(format_grammar(result.grammar))                  # doctest: +SKIP
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from lsys_core.cancel import CancelToken, Progress, check, report
from lsys_core.derive.derivation import derive
from lsys_core.errors import InferenceError
from lsys_core.grammar.model import Grammar
from lsys_core.hierarchy.pivots import estimate_pivots, recenter
from lsys_core.hierarchy.postprocess import simplify
from lsys_core.hierarchy.rules import Hierarchy, Tolerance, Weights, build_hierarchy
from lsys_core.instancing.fidelity import split_unfaithful
from lsys_core.instancing.model import Instancing
from lsys_core.instancing.orientation import unwrap_symmetric
from lsys_core.settings import SETTINGS, setting
from lsys_core.settings import check as check_setting
from lsys_core.svg.model import Scene

__all__ = ["InferenceResult", "InferenceSettings", "infer", "symmetrize"]

#: Bandwidth factor used by :func:`symmetrize` (the paper's "relaxed sensitivity").
RELAXED = 12.0
#: Largest reproduction error (relative to the scene's diagonal) :func:`infer` accepts
#: when it relaxes the clustering to explain jittered repetitions.
INFER_ERROR = 0.004
#: Largest deviation (relative to the scene's diagonal) of an element from the terminal
#: drawn in its place; elements farther from their group's shape get a terminal of their own.
SHAPE_ERROR = 0.002
#: Scenes with more elements than this try fewer relaxed tolerances (see :func:`_factors`).
LARGE_SCENE = 1000
#: A relaxed grammar may deviate up to this much if it needs at most :data:`JITTER_GAIN`
#: times the productions of the exact one (jittered repetitions, paper Fig. 10).
JITTER_ERROR = 0.025
JITTER_GAIN = 0.7
#: The same for :func:`symmetrize`, whose purpose is to move elements onto a regular pattern.
SYMMETRIZE_ERROR = 0.03


@dataclass(frozen=True)
class InferenceSettings:
    """User settings of the inference.

    Attributes
    ----------
    wn, wh, wphi, wl : float
        Cluster importance weights in [0, 1] (§5.4): repetition count, proximity,
        similarity and sequence length.
    similarity : float
        Similarity threshold φ for two elements to share a terminal (§4.1).
    tolerance : float
        Factor on the clustering bandwidths; larger values merge jittered repetitions.
    neighbours : int
        Neighbours per node in the transformation spaces.
    """

    wn: float = setting("wn").default
    wh: float = setting("wh").default
    wphi: float = setting("wphi").default
    wl: float = setting("wl").default
    similarity: float = setting("similarity").default
    tolerance: float = setting("tolerance").default
    neighbours: int = 24

    def relaxed(self, factor: float = RELAXED) -> InferenceSettings:
        """Return these settings with the tolerance multiplied by ``factor`` (for symmetrization)."""
        return replace(self, tolerance=self.tolerance * factor)

    def validated(self) -> InferenceSettings:
        """Return the settings, raising :class:`InferenceError` for values out of range.

        The ranges are those of :data:`lsys_core.settings.SETTINGS` (which the editor's sliders
        and the CLI's help show too).
        """
        for s in SETTINGS:
            problem = check_setting(s.name, float(getattr(self, s.name)))
            if problem is not None:
                raise InferenceError(problem)
        return self


@dataclass(frozen=True, eq=False)
class InferenceResult:
    """What :func:`infer` returns: the grammar, the instancing and timings (seconds per stage)."""

    grammar: Grammar
    instancing: Instancing
    stages: dict[str, float]
    seconds: float
    log: tuple[str, ...] = field(default=())


def _element_circles(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Return the centre and radius of every element's control polygon (vectorised)."""
    sizes = np.array([e.cubics.shape[0] for e in scene.elements])
    pts = np.concatenate([e.cubics.reshape(-1) for e in scene.elements])
    owner = np.repeat(np.arange(sizes.size), sizes * 4)
    cnt = np.bincount(owner, minlength=sizes.size)
    cen = (np.bincount(owner, pts.real, sizes.size) + 1j * np.bincount(owner, pts.imag, sizes.size)) / cnt
    rad = np.zeros(sizes.size)
    np.maximum.at(rad, owner, np.abs(pts - cen[owner]))
    return cen, rad


def _shape_similarity(inst: Instancing, cancel: CancelToken | None) -> np.ndarray:
    """Similarity of pairs of terminals for the importance's φ (§5.4, mirror images count as alike)."""
    from lsys_core.instancing.similarity import terminal_similarity

    if len(inst.terminals) > 64:  # pairwise shape matching; beyond this a constant keeps it cheap
        k = len(inst.terminals)
        return np.full((k, k), 0.5) + 0.5 * np.eye(k)
    return terminal_similarity(inst.terminals, cancel=cancel)


def description_size(g: Grammar) -> int:
    """Size of a grammar's rules: modules in all productions and the axiom, plus one per production.

    Used to compare grammars found at different tolerances: a rule that merely lists the
    nodes no repetition explains is as large as what it lists.
    """
    return len(g.axiom) + sum(1 + len(c.body) for r in g.rules for c in r.cases)


def _diagonal(center: np.ndarray, radius: np.ndarray) -> float:
    lo = np.array([np.min(center.real - radius), np.min(center.imag - radius)])
    hi = np.array([np.max(center.real + radius), np.max(center.imag + radius)])
    return max(float(np.hypot(*(hi - lo))), 1e-12)


def _factors(settings: InferenceSettings, symmetrizing: bool, n: int) -> list[float]:
    """Bandwidth factors to try: the user's tolerance first, then relaxed ones.

    Large scenes try fewer relaxed factors: each try is a whole rule generation.
    """
    steps: tuple[float, ...]
    if symmetrizing:
        steps = (1.0, 2.0)
    elif n <= LARGE_SCENE:
        steps = (1.0, 3.0, 5.0, 9.0, 15.0)
    else:
        steps = (1.0, 5.0)
    return [settings.tolerance * f for f in steps]


def reproduction_error(inst: Instancing, sizes: np.ndarray, drawing) -> float:
    """Largest displacement of an input element in ``drawing`` (document units).

    Each input element is matched to the nearest derived instance of its terminal; the
    displacement counts the translation and the rotation/scale change at the shape's radius.
    Missing instances count as infinitely far.
    """
    from scipy.spatial import cKDTree

    worst = 0.0
    for g in range(len(inst.terminals)):
        mine = np.flatnonzero(inst.group == g)
        theirs = np.flatnonzero(drawing.symbol == g)
        if mine.size != theirs.size:
            return float("inf")
        if mine.size == 0:
            continue
        tb = drawing.b[theirs]
        _, j = cKDTree(np.column_stack([tb.real, tb.imag])).query(
            np.column_stack([inst.b[mine].real, inst.b[mine].imag])
        )
        err = np.abs(inst.b[mine] - tb[j]) + sizes[g] * np.abs(inst.a[mine] - drawing.a[theirs][j])
        worst = max(worst, float(err.max()))
    return worst


def infer(
    scene: Scene,
    settings: InferenceSettings = InferenceSettings(),
    *,
    cancel: CancelToken | None = None,
    progress: Progress | None = None,
    symmetrizing: bool = False,
) -> InferenceResult:
    """Infer a compact L-system that regenerates ``scene`` (paper §4–§5).

    Parameters
    ----------
    scene : Scene
        The imported SVG.
    settings : InferenceSettings
        Weights, similarity threshold and clustering tolerance.
    cancel : CancelToken, optional
        Checked between stages and levels; raises :class:`~lsys_core.errors.Cancelled`.
    progress : callable, optional
        ``progress(stage, fraction)`` for the stages ``similarity`` and ``rules``.
    symmetrizing : bool
        Used by :func:`symmetrize`: relaxed bandwidths, larger accepted deviation.

    Notes
    -----
    If the rules found at the user's tolerance leave elements unexplained by any
    repetition, the clustering is relaxed (×3 … ×15) and the grammar with the fewest
    rules (:func:`description_size`) is kept among those that deviate at most
    :data:`INFER_ERROR` from the input, or at most :data:`JITTER_ERROR` when they are
    clearly smaller (a jittered pattern).

    Returns
    -------
    InferenceResult
    """
    from lsys_core.instancing.similarity import detect_similarity

    settings = settings.validated()
    if not scene.elements:
        raise InferenceError("the scene has no drawable elements")
    t_all = time.perf_counter()
    stages: dict[str, float] = {}
    t = time.perf_counter()
    inst = detect_similarity(scene, threshold=settings.similarity, cancel=cancel, progress=progress)
    stages["similarity"] = time.perf_counter() - t
    check(cancel)
    center, radius = _element_circles(scene)
    t = time.perf_counter()
    inst = split_unfaithful(
        scene,
        inst,
        radius,
        threshold=settings.similarity,
        absolute=SHAPE_ERROR * _diagonal(center, radius),
        cancel=cancel,
    )
    stages["similarity"] += time.perf_counter() - t
    sizes = np.zeros(len(inst.terminals))
    np.maximum.at(sizes, inst.group, radius / np.maximum(np.abs(inst.a), 1e-300))
    t = time.perf_counter()
    inst = unwrap_symmetric(inst)
    inst = recenter(inst, estimate_pivots(inst, sizes))
    stages["pivots"] = time.perf_counter() - t
    weights = Weights(settings.wn, settings.wh, settings.wphi, settings.wl)
    diag = _diagonal(center, radius)
    shape_sim = _shape_similarity(inst, cancel)
    best: tuple[Grammar, Hierarchy, float] | None = None
    first_count: int | None = None  # production count of the first try, which is always kept
    for factor in _factors(settings, symmetrizing, len(scene.elements)):
        check(cancel)
        hier = build_hierarchy(
            [t.name for t in inst.terminals],
            sizes,
            inst.group,
            inst.a,
            inst.b,
            center,
            radius,
            weights=weights,
            tol=Tolerance().scaled(factor),
            similarity=shape_sim,
            neighbours=settings.neighbours,
            cancel=cancel,
            progress=progress,
            timer=stages,
        )
        t = time.perf_counter()
        grammar = simplify(Grammar(inst.terminals, tuple(hier.rules), hier.axiom, scene.viewbox, scene.size))
        error = (
            reproduction_error(inst, sizes, derive(grammar, limit=max(10 * len(scene.elements), 1000))) / diag
        )
        stages["postprocess"] = stages.get("postprocess", 0.0) + time.perf_counter() - t
        count = description_size(grammar)
        if first_count is None:
            ok = True
        elif symmetrizing:
            ok = error <= SYMMETRIZE_ERROR
        else:
            ok = error <= INFER_ERROR or (error <= JITTER_ERROR and count <= JITTER_GAIN * first_count)
        if ok and (best is None or (count, error) < (description_size(best[0]), best[2])):
            best = (grammar, hier, error)
        if first_count is None:
            first_count = count
        if hier.closed and not symmetrizing:
            break  # every element is explained by repetitions: no need to relax
    assert best is not None  # _factors is never empty and the first try is always kept
    grammar, hier, error = best
    stages["reproduction_error"] = error
    report(progress, "done", 1.0)
    return InferenceResult(grammar, inst, stages, time.perf_counter() - t_all, tuple(hier.log))


def symmetrize(
    scene: Scene,
    settings: InferenceSettings = InferenceSettings(),
    *,
    factor: float = RELAXED,
    cancel: CancelToken | None = None,
    progress: Progress | None = None,
) -> InferenceResult:
    """Infer with relaxed clustering so jittered repetitions share one mean transform (Fig. 10)."""
    return infer(scene, settings.relaxed(factor), cancel=cancel, progress=progress, symmetrizing=True)
