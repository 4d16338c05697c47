"""Opening SVGs: inference in a worker, weight changes, symmetrize, export, errors."""

from __future__ import annotations

import importlib.util
import json
import threading
import time

import numpy as np
import pytest

from lsys_core.errors import Cancelled

from .conftest import CORPUS


def _compare():
    """Return ``compare`` of the shared comparison tool (skips if it is absent)."""
    path = CORPUS.parent / "tools" / "compare_svg.py"
    if not path.is_file():
        pytest.skip(f"{path} not available")
    spec = importlib.util.spec_from_file_location("compare_svg", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.compare


def _spy_inference(doc):
    """Wrap the document's inference compute to record the thread, settings and fate of each job."""
    jobs = []
    compute = doc.inference.runner._compute

    def spy(request, cancel, progress):
        job = {
            "settings": request.settings,
            "token": cancel,
            "thread": threading.current_thread(),
            "end": None,
        }
        jobs.append(job)
        try:
            out = compute(request, cancel, progress)
        except Cancelled:
            job["end"] = "cancelled"
            raise
        job["end"] = "done"
        return out

    doc.inference.runner._compute = spy
    return jobs


def test_open_svg_infers_in_a_worker_and_fills_panels(window, corpus, wait_idle):
    helix = corpus("helix.svg")
    jobs = _spy_inference(window.doc)
    stages = []
    window.doc.inferenceProgress.connect(lambda s, f: stages.append(s))
    window.open_path(str(helix))
    assert window.doc.inference.busy and window.doc.drawing is None  # returned before inference ended
    wait_idle(window)
    assert jobs[0]["thread"] is not threading.main_thread() and jobs[0]["end"] == "done"
    doc = window.doc
    assert doc.scene is not None and doc.scene_path == str(helix)
    assert "axiom:" in window.rules_panel.text() and window.rules_panel.text() == doc.text
    assert len(window.params_panel.rows) >= 3
    assert any(r.kind == "count" for r in window.params_panel.rows.values())
    assert len(doc.drawing) == json.loads(helix.with_suffix(".json").read_text())["elements"]
    assert window.inference_panel.weights_box.isEnabled() and window.act_symmetrize.isEnabled()
    assert "similarity" in window.inference_panel.bars and stages
    assert "compression" in window._status_labels["compression"].text()
    assert "inference" in window._status_labels["time"].text()
    assert not doc.modified and doc.undo_stack.count() == 0


def test_weight_slider_cancels_running_inference_and_applies_newest(window, corpus, qtbot, wait_idle):
    window.open_path(str(corpus("helix.svg")))
    wait_idle(window)
    doc = window.doc
    first_text = doc.text
    jobs = []
    compute = doc.inference.runner._compute

    def slow(request, cancel, progress):  # long enough for the next slider move to catch it running
        jobs.append((request.settings, cancel))
        for _ in range(200):
            cancel.check()
            time.sleep(0.005)
        return compute(request, cancel, progress)

    doc.inference.runner._compute = slow
    row = window.inference_panel.rows["wh"]
    row.slider.setSliderDown(True)
    row.slider.setValue(row.slider.value() - 100)
    qtbot.waitUntil(lambda: len(jobs) == 1, timeout=120_000)  # the first job is computing
    row.slider.setValue(row.slider.value() - 100)
    row.slider.setSliderDown(False)
    wait_idle(window)
    assert len(jobs) == 2
    assert jobs[0][1].cancelled and not jobs[1][1].cancelled  # the running job was cancelled
    assert doc.settings.wh == pytest.approx(row.spin.value()) == pytest.approx(jobs[1][0].wh)
    assert doc.undo_stack.count() == 1  # the drag is one step
    command = doc.undo_stack.command(0)
    assert command.new_text == doc.text
    doc.undo_stack.undo()
    wait_idle(window)
    assert doc.text == first_text and doc.settings.wh == pytest.approx(1.0)
    assert window.inference_panel.rows["wh"].spin.value() == pytest.approx(1.0)
    assert len(jobs) == 2  # undo restores the old rules without re-running inference


def test_cancel_button_stops_inference_and_keeps_rules(window, corpus, qtbot, wait_idle):
    window.open_path(str(corpus("helix.svg")))
    wait_idle(window)
    doc = window.doc
    text = doc.text
    compute = doc.inference.runner._compute

    def slow(request, cancel, progress):
        for _ in range(400):
            cancel.check()
            time.sleep(0.005)
        return compute(request, cancel, progress)

    doc.inference.runner._compute = slow
    window.inference_panel.reinfer_button.click()
    qtbot.waitUntil(lambda: doc.inference.runner.running, timeout=120_000)
    assert window.inference_panel.cancel_button.isEnabled()
    window.inference_panel.cancel_button.click()
    wait_idle(window)
    assert doc.text == text and not window.inference_panel.cancel_button.isEnabled()


def test_symmetrize_is_one_undoable_step(window, corpus, wait_idle):
    path = corpus("noisy_sequence.svg")  # symmetrize regularises its noisy rules
    window.open_path(str(path))
    wait_idle(window)
    doc = window.doc
    before = doc.text
    window.act_symmetrize.trigger()
    wait_idle(window)
    assert doc.text != before
    assert doc.undo_stack.count() == 1 and doc.undo_stack.undoText() == "Symmetrize"
    assert doc.scene is not None and doc.drawing is not None
    doc.undo_stack.undo()
    wait_idle(window)
    assert doc.text == before


def test_symmetrize_and_reinfer_that_change_nothing_push_no_step_and_say_why(window, corpus, wait_idle):
    window.open_path(str(corpus("helix.svg")))  # exact: inferred as regular as symmetrize makes it
    wait_idle(window)
    doc = window.doc
    before = doc.text
    messages = []
    doc.message.connect(messages.append)
    window.act_symmetrize.trigger()
    wait_idle(window)
    assert doc.text == before and doc.undo_stack.count() == 0
    assert messages and "Symmetrize: nothing changed" in messages[-1]
    window.inference_panel.reinfer_button.click()
    wait_idle(window)
    assert doc.text == before and doc.undo_stack.count() == 0
    assert "Re-infer: nothing changed" in messages[-1]


def test_export_svg_reproduces_input(window, corpus, tmp_path, wait_idle):
    compare = _compare()
    helix = corpus("helix.svg")
    tol = json.loads(helix.with_suffix(".json").read_text())["tol"]
    window.open_path(str(helix))
    wait_idle(window)
    out = tmp_path / "helix-derived.svg"
    assert window.export_svg(str(out))
    report = compare(str(helix), str(out))
    assert report["output_elements"] == report["input_elements"] == len(window.doc.drawing)
    assert report["hausdorff_rel"] <= tol


def test_export_png(window, helix_lsys, tmp_path, wait_idle):
    window.open_path(str(helix_lsys))
    wait_idle(window)
    out = tmp_path / "helix.png"
    assert window.export_png(str(out))
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_bad_files_show_errors_and_the_app_stays_usable(window, tmp_path, helix_lsys, qtbot, wait_idle):
    bad = tmp_path / "broken.svg"
    bad.write_text("<svg><path d='M 0 0 L", encoding="utf-8")
    window.open_path(str(bad))
    wait_idle(window)
    assert "Could not open broken.svg" in window.message_bar.text()
    assert window.doc.scene is None and window.doc.drawing is None

    window.open_path(str(tmp_path / "missing.lsys"))
    assert "no such file" in window.message_bar.text()

    binary = tmp_path / "binary.lsys"
    binary.write_bytes(b"\xff\xfe\x00garbage")
    window.open_path(str(binary))
    assert "not UTF-8" in window.message_bar.text()

    window.open_path(str(helix_lsys))  # still works
    wait_idle(window)
    assert len(window.doc.drawing) == 120 and window.isVisible()


def test_too_many_elements_is_a_message_not_a_crash(window, helix_lsys, qtbot, wait_idle):
    window.open_path(str(helix_lsys))
    wait_idle(window)
    window.doc.edit_text(window.doc.text.replace("P(119)", "P(5000000)"))
    qtbot.waitUntil(lambda: "element limit" in window.message_bar.text(), timeout=120_000)
    wait_idle(window)
    assert len(window.doc.drawing) == 120  # the last drawing stays


def test_open_recovers_from_inference_failure(window, tmp_path, corpus, wait_idle):
    empty = tmp_path / "empty.svg"
    empty.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"/>', encoding="utf-8")
    window.open_path(str(empty))
    wait_idle(window)
    assert "Could not open empty.svg" in window.message_bar.text()
    assert not window.doc.inference.busy and window.doc.scene is None
    window.open_path(str(corpus("helix.svg")))
    wait_idle(window)
    assert window.doc.scene is not None and not window.message_bar.isVisible()


def test_input_overlay_and_colour_by_group(window, corpus, wait_idle):
    window.open_path(str(corpus("helix.svg")))
    wait_idle(window)
    plain = window.canvas._frame.pixels.copy()
    window.act_overlay.trigger()
    wait_idle(window)
    frame = window.canvas._frame
    assert frame.overlay and not np.array_equal(frame.pixels, plain)
    window.act_overlay.trigger()  # off again
    window.act_colors["group"].trigger()
    wait_idle(window)
    pixels = window.canvas._frame.pixels.astype(int)
    blue = pixels[..., 2] > pixels[..., 0] + 40  # the first palette colour, #1f77b4
    green = pixels[..., 1] > pixels[..., 2] + 40  # the input's own colour, #1b5e20
    assert blue.sum() > 50 and green.sum() == 0


def test_restore_reloads_the_input_in_the_background(qtbot, corpus, inference_process):
    from app.document import Document

    helix = corpus("helix.svg")
    doc = Document(infer_compute=inference_process)
    state = {"text": "lsys 1\naxiom: ε\n", "settings": {"wh": 0.5}, "scene_path": str(helix), "path": None}
    doc.restore(state)
    assert doc.loading and doc.scene is None
    qtbot.waitUntil(lambda: doc.scene is not None, timeout=120_000)
    assert doc.scene_path == str(helix) and doc.settings.wh == 0.5 and doc.text == state["text"]
    assert doc.result is None  # no inference ran: the restored rules stay
    doc.shutdown()


def test_after_a_restore_the_first_weight_change_reuses_an_analysis_made_in_the_background(
    qtbot, corpus, inference_process
):
    """The reloaded scene is analysed in the worker without touching the restored rules, so the
    first weight change re-runs only the rules."""
    import dataclasses

    from app.document import Document

    doc = Document(infer_compute=inference_process)
    outcomes = []
    doc.inference.done.connect(lambda purpose, out: outcomes.append((purpose.kind, out)))
    state = {
        "text": "lsys 1\naxiom: ε\n",
        "settings": {},
        "scene_path": str(corpus("helix.svg")),
        "path": None,
    }
    doc.restore(state)
    qtbot.waitUntil(lambda: doc.scene is not None and not doc.busy, timeout=120_000)
    assert [kind for kind, _ in outcomes] == ["reload", "prepare"]
    assert doc.text == state["text"] and doc.result is None and doc.undo_stack.count() == 1
    doc.set_settings(dataclasses.replace(doc.settings, wh=0.5))
    qtbot.waitUntil(lambda: not doc.busy and len(outcomes) == 3, timeout=120_000)
    assert outcomes[-1][0] == "settings" and outcomes[-1][1].reused_analysis
    assert doc.text != state["text"] and doc.undo_stack.count() == 2
    doc.shutdown()


def test_a_typed_weight_starts_at_once_and_a_slider_drag_after_a_pause(window, corpus, wait_idle):
    """A value typed into a spin box is one edit: inference starts without the debounce; the
    steps of a slider drag wait for a pause (each would cancel the one before)."""
    window.open_path(str(corpus("helix.svg")))
    wait_idle(window)
    doc, row = window.doc, window.inference_panel.rows["wh"]
    row.spin.setValue(0.5)
    assert doc.inference.runner.running  # started in the same turn
    wait_idle(window)
    row.slider.setSliderDown(True)
    row.slider.setValue(row.slider.value() + 100)
    assert doc.interactive and doc.inference.runner.busy and not doc.inference.runner.running
    row.slider.setSliderDown(False)
    wait_idle(window)
    assert doc.undo_stack.count() == 2
