"""The whole inference, from a :class:`~lsys_core.svg.model.Scene` to a :class:`Grammar`.

:mod:`.analysis` analyses a scene once (similarity, instancing, pivots); this module turns an
analysis into rules for given weights (relaxed tries, minimum description length, the tighter
try) and runs the whole of it (:func:`infer`, :func:`symmetrize`).

>>> from lsys_core.svg.parse import load_svg              # doctest: +SKIP
>>> result = infer(load_svg("helix.svg"))                 # doctest: +SKIP
>>> print(format_grammar(result.grammar))                  # doctest: +SKIP
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from lsys_core.cancel import CancelToken, Progress, check, report
from lsys_core.derive.derivation import Trace, derive, derive_traced
from lsys_core.derive.model import Drawing
from lsys_core.grammar.model import Grammar
from lsys_core.hierarchy.describe import flat_bits, grammar_bits
from lsys_core.hierarchy.explain import explained_share, placed_by_repetition
from lsys_core.hierarchy.postprocess import simplify
from lsys_core.hierarchy.rules import Hierarchy, Tolerance, Weights, build_hierarchy
from lsys_core.hierarchy.snap import SHARE
from lsys_core.report import (
    InferenceResult,
    Matched,
    as_instancing,
    deviation,
    displacement,
    matched_poses,
    measurer,
)
from lsys_core.settings import RELAXED, InferenceSettings
from lsys_core.svg.model import Scene

from .analysis import (
    DEFAULT_DEVIATION,
    EXACT_PLACEMENT,
    SYMMETRIZE_SHAPES,
    Analysis,
    analyse,
    paint_like_input,
    paint_limit,
)

__all__ = [
    "DEFAULT_DEVIATION",
    "EXACT_PLACEMENT",
    "SYMMETRIZE_SHAPES",
    "Analysis",
    "InferenceResult",
    "InferenceSettings",
    "analyse",
    "infer",
    "paint_like_input",
    "rules_from_analysis",
    "symmetrize",
    "tighter_if_better",
]

#: :func:`symmetrize` rounds the rules' numbers within this share of its tolerance (and lets
#: shapes that deviate :data:`~.analysis.SYMMETRIZE_SHAPES` times the tolerance share a terminal).
SYMMETRIZE_SNAP = 0.5
#: Scenes with more elements than this try fewer relaxed tolerances (see :func:`_tries`).
LARGE_SCENE = 1000
#: The noise floor of the clustering bandwidths in the try that has one, as a share of the
#: tolerance (see :class:`~lsys_core.hierarchy.rules.Tolerance`).
NOISE_FLOOR = 0.5
#: The tolerance of :func:`symmetrize`, whose purpose is to move elements onto a regular pattern
#: (share of the diagonal; the user's tolerance if larger).
SYMMETRIZE_ERROR = 0.03
#: :func:`infer` also tries this share of the tolerance when near-identical shapes that differ
#: by more than it share a terminal that is placed one by one somewhere, and keeps it when its
#: rules explain more elements, at least :data:`MIN_EXPLAINED` more for every production they
#: add.  Only scenes of at most
#: :data:`TIGHTER_SCENE` elements (icons, emoji: where a few merged shapes decide the
#: structure) are inferred twice: a chart of 228 elements took 14 s, with the try 42 s.
TIGHTER = 0.25
MIN_EXPLAINED = 2
TIGHTER_SCENE = 64


def _tries(settings: InferenceSettings, symmetrizing: bool, n: int, drawn_by_hand: bool) -> list[Tolerance]:
    """Clustering bandwidths to try: the user's tolerance first, then relaxed ones.

    Each factor is tried also with the bandwidths' noise floor (``Tolerance.length``,
    :data:`NOISE_FLOOR`): copies drawn by hand, a little off in size and place, pair up as one
    repetition.  Like every try it is kept only when its grammar is the shortest (minimum
    description length), so drawings where the floor merges distinct transforms keep the
    grammar without it.  The floor measures how far copies' outlines deviate from their
    terminal: without ``drawn_by_hand`` (every copy exact, up to the precision SVG coordinates
    are written at, :data:`EXACT_PLACEMENT`) it is not tried: a floor of rounding noise is far
    below the bandwidths, and its try repeated the plain one (a chart of 435 ticks whose shapes
    deviate by 3e-16 of the diagonal ran ten tries, five of them the same as the other five).  Large scenes try
    fewer relaxed factors and no floor: each try is a whole rule generation.
    """
    steps: tuple[float, ...]
    if symmetrizing:
        steps = (1.0, 2.0)
    elif n <= LARGE_SCENE:
        steps = (1.0, 3.0, 5.0, 9.0, 15.0)
    else:
        steps = (1.0, 5.0)
    tries = []
    for f in steps:
        tol = Tolerance().scaled(settings.tolerance * f)
        tries.append(tol)
        if n <= LARGE_SCENE and drawn_by_hand:
            tries.append(replace(tol, length=NOISE_FLOOR * settings.tolerance * f))
    return tries


def rules_from_analysis(
    analysis: Analysis,
    weights: Weights | None = None,
    *,
    tolerance: float | None = None,
    symmetrizing: bool = False,
    cancel: CancelToken | None = None,
    progress: Progress | None = None,
) -> InferenceResult:
    """Generate rules from an :class:`Analysis` with the importance ``weights`` (§5.4–§5.7).

    Gives what :func:`infer` gives with those weights; levels whose candidates the analysis
    already holds are not clustered again.

    Parameters
    ----------
    analysis : Analysis
        From :func:`analyse`.
    weights : Weights, optional
        Importance weights (default: those of ``analysis.settings``).
    tolerance : float, optional
        Factor on the clustering bandwidths (default: ``analysis.settings.tolerance``).
    symmetrizing : bool
        Relaxed acceptance of :func:`symmetrize`.
    """
    settings = analysis.settings
    if weights is None:
        weights = Weights(settings.wn, settings.wh, settings.wphi, settings.wl)
    if tolerance is not None:
        settings = replace(settings, tolerance=tolerance).validated()
    replace(settings, wn=weights.wn, wh=weights.wh, wphi=weights.wphi, wl=weights.wl).validated()
    scene, inst, sizes, prec = analysis.scene, analysis.instancing, analysis.sizes, analysis.precision
    t_all = time.perf_counter()
    stages = dict(analysis.stages)
    diag = prec.diagonal
    limit = max(prec.eps, SYMMETRIZE_ERROR * diag) if symmetrizing else prec.eps
    shape_dev = inst.deviation if inst.deviation is not None else np.zeros(inst.a.size)
    slack = np.maximum(limit - shape_dev, 0.0)
    measure = measurer(scene, inst)
    # stretched copies are drawn as their base with a stretch: the grammar does not list them
    copies = inst.stretch_base if inst.stretch_base is not None else np.full(len(inst.terminals), -1)
    drawn = tuple(t for t, c in zip(inst.terminals, copies, strict=True) if c < 0)
    best: tuple[Grammar, Hierarchy, float, float, Drawing, Matched, tuple[Drawing, Trace]] | None = None
    by_hand = bool(np.any(shape_dev > EXACT_PLACEMENT * diag))  # beyond rounding: see _tries
    for tol in _tries(settings, symmetrizing, len(scene.elements), by_hand):
        check(cancel)
        hier = build_hierarchy(
            [t.name for t in inst.terminals],
            sizes,
            inst.group,
            inst.a,
            inst.b,
            analysis.center,
            analysis.radius,
            weights=weights,
            tol=tol,
            similarity=analysis.shape_similarity,
            precision=prec,
            tolerance=limit,
            slack=slack,
            snap=SYMMETRIZE_SNAP if symmetrizing else SHARE,
            measure=measure,
            symmetry=inst.symmetry,
            neighbours=settings.neighbours,
            cancel=cancel,
            progress=progress,
            timer=stages,
            cache=analysis.levels,
            stretch_base=inst.stretch_base,
            stretch=inst.stretch,
        )
        t = time.perf_counter()
        grammar = simplify(Grammar(drawn, tuple(hier.rules), hier.axiom, scene.viewbox, scene.size))
        derived = derive_traced(grammar, limit=paint_limit(scene))  # painting the kept one reads it too
        drawing = as_instancing(derived[0], inst)
        matched = matched_poses(inst, sizes, drawing)
        error = deviation(inst, sizes, matched, shape_dev, limit, measure)
        bits = grammar_bits(grammar, prec)
        stages["postprocess"] = stages.get("postprocess", 0.0) + time.perf_counter() - t
        # The first try is always kept; relaxed ones must stay within the tolerance and be shorter.
        if best is None or (error <= limit and (bits, error) < (best[3], best[2])):
            best = (grammar, hier, error, bits, drawing, matched, derived)
        if hier.closed and not symmetrizing:
            break  # every element is explained by repetitions: no need to relax
        if hier.levels == 0 and len(scene.elements) > LARGE_SCENE:
            break  # nothing repeats at all in a large scene: relaxing would only find chance
    assert best is not None  # _tries is never empty and the first try is always kept
    grammar, hier, error, bits, drawing, matched, derived = best
    stages["reproduction_error"] = displacement(inst, sizes, matched) / diag
    t = time.perf_counter()
    grammar = paint_like_input(grammar, scene, inst, derived)
    stages["paint"] = time.perf_counter() - t
    report(progress, "done", 1.0)
    segments = np.array([e.cubics.shape[0] for e in scene.elements])
    return InferenceResult(
        grammar,
        inst,
        stages,
        time.perf_counter() - t_all,
        tuple(hier.log),
        tolerance=limit,
        max_deviation=error,
        explained=explained_share(grammar, drawing.rule),
        description_bits=(flat_bits(prec, segments, analysis.radius), bits),
    )


def _merged_placed_alone(result: InferenceResult, tight: float) -> bool:
    """Whether a terminal the rules place one by one somewhere stands for shapes that differ by more than ``tight``."""
    inst = result.instancing
    if inst.deviation is None or not np.any(inst.deviation > tight):
        return False
    far = {inst.terminals[g].name for g in np.unique(inst.group[inst.deviation > tight])}
    drawing = derive(result.grammar, limit=max(10 * inst.group.size, 1000))
    alone = np.unique(drawing.symbol[~placed_by_repetition(result.grammar, drawing.rule)])
    bases = drawing.bases or tuple(range(len(drawing.terminals)))
    return any(drawing.terminals[bases[int(k)]].name in far for k in alone)


def tighter_if_better(
    analysis: Analysis,
    result: InferenceResult,
    *,
    cancel: CancelToken | None = None,
    progress: Progress | None = None,
) -> InferenceResult:
    """``result``, or the rules at :data:`TIGHTER` of the tolerance when they explain more.

    A looser tolerance should only buy structure.  When it lets shapes that differ share a
    terminal (a symmetric corner merged into asymmetric ones) that the rules then place one by
    one somewhere, the terminal's copies no longer repeat exactly what each kind repeats: the
    scene (of at most :data:`TIGHTER_SCENE` elements) is inferred again at the tighter
    tolerance, and that result is kept when its rules explain more elements, at least
    :data:`MIN_EXPLAINED` more for every production they add (it is also the more faithful
    one).  :func:`infer` and the editor's worker both end with it, so both give the same rules.
    """
    scene, settings = analysis.scene, analysis.settings
    tight = TIGHTER * analysis.precision.eps
    if not (
        0.0 < result.explained < 1.0  # cost: distinct shapes (nothing repeats) are not inferred twice
        and len(scene.elements) <= TIGHTER_SCENE
        and tight > EXACT_PLACEMENT * analysis.precision.diagonal
        and _merged_placed_alone(result, tight)
    ):
        return result
    closer = analyse(scene, replace(settings, deviation=tight), cancel=cancel, progress=progress)
    other = rules_from_analysis(closer, cancel=cancel, progress=progress)
    # every production it adds must explain two more elements (a repetition places two at
    # least): at a finer precision, chance coincidences among many elements (a chart's
    # data) pay for pair rules of their own that explain next to nothing more
    more = (other.explained - result.explained) * len(scene.elements)
    added = other.grammar.production_count - result.grammar.production_count
    return other if more > 0.5 and more >= MIN_EXPLAINED * added else result


def infer(
    scene: Scene,
    settings: InferenceSettings = InferenceSettings(),
    *,
    cancel: CancelToken | None = None,
    progress: Progress | None = None,
    symmetrizing: bool = False,
) -> InferenceResult:
    """Infer a compact L-system that regenerates ``scene`` (paper §4–§5).

    :func:`analyse` then :func:`rules_from_analysis`; keep the :class:`Analysis` to try other
    weights cheaply.

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
    Rules are written only when they shorten the description of the drawing (minimum
    description length, :mod:`lsys_core.hierarchy.mdl`) and derive their elements within the
    tolerance.  If the rules found at the user's clustering bandwidth leave elements
    unexplained by any repetition, the clustering is relaxed (×3 … ×15) and the shortest
    grammar (in bits) that stays within the tolerance is kept.  When the tolerance let shapes
    that differ by more than :data:`TIGHTER` of it share a terminal that the rules place one
    by one somewhere (there the merge may have cost a repetition), and the rules explain some
    but not all of the drawing (scenes of at most :data:`TIGHTER_SCENE` elements), the
    inference runs again at that tighter tolerance and keeps it when it explains more
    elements, two more for every production it adds (:attr:`InferenceResult.tolerance` says
    which tolerance the result is written at).

    Returns
    -------
    InferenceResult
    """
    t_all = time.perf_counter()
    analysis = analyse(scene, settings, symmetrizing=symmetrizing, cancel=cancel, progress=progress)
    result = rules_from_analysis(analysis, symmetrizing=symmetrizing, cancel=cancel, progress=progress)
    if not symmetrizing:
        result = tighter_if_better(analysis, result, cancel=cancel, progress=progress)
    return replace(result, seconds=time.perf_counter() - t_all)


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
