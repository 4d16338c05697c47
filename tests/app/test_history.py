"""Consistent state and history: cancelled runs, one undo step per action, randomize in the file."""

from __future__ import annotations

import time

import numpy as np
import pytest
from PySide6.QtWidgets import QDialog

from lsys_core.grammar.model import Randomize


def _slow_inference(doc, steps: int = 400):
    """Make inference jobs wait (cancellably) before computing; return the list of their tokens."""
    compute = doc.inference.runner._compute
    tokens = []

    def slow(request, cancel, progress):
        tokens.append(cancel)
        for _ in range(steps):
            cancel.check()
            time.sleep(0.005)
        return compute(request, cancel, progress)

    doc.inference.runner._compute = slow
    return tokens


def test_cancelled_weight_change_restores_the_slider_and_leaves_no_step(window, corpus, qtbot, wait_idle):
    window.open_path(str(corpus("helix.svg")))
    wait_idle(window)
    doc = window.doc
    text, settings = doc.text, doc.settings
    tokens = _slow_inference(doc)
    row = window.inference_panel.rows["wh"]
    row.spin.setValue(0.25)  # typed: one change
    assert doc.pending_settings is not None and doc.pending_settings.wh == pytest.approx(0.25)
    qtbot.waitUntil(lambda: len(tokens) == 1, timeout=120_000)
    window.inference_panel.cancel_button.click()
    wait_idle(window)
    assert tokens[0].cancelled
    assert doc.text == text and doc.settings == settings and doc.pending_settings is None
    assert row.spin.value() == pytest.approx(settings.wh)  # the panel shows the rules' settings again
    assert doc.undo_stack.count() == 0 and not doc.modified


def test_editing_the_rules_during_a_weight_change_drops_it_and_restores_the_slider(
    window, corpus, qtbot, wait_idle
):
    window.open_path(str(corpus("helix.svg")))
    wait_idle(window)
    doc = window.doc
    settings = doc.settings
    tokens = _slow_inference(doc)
    window.inference_panel.rows["wl"].spin.setValue(0.9)
    qtbot.waitUntil(lambda: len(tokens) == 1, timeout=120_000)
    key = next(p.key for p in window.params_panel.rows.values() if p.kind == "count")
    window.params_panel.rows[key].spin.setValue(10)
    wait_idle(window)
    assert tokens[0].cancelled and doc.settings == settings
    assert window.inference_panel.rows["wl"].spin.value() == pytest.approx(settings.wl)
    assert doc.undo_stack.count() == 1 and doc.undo_stack.undoText().startswith("Change")


def test_weight_change_is_one_step_with_the_rules_it_produced(window, corpus, wait_idle):
    window.open_path(str(corpus("helix.svg")))
    wait_idle(window)
    doc = window.doc
    before_text, before = doc.text, doc.settings
    window.inference_panel.rows["similarity"].spin.setValue(0.9)
    wait_idle(window)
    assert doc.settings.similarity == pytest.approx(0.9) and doc.pending_settings is None
    assert doc.undo_stack.count() == 1
    doc.undo_stack.undo()
    wait_idle(window)
    assert doc.settings == before and doc.text == before_text
    assert window.inference_panel.rows["similarity"].spin.value() == pytest.approx(before.similarity)


def test_reinfer_after_an_edit_is_one_step(window, corpus, wait_idle):
    window.open_path(str(corpus("helix.svg")))
    wait_idle(window)
    doc = window.doc
    inferred = doc.text
    key = next(p.key for p in window.params_panel.rows.values() if p.kind == "count")
    window.params_panel.rows[key].spin.setValue(10)
    wait_idle(window)
    edited = doc.text
    assert edited != inferred and doc.undo_stack.count() == 1
    window.inference_panel.reinfer_button.click()
    wait_idle(window)
    assert doc.text == inferred
    assert doc.undo_stack.count() == 2 and doc.undo_stack.undoText() == "Re-infer"
    doc.undo_stack.undo()
    assert doc.text == edited


