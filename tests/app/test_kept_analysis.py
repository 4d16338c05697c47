"""The inference worker keeps a scene's analysis: a weight change re-runs only rule generation."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

import lsys_core.pipeline as pipeline
from app import jobs
from lsys_core.cancel import CancelToken
from lsys_core.grammar import format_grammar
from lsys_core.svg.parse import load_svg

EXAMPLES = Path(__file__).resolve().parents[2] / "resources" / "examples"


@pytest.fixture
def counted(monkeypatch):
    """Count the similarity analyses run (the expensive first stage of ``analyse``)."""
    calls = []
    real = pipeline._instancing

    def spy(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(pipeline, "_instancing", spy)
    monkeypatch.setattr(jobs, "_KEPT", [])
    return calls


def _infer(scene, settings):
    request = jobs.InferRequest(scene, settings)
    return jobs.run_inference(request, CancelToken(), lambda stage, fraction: None)


def test_a_weight_change_reuses_the_analysis_and_gives_what_a_full_inference_gives(counted):
    path = EXAMPLES / "flower-ring.svg"
    settings = pipeline.InferenceSettings()
    first = _infer(load_svg(str(path)), settings)
    reweighted = replace(settings, wh=0.25, wl=0.5)
    again = _infer(load_svg(str(path)), reweighted)  # a new but equal scene object, as a worker gets
    assert len(counted) == 1  # the analysis of the first run was kept
    full = pipeline.infer(load_svg(str(path)), reweighted)
    assert again.text == format_grammar(full.grammar)
    assert first.text == format_grammar(pipeline.infer(load_svg(str(path)), settings).grammar)


def test_a_new_scene_or_similarity_threshold_analyses_again(counted):
    settings = pipeline.InferenceSettings()
    _infer(load_svg(str(EXAMPLES / "flower-ring.svg")), settings)
    _infer(load_svg(str(EXAMPLES / "facade.svg")), settings)
    assert len(counted) == 2
    stricter = replace(settings, similarity=min(0.99, settings.similarity + 0.05))
    _infer(load_svg(str(EXAMPLES / "facade.svg")), stricter)
    assert len(counted) == 3
    assert jobs.scene_digest(load_svg(str(EXAMPLES / "facade.svg"))) == jobs._KEPT[0][0]


def test_a_request_that_names_its_scene_is_not_digested_again(counted, monkeypatch):
    scene = load_svg(str(EXAMPLES / "flower-ring.svg"))
    key = jobs.scene_digest(scene)
    digests = []
    real = jobs.scene_digest
    monkeypatch.setattr(jobs, "scene_digest", lambda s: digests.append(1) or real(s))
    settings = pipeline.InferenceSettings()
    for wh in (1.0, 0.5):
        request = jobs.InferRequest(scene, replace(settings, wh=wh), scene_key=key)
        jobs.run_inference(request, CancelToken(), lambda stage, fraction: None)
    assert digests == [] and len(counted) == 1 and jobs._KEPT[0][0] == key


def test_the_document_digests_its_scene_once(window, wait_idle):
    window.open_path(str(EXAMPLES / "flower-ring.svg"))
    wait_idle(window)
    doc = window.doc
    key = doc.scene_key()
    assert key == jobs.scene_digest(doc.scene) and doc.scene_key() is key
