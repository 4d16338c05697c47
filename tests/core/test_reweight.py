"""Re-weighting from a kept analysis gives what a full inference with those weights gives."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import lsys_core.hierarchy.gain as gain_mod
import lsys_core.hierarchy.rules as rules_mod
import lsys_core.instancing.similarity as similarity_mod
from lsys_core.derive.derivation import derive
from lsys_core.grammar import format_grammar
from lsys_core.hierarchy.cache import LevelCache
from lsys_core.hierarchy.rules import Weights
from lsys_core.pipeline import InferenceSettings, analyse, infer, rules_from_analysis
from lsys_core.svg.parse import load_svg

EXAMPLES = Path(__file__).resolve().parents[2] / "resources" / "examples"
WEIGHTS = [Weights(), Weights(1.0, 0.1, 0.0, 1.0), Weights(0.0, 1.0, 1.0, 0.0), Weights(0.5, 0.5, 0.5, 0.5)]


def _same(r1, r2) -> None:
    assert format_grammar(r1.grammar) == format_grammar(r2.grammar)
    d1, d2 = derive(r1.grammar), derive(r2.grammar)
    assert np.array_equal(d1.symbol, d2.symbol)
    assert np.array_equal(d1.a, d2.a) and np.array_equal(d1.b, d2.b)
    assert r1.log == r2.log


def _counted(calls: dict[str, int], name: str, fn):
    """``fn``, counting its calls in ``calls[name]``."""

    def wrapper(*args, **kwargs):
        calls[name] += 1
        return fn(*args, **kwargs)

    return wrapper


@pytest.mark.parametrize("name", ["facade", "flower-ring", "tiled-ornament"])
def test_rules_from_analysis_equal_full_runs_for_every_weight(name: str) -> None:
    scene = load_svg(EXAMPLES / f"{name}.svg")
    analysis = analyse(scene)
    for w in WEIGHTS:
        settings = InferenceSettings(wn=w.wn, wh=w.wh, wphi=w.wphi, wl=w.wl)
        _same(rules_from_analysis(analysis, w), infer(scene, settings))


def test_reweighting_runs_neither_similarity_nor_first_level_clustering_again(monkeypatch) -> None:
    scene = load_svg(EXAMPLES / "facade.svg")
    analysis = analyse(scene)
    rules_from_analysis(analysis)
    calls = {"similarity": 0, "levels": 0}

    monkeypatch.setattr(
        similarity_mod, "detect_similarity", _counted(calls, "similarity", similarity_mod.detect_similarity)
    )
    monkeypatch.setattr(rules_mod, "find_candidates", _counted(calls, "levels", rules_mod.find_candidates))
    hits = analysis.levels.hits
    rules_from_analysis(analysis, Weights())
    assert calls == {"similarity": 0, "levels": 0}  # same weights: every level is known
    assert analysis.levels.hits > hits
    rules_from_analysis(analysis, Weights(1.0, 0.1, 0.0, 1.0))
    assert calls["similarity"] == 0  # other weights: at most the levels after another choice


def test_analyse_reuses_what_a_setting_does_not_change() -> None:
    scene = load_svg(EXAMPLES / "helix.svg")
    first = analyse(scene)
    looser = analyse(scene, InferenceSettings(tolerance=3.0), previous=first)
    assert looser.instancing is first.instancing and looser.levels is first.levels
    _same(rules_from_analysis(looser), infer(scene, InferenceSettings(tolerance=3.0)))
    fewer = analyse(scene, InferenceSettings(neighbours=8), previous=first)
    assert fewer.instancing is first.instancing and fewer.levels is not first.levels
    other = analyse(scene, InferenceSettings(similarity=0.8), previous=first)
    assert other.instancing is not first.instancing
    elsewhere = analyse(load_svg(EXAMPLES / "helix.svg"), previous=first)
    assert elsewhere.instancing is not first.instancing  # another scene object: analysed anew


def test_a_sequence_of_weights_and_tolerances_from_one_analysis_equals_full_runs() -> None:
    """Levels, their views (start orders, ledgers, tested candidates) and the order are reused
    across weight changes, back and forth, and across a tolerance change: never a different result."""
    scene = load_svg(EXAMPLES / "tiled-ornament.svg")
    analysis = analyse(scene)
    sequence = [WEIGHTS[1], WEIGHTS[0], WEIGHTS[2], WEIGHTS[1], WEIGHTS[3], WEIGHTS[0]]
    for w in sequence:
        settings = InferenceSettings(wn=w.wn, wh=w.wh, wphi=w.wphi, wl=w.wl)
        _same(rules_from_analysis(analysis, w), infer(scene, settings))
    looser = analyse(scene, InferenceSettings(tolerance=3.0), previous=analysis)
    for w in (WEIGHTS[2], WEIGHTS[0]):
        settings = InferenceSettings(tolerance=3.0, wn=w.wn, wh=w.wh, wphi=w.wphi, wl=w.wl)
        _same(rules_from_analysis(looser, w), infer(scene, settings))


def test_a_cache_too_small_for_every_level_gives_the_same_rules() -> None:
    scene = load_svg(EXAMPLES / "flower-ring.svg")
    analysis = analyse(scene)
    tiny = replace(analysis, levels=LevelCache(budget=1))  # keeps only the last level stored
    for w in WEIGHTS[:3] + WEIGHTS[:1]:
        _same(rules_from_analysis(tiny, w), rules_from_analysis(analysis, w))
    assert len(tiny.levels) == 1 and len(analysis.levels) > 1


def test_weights_met_before_test_no_candidate_again(monkeypatch) -> None:
    scene = load_svg(EXAMPLES / "facade.svg")
    analysis = analyse(scene)
    first = rules_from_analysis(analysis, WEIGHTS[1])
    rules_from_analysis(analysis, WEIGHTS[0])
    calls = {"worthwhile": 0, "ceiling": 0}

    monkeypatch.setattr(rules_mod, "worthwhile", _counted(calls, "worthwhile", rules_mod.worthwhile))
    monkeypatch.setattr(gain_mod.Ledger, "ceiling", _counted(calls, "ceiling", gain_mod.Ledger.ceiling))
    again = rules_from_analysis(analysis, WEIGHTS[1])
    _same(again, first)
    assert calls == {"worthwhile": 0, "ceiling": 0}


def test_the_level_cache_is_bounded_by_bytes_least_recently_used_first() -> None:
    cache = LevelCache(budget=100)
    for k in range(3):
        cache.put(bytes([k]), f"level {k}", 40)
    assert len(cache) == 2 and cache.nbytes == 80  # the first went
    assert cache.get(bytes([0])) is None and cache.get(bytes([1])) == "level 1"
    cache.put(bytes([3]), "level 3", 40)  # 2 is now the least recently used
    assert cache.get(bytes([2])) is None and cache.get(bytes([1])) == "level 1"
    cache.put(bytes([4]), "big", 500)  # larger than the budget: kept alone
    assert len(cache) == 1 and cache.get(bytes([4])) == "big"
