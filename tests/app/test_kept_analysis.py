"""The inference worker keeps a scene's analysis: a weight change re-runs only rule generation."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

import lsys_core.pipeline as pipeline
import lsys_core.pipeline.analysis as analysis
from app import jobs
from lsys_core.cancel import CancelToken
from lsys_core.grammar import format_grammar
from lsys_core.svg.parse import load_svg

EXAMPLES = Path(__file__).resolve().parents[2] / "resources" / "examples"


@pytest.fixture
def counted(monkeypatch):
    """Count the similarity analyses run (the expensive first stage of ``analyse``)."""
    calls = []
    real = analysis._instancing

    def spy(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(analysis, "_instancing", spy)
    monkeypatch.setattr(jobs, "_KEPT", [])
    return calls


def _infer(scene, settings, key=None):
    request = jobs.InferRequest(scene, settings, scene_key=key)
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


def test_a_scene_sent_back_through_a_pipe_finds_the_analysis_kept_of_it(counted):
    """The worker returns a loaded scene through a pipe (its arrays come back writeable, the
    reader's are read-only): the requester's key for it is the one the analysis is kept under."""
    import pickle
    from multiprocessing.reduction import ForkingPickler

    settings = pipeline.InferenceSettings()
    request = jobs.InferRequest(None, settings, svg_path=str(EXAMPLES / "flower-ring.svg"))
    opened = jobs.run_inference(request, CancelToken(), lambda stage, fraction: None)
    assert not opened.reused_analysis and opened.scene_key == jobs._KEPT[0][0]
    received = pickle.loads(ForkingPickler.dumps(opened))  # as the editor gets it
    assert received.scene.elements[0].cubics.flags.writeable  # not as the reader made it
    assert jobs.scene_digest(received.scene) == opened.scene_key
    again = _infer(received.scene, replace(settings, wh=0.5))  # its key digested here
    assert again.reused_analysis and len(counted) == 1
    loaded = jobs.run_inference(
        replace(request, load_only=True), CancelToken(), lambda stage, fraction: None
    )  # a session restored: only loaded, the key comes with it
    assert pickle.loads(ForkingPickler.dumps(loaded)).scene_key == opened.scene_key


def test_the_first_weight_change_after_opening_reuses_the_worker_analysis(window, wait_idle, monkeypatch):
    """Opened in the worker process, re-weighted: the scene is not digested on the UI thread and
    the worker finds the analysis it made when the file was opened."""
    import app.document as document

    digests = []
    monkeypatch.setattr(document, "scene_digest", lambda scene: digests.append(1) or jobs.scene_digest(scene))
    outcomes = []
    window.doc.inference.done.connect(lambda purpose, out: outcomes.append((purpose.kind, out)))
    window.open_path(str(EXAMPLES / "flower-ring.svg"))
    wait_idle(window)
    assert window.doc.scene_key() == outcomes[-1][1].scene_key
    spin = window.inference_panel.rows["wh"].spin
    spin.setValue(0.5 if spin.value() != 0.5 else 0.75)
    wait_idle(window)
    kinds = [kind for kind, _out in outcomes]
    assert kinds == ["open", "settings"]
    assert outcomes[-1][1].reused_analysis and digests == []


def test_the_worker_keeps_the_tighter_tolerance_as_infer_does(counted):
    """Where merged shapes cost a repetition, the editor's rules are the command's: both end
    with the tighter try (a corner mark's two kinds told apart)."""
    from tests.core.scenes import scene
    from tests.core.test_tighter_tolerance import _dashed_hexagon

    sc = scene(_dashed_hexagon(1.06))
    settings = pipeline.InferenceSettings()
    full = pipeline.infer(sc, settings)
    user = pipeline.analyse(sc, settings).precision.eps
    assert full.tolerance == pytest.approx(pipeline.TIGHTER * user)  # the tighter one was kept
    first = _infer(sc, settings)
    assert first.text == format_grammar(full.grammar)
    reweighted = replace(settings, wh=0.25)
    again = _infer(sc, reweighted)
    assert again.text == format_grammar(pipeline.infer(sc, reweighted).grammar)