def test_randomize_is_one_step_saved_in_the_file_and_read_back(window, helix_lsys, tmp_path, wait_idle):
    window.open_path(str(helix_lsys))
    wait_idle(window)
    doc = window.doc
    plain = doc.drawing
    r = Randomize(angle=4.0, distance=0.05, scale=0.0, seed=1234, jitter="instance")
    doc.set_randomize(r)
    wait_idle(window)
    assert doc.undo_stack.count() == 1 and doc.undo_stack.undoText() == "Randomize"
    assert "randomize angle 4 distance 0.05 seed 1234 jitter instance" in window.rules_panel.text()
    assert not np.allclose(doc.drawing.b, plain.b)
    shown = doc.drawing
    messages = []
    doc.message.connect(messages.append)
    doc.set_randomize(r)  # the same again: no step, and a message saying so
    assert doc.undo_stack.count() == 1 and "nothing changed" in messages[-1]
    out = tmp_path / "randomized.lsys"
    window._save_to(str(out))
    window.open_path(str(out))
    wait_idle(window)
    assert doc.randomize == r
    np.testing.assert_allclose(doc.drawing.b, shown.b)  # the same seed draws the same
    doc.set_randomize(None)
    wait_idle(window)
    assert doc.randomize is None and "randomize" not in doc.text
    np.testing.assert_allclose(doc.drawing.b, plain.b)


def test_randomize_dialog_previews_and_ok_is_one_step_cancel_none(window, helix_lsys, monkeypatch, wait_idle):
    from app import dialogs

    window.open_path(str(helix_lsys))
    wait_idle(window)
    doc = window.doc
    plain = doc.drawing
    previews = []

    def run(dialog, accept: bool) -> int:
        dialog.angle.setValue(6.0)
        dialog.reroll()  # previews a new seed at once
        dialog.reroll()
        previews.append(doc.rules.preview_randomize)
        return QDialog.DialogCode.Accepted if accept else QDialog.DialogCode.Rejected

    monkeypatch.setattr(dialogs.RandomizeDialog, "exec", lambda self: run(self, False))
    window.randomize_dialog()
    wait_idle(window)
    assert previews[-1] is not None and previews[-1].angle == pytest.approx(6.0)
    assert doc.undo_stack.count() == 0 and doc.randomize is None and doc.rules.preview_randomize is None
    np.testing.assert_allclose(doc.drawing.b, plain.b)
    monkeypatch.setattr(dialogs.RandomizeDialog, "exec", lambda self: run(self, True))
    window.randomize_dialog()
    wait_idle(window)
    assert doc.undo_stack.count() == 1 and doc.randomize == previews[-1]
    assert f"seed {previews[-1].seed}" in doc.text


def test_instance_jitter_does_not_drift_along_a_sequence(window, helix_lsys, wait_idle):
    window.open_path(str(helix_lsys))
    wait_idle(window)
    doc = window.doc
    plain = doc.drawing.b.copy()
    drift = {}
    for jitter in ("cumulative", "instance"):
        doc.set_randomize(Randomize(angle=3.0, seed=5, jitter=jitter))
        wait_idle(window)
        drift[jitter] = np.abs(doc.drawing.b - plain)
    gap = np.abs(np.diff(plain)).min()
    assert drift["instance"].max() < 1e-9 * gap  # angle-only jitter turns each instance in place
    assert drift["cumulative"][-10:].mean() > gap  # a turned heading carries on along the row


def test_opening_a_file_can_be_cancelled_and_keeps_the_open_document(window, corpus, qtbot, wait_idle):
    """A huge file takes long to read and analyse: Cancel stops it, the open document stays."""
    window.open_path(str(corpus("helix.svg")))
    wait_idle(window)
    doc = window.doc
    text, scene, path = doc.text, doc.scene, doc.scene_path
    tokens = _slow_inference(doc)
    window.open_path(str(corpus("flowers.svg")))
    qtbot.waitUntil(lambda: len(tokens) == 1, timeout=120_000)
    assert doc.busy
    window.inference_panel.cancel_button.click()
    wait_idle(window)
    assert tokens[0].cancelled
    assert doc.text == text and doc.scene is scene and doc.scene_path == path
    assert not doc.busy and window.is_idle()
    window.open_path(str(corpus("flowers.svg")))  # the window is still usable: the next open works
    wait_idle(window)
    assert doc.scene_path is not None and doc.scene_path.endswith("flowers.svg")
