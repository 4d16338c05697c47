"""Analysis of a scene, once for any weights: similarity, instancing, pivots (paper §4, §5.3).

:func:`analyse` computes what inference needs whatever the importance weights (the scene's
terminals and poses, their shape similarity, the precision of the description and a cache of
the hierarchy levels' candidates); :func:`~lsys_core.pipeline.rules_from_analysis` turns an
:class:`Analysis` into rules for any weights.  :func:`paint_like_input` gives an inferred
grammar the input's styles, paint order, definitions and verbatim content.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from lsys_core.cancel import CancelToken, Progress, check
from lsys_core.derive.derivation import Trace, derive_traced
from lsys_core.derive.faithful import fit_paint, match_instances
from lsys_core.derive.model import Drawing
from lsys_core.errors import InferenceError
from lsys_core.grammar.model import Grammar
from lsys_core.hierarchy.cache import LevelCache
from lsys_core.hierarchy.mdl import Precision
from lsys_core.hierarchy.pivots import estimate_pivots, recenter
from lsys_core.instancing.fidelity import split_unfaithful
from lsys_core.instancing.halfturn import turn_near_symmetric
from lsys_core.instancing.merge import merge_within
from lsys_core.instancing.model import Instancing, terminal_shapes
from lsys_core.instancing.orientation import ring_headings, unwrap_symmetric
from lsys_core.instancing.roundness import merge_round, round_within
from lsys_core.instancing.stretch import stretch_families
from lsys_core.report import as_instancing, bounds, element_circles
from lsys_core.settings import InferenceSettings
from lsys_core.svg.model import Scene

__all__ = [
    "DEFAULT_DEVIATION",
    "EXACT_PLACEMENT",
    "SYMMETRIZE_SHAPES",
    "Analysis",
    "analyse",
    "paint_like_input",
]

#: Default tolerance: the derived drawing may deviate from the input by this share of its diagonal.
DEFAULT_DEVIATION = 0.005
#: With tolerance 0 (exact copies only), rules still place elements to this share of the
#: diagonal: the precision SVG coordinates are written at.
EXACT_PLACEMENT = 1e-4
#: :func:`~lsys_core.pipeline.symmetrize` lets shapes that deviate this many times the
#: tolerance share a terminal.
SYMMETRIZE_SHAPES = 2.0


def _shape_similarity(inst: Instancing, cancel: CancelToken | None) -> np.ndarray:
    """Similarity of pairs of terminals for the importance's φ (§5.4, mirror images count as alike)."""
    from lsys_core.instancing.similarity import terminal_similarity

    if len(inst.terminals) > 64:  # pairwise shape matching; beyond this a constant keeps it cheap
        k = len(inst.terminals)
        return np.full((k, k), 0.5) + 0.5 * np.eye(k)
    return terminal_similarity(inst.terminals, cancel=cancel)


def _instancing(scene: Scene, settings: InferenceSettings, tolerance: float, cancel, progress) -> Instancing:
    """Terminals and poses (§4.1–4.2): similar shapes within ``tolerance`` share a terminal, the medoid."""
    from lsys_core.instancing.representative import medoids, regular_scales
    from lsys_core.instancing.similarity import detect_similarity

    inst = detect_similarity(scene, threshold=settings.similarity, cancel=cancel, progress=progress)
    check(cancel)
    inst = split_unfaithful(scene, inst, tolerance=tolerance, threshold=settings.similarity, cancel=cancel)
    inst = merge_within(scene, inst, tolerance)
    inst = regular_scales(scene, medoids(scene, inst, tolerance), tolerance)
    inst = turn_near_symmetric(scene, inst, tolerance)
    inst = round_within(terminal_shapes(inst), inst, tolerance)
    inst = merge_round(scene.elements, terminal_shapes(inst), inst, tolerance)
    return stretch_families(scene, inst, tolerance)


def paint_like_input(
    grammar: Grammar, scene: Scene, inst: Instancing, derived: tuple[Drawing, Trace] | None = None
) -> Grammar:
    """Give an inferred grammar the input's names, styles, paint order, defs and verbatim content.

    The grammar is derived once (``derived``: its :func:`~lsys_core.derive.derivation.derive_traced`
    with the limit :func:`paint_limit`, if already made)
    and each instance matched to its element (:func:`~lsys_core.derive.faithful.fit_paint`);
    the scene's ``defs`` and verbatim content are carried over, each verbatim item placed
    after the instances of the elements that precede it in the document.
    """
    orders = np.array([e.order if e.order >= 0 else i for i, e in enumerate(scene.elements)], float)
    drawing, trace = derived if derived is not None else derive_traced(grammar, limit=paint_limit(scene))
    names = [inst.terminals[g].name for g in inst.group]
    mapped = as_instancing(drawing, inst)  # stretched copies by the terminals of their elements
    match = match_instances(
        [t.name for t in mapped.terminals], mapped.symbol, mapped.a, mapped.b, names, inst.a, inst.b
    )
    if match is not None:
        grammar = fit_paint(grammar, [e.style for e in scene.elements], orders, match, trace, drawing)
    verbatim = tuple(
        replace(v, order=int(np.count_nonzero(orders < v.order)))
        for v in sorted(scene.verbatim, key=lambda v: v.order)
    )
    return replace(grammar, defs=scene.defs, verbatim=verbatim)


def paint_limit(scene: Scene) -> int:
    """The instance limit :func:`paint_like_input` derives a grammar of ``scene`` with."""
    return max(10 * len(scene.elements), 1000)


@dataclass(frozen=True, eq=False)
class Analysis:
    """What inference computes once per scene, whatever the importance weights (§4, §5.3).

    Similarity detection and inverse instancing (with the fidelity split, unwrapped symmetric
    rotations and pivots), the shape similarity of the terminals, the precision of the
    description, and a cache of every hierarchy level's transformation spaces, clustering and
    candidates.  :func:`rules_from_analysis` turns it into rules for any weights: only
    importance, rule generation, post-processing and derivation run again.  Made by
    :func:`analyse`; keep it in the process that made it.

    Attributes
    ----------
    scene : Scene
        The analysed scene.
    settings : InferenceSettings
        The settings it was made with (its weights are only defaults).
    instancing : Instancing
        Terminals and poses after the fidelity split, unwrapping and pivots.
    sizes, center, radius : ndarray
        Reach of every terminal's shape from its origin; bounding circle of every element.
    precision : Precision
        The tolerance the description is written at.
    shape_similarity : ndarray
        φ of every pair of terminals.
    levels : LevelCache
        Candidates of the hierarchy levels met so far (filled by rule generation).
    stages : dict
        Seconds spent in the analysis stages.
    symmetrizing : bool
        Made for :func:`symmetrize` (shapes grouped at a relaxed tolerance).
    """

    scene: Scene
    settings: InferenceSettings
    instancing: Instancing
    sizes: np.ndarray
    center: np.ndarray
    radius: np.ndarray
    precision: Precision
    shape_similarity: np.ndarray
    levels: LevelCache
    stages: dict[str, float]
    symmetrizing: bool = False


def analyse(
    scene: Scene,
    settings: InferenceSettings = InferenceSettings(),
    *,
    previous: Analysis | None = None,
    symmetrizing: bool = False,
    cancel: CancelToken | None = None,
    progress: Progress | None = None,
) -> Analysis:
    """Analyse ``scene`` once for any number of rule generations (see :class:`Analysis`).

    With ``previous`` (an analysis of the same scene object), only what ``settings`` change
    is computed again: a new similarity threshold or deviation redoes everything; a new number
    of neighbours starts an empty level cache; new weights or a new tolerance reuse all of it
    (the level cache is keyed by the bandwidths).  ``symmetrizing`` groups shapes at the
    relaxed tolerance of :func:`symmetrize`.
    """
    settings = settings.validated()
    if not scene.elements:
        raise InferenceError("the scene has no drawable elements")
    if (
        previous is not None
        and previous.scene is scene
        and previous.settings.similarity == settings.similarity
        and previous.settings.deviation == settings.deviation
        and previous.symmetrizing == symmetrizing
    ):
        same = previous.settings.neighbours == settings.neighbours
        return replace(previous, settings=settings, levels=previous.levels if same else LevelCache())
    stages: dict[str, float] = {}
    center, radius = element_circles(scene)
    box = bounds(scene)
    diag = max(abs(box[1] - box[0]), 1e-12)
    eps = DEFAULT_DEVIATION * diag if settings.deviation is None else settings.deviation
    eps = max(eps, EXACT_PLACEMENT * diag)  # 0: exact copies, placed as precisely as SVG writes them
    t = time.perf_counter()
    inst = _instancing(scene, settings, SYMMETRIZE_SHAPES * eps if symmetrizing else eps, cancel, progress)
    stages["similarity"] = time.perf_counter() - t
    sizes = np.zeros(len(inst.terminals))
    np.maximum.at(sizes, inst.group, radius / np.maximum(np.abs(inst.a), 1e-300))
    t = time.perf_counter()
    prec = Precision.of_box(*box, eps)
    inst = ring_headings(unwrap_symmetric(inst), eps)
    offsets = estimate_pivots(inst, sizes, tolerance=prec.eps)
    if inst.stretch_base is not None:  # a stretch cuts its shape through the origin: keep it there
        family = inst.stretch_base >= 0
        family[inst.stretch_base[family]] = True
        offsets = np.where(family, 0.0, offsets)
    inst = recenter(inst, offsets)
    sizes = sizes + np.abs(offsets)  # how far each shape reaches from its (moved) origin
    stages["pivots"] = time.perf_counter() - t
    shape_sim = _shape_similarity(inst, cancel)
    return Analysis(
        scene, settings, inst, sizes, center, radius, prec, shape_sim, LevelCache(), stages, symmetrizing
    )
