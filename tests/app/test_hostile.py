"""Hostile input in the editor: every failure is one readable line and the window stays usable.

Each test drives one main window (offscreen, pytest-qt, exceptions raised in Qt virtual methods and
slots fail the test): it opens a hostile SVG of one class of the robustness issue, or types a
hostile rules text, or saves/exports where that cannot work, then checks what the user sees (the
message bar, the rules panel's error marker, the canvas) and that the same window still opens a
good file and draws.  Bugs are logged with their traceback by the workers: no error may be logged.
"""

from __future__ import annotations

import logging
import re
import time
from pathlib import Path

import pytest
from PySide6.QtCore import QTimer
from PySide6.QtGui import QTextCursor
from PySide6.QtWidgets import QMessageBox

from tests.robustness.generators import hostile_rules, hostile_svgs

from .conftest import CORPUS, HELIX_LSYS

GOOD_SVG = CORPUS / "sequence5.svg"

#: Hostile SVGs that cannot be opened: what the message must say.
SVG_ERRORS = {
    "empty": "is empty",
    "whitespace": "is empty",
    "binary": "holds binary data",
    "png_magic": "holds binary data",
    "truncated": "not an SVG",
    "wrong_encoding": "not an SVG",
    "unknown_encoding": "unknown encoding",
    "html": "root element is <html>",
    "corrupt_gzip": "corrupt gzip data",
    "gzip_bomb": "decompresses to more than 50,000,000 bytes",
    "billion_laughs": "entities are not allowed",
    "quadratic_blowup": "entity references expand to more than 10,000,000 bytes",
    "xxe": "entities are not allowed",
    "parameter_entity": "entities are not allowed|external references",
    "too_many_elements": "more than 200,000 elements",
    "too_large": "too large",
    "use_cycle": "cycle",
    "use_fan_out": "fan-out",
    "only_text_images_defs": "no drawable elements",
    "deep_nesting": "nested more than 500 levels",
}
#: Hostile SVGs that open: the note shown about what was skipped (None: no message).
SVG_OK = {
    "use_missing": "skipped 1 element: <use> of an external file (not read)",
    "single_element": None,
    "two_elements": None,
    "exact_duplicates": None,
    "overlapping_3000": None,
    "non_finite": "skipped 2 elements: non-finite or huge coordinates",
    "huge_coordinates": None,
    "zero_length_paths": "skipped 4 elements: degenerate",
    "malformed_path_data": "skipped 3 elements: malformed path data",  # "nan" is no number in path data
    "zero_viewbox": "ignored the viewBox '0 0 0 0'",
    "nested_zero_viewbox": "ignored the viewBox '0 0 0 0'",
    "degenerate_transforms": "skipped 2 elements: degenerate",
    "overflowing_opacity": None,
    "use_self": "skipped a <use> that refers to itself (a reference cycle): <use id=u>",  # as renderers do
    "invalid_transform": "ignored the unreadable transform 'rotate(foo)' of <g>",  # as renderers do
}
SLOW_SVGS = {"overlapping_3000": 600_000}  # inference time-outs (ms) of the heavy classes

#: Hostile rules the parser rejects: the line of the marker and what the message says.
RULE_SYNTAX_ERRORS = {
    "syntax_error": (3, r"expected '\)'"),
    "undefined_symbol": (3, "undefined symbol 'Q'"),
    "never_terminates": (4, "rule P never terminates"),
    "mutual_recursion": (4, "never terminates"),
    "m_too_big": (3, "out of range"),
    "scale_zero": (3, "scale must be positive"),
    "scale_negative": (4, "scale must be positive"),
    "nan": (3, "non-finite number 'nan'"),
    "overflowing_number": (3, "number out of range '1e999'"),
    "empty": (1, "missing header"),
    "binary": (1, "unexpected character"),
    "bad_terminal_path": (2, "terminal A: invalid path data 'hello world'"),
    "non_finite_terminal_path": (2, "terminal A: path data has non-finite or huge coordinates"),
}
#: Hostile rules that parse but cannot be derived: what the message bar says.
RULE_DERIVE_ERRORS = {
    "m_1e9": "element limit",
    "exponential_branching": "element limit",
    "overflowing_scale": "overflows in rule P",
    "overflowing_distance": "overflows in the axiom",
}
#: Longest time the UI thread may go without processing events while bad rules are handled: a
#: freeze guard far above the ~50 ms measured (a loaded CI machine must not fail it); the stall
#: itself is measured by ``make bench`` (bench_editor.py).
MAX_STALL_S = 5.0


def test_every_hostile_class_has_an_expectation():
    assert set(SVG_ERRORS) | set(SVG_OK) == set(hostile_svgs())
    assert set(RULE_SYNTAX_ERRORS) | set(RULE_DERIVE_ERRORS) == set(hostile_rules())


@pytest.fixture
def no_logged_errors(caplog):
    """Fail the test if anything logged an error (the workers log every bug with its traceback)."""
    caplog.set_level(logging.WARNING)
    yield
    errors = [r.getMessage() for r in caplog.records if r.levelno >= logging.ERROR]
    assert not errors, errors


def _assert_one_line(message: str, pattern: str) -> None:
    assert message, "no message shown"
    assert "\n" not in message and "internal error" not in message and "Traceback" not in message
    assert re.search(pattern, message), message


def _set_rules(window, text: str) -> None:
    """Replace the whole rules text the way a user does: select all and type (or paste) over it."""
    editor = window.rules_panel.editor
    cursor = editor.textCursor()
    cursor.select(QTextCursor.SelectionType.Document)
    editor.setTextCursor(cursor)
    editor.insertPlainText(text)


def _assert_usable(window, qtbot, wait_idle) -> None:
    """Open a good SVG (if the corpus is there) and type good rules: each must draw."""
    window.ask_save_changes = lambda: QMessageBox.StandardButton.Discard  # no modal question
    if GOOD_SVG.is_file():
        window.open_path(str(GOOD_SVG))
        wait_idle(window)
        assert window.doc.scene_path == str(GOOD_SVG)
        assert window.doc.drawing is not None and len(window.doc.drawing) == len(window.doc.scene.elements)
        assert not window.message_bar.text()
    _set_rules(window, HELIX_LSYS)
    qtbot.waitUntil(
        lambda: window.doc.drawing is not None and len(window.doc.drawing) == 120, timeout=120_000
    )
    wait_idle(window)
    frame = window.canvas._frame
    assert frame is not None and frame.drawing is window.doc.drawing and not frame.draft
    assert window.doc.error is None and not window.rules_panel.error_label.isVisible()


class StallMeter:
    """Record the longest gap between ticks of a 10 ms timer on the UI thread."""

    def __init__(self) -> None:
        self.last = time.perf_counter()
        self.longest = 0.0
        self.timer = QTimer()
        self.timer.setInterval(10)
        self.timer.timeout.connect(self._tick)

    def _tick(self) -> None:
        now = time.perf_counter()
        self.longest = max(self.longest, now - self.last)
        self.last = now

    def __enter__(self) -> StallMeter:
        self.last = time.perf_counter()
        self.timer.start()
        return self

    def __exit__(self, *exc) -> None:
        self._tick()
        self.timer.stop()


# ---------------------------------------------------------------------------
# Opening hostile SVG files


@pytest.mark.parametrize("name", sorted(SVG_ERRORS))
def test_unreadable_svg_shows_one_line_and_window_stays_usable(
    name, window, tmp_path, qtbot, wait_idle, no_logged_errors
):
    path = tmp_path / f"{name}.svg"
    path.write_bytes(hostile_svgs()[name]())
    window.open_path(str(path))
    wait_idle(window)
    message = window.message_bar.text()
    _assert_one_line(message, f"^Could not open {re.escape(path.name)}: .*({SVG_ERRORS[name]})")
    assert window.doc.scene is None and window.doc.drawing is None  # nothing half-loaded
    _assert_usable(window, qtbot, wait_idle)


def _svg_ok_params():
    """The SVG_OK names; heavy ones are ``slow`` with a pytest time-out above their inference wait."""
    for name in sorted(SVG_OK):
        wait_ms = SLOW_SVGS.get(name)
        marks = [pytest.mark.slow, pytest.mark.timeout(wait_ms / 1000 + 300)] if wait_ms else []
        yield pytest.param(name, id=name, marks=marks)


@pytest.mark.parametrize("name", list(_svg_ok_params()))
def test_odd_but_readable_svg_is_inferred_and_drawn(
    name, window, tmp_path, qtbot, wait_idle, no_logged_errors
):
    path = tmp_path / f"{name}.svg"
    path.write_bytes(hostile_svgs()[name]())
    window.open_path(str(path))
    wait_idle(window, timeout=SLOW_SVGS.get(name, 120_000))
    doc = window.doc
    assert doc.scene_path == str(path) and doc.result is not None
    assert doc.drawing is not None and len(doc.drawing) == len(doc.scene.elements) > 0  # all reproduced
    frame = window.canvas._frame
    assert frame is not None and frame.drawing is doc.drawing and not frame.draft
    assert frame.image.width() > 0 and frame.pixels[..., :3].min() < 255  # something is drawn
    assert doc.text.startswith("lsys 2") and doc.error is None
    note = SVG_OK[name]
    if note is None:
        assert not window.message_bar.text()
    else:
        _assert_one_line(window.message_bar.text(), re.escape(note))
    _assert_usable(window, qtbot, wait_idle)


# ---------------------------------------------------------------------------
# Typing hostile rules


@pytest.fixture
def helix_window(window, helix_lsys, wait_idle):
    """A window showing the helix rules and their 120-element drawing."""
    window.open_path(str(helix_lsys))
    wait_idle(window)
    assert len(window.doc.drawing) == 120
    return window


@pytest.mark.parametrize("name", sorted(RULE_SYNTAX_ERRORS))
def test_bad_rules_mark_line_and_column_and_keep_the_drawing(
    name, helix_window, qtbot, wait_idle, no_logged_errors
):
    window, doc = helix_window, helix_window.doc
    good = doc.drawing
    line, pattern = RULE_SYNTAX_ERRORS[name]
    with StallMeter() as stall:
        _set_rules(window, hostile_rules()[name])
        qtbot.waitUntil(lambda: doc.error is not None, timeout=120_000)
        wait_idle(window)
    assert stall.longest < MAX_STALL_S
    assert (doc.error.line, re.search(pattern, str(doc.error)) is not None) == (line, True), str(doc.error)
    column = doc.error.column
    assert column >= 1
    label = window.rules_panel.error_label
    assert label.isVisible() and "\n" not in label.text()
    assert label.text().startswith(f"line {line}, column {column}: ")
    assert window.rules_panel.editor._error[:2] == (line, column)  # the underline and gutter marker
    assert not window.params_panel.isEnabled()
    assert doc.drawing is good and window.canvas._frame.drawing is good  # the last valid drawing stays
    _assert_usable(window, qtbot, wait_idle)


@pytest.mark.parametrize("name", sorted(RULE_DERIVE_ERRORS))
def test_underivable_rules_show_a_message_without_freezing(
    name, helix_window, qtbot, wait_idle, no_logged_errors
):
    window, doc = helix_window, helix_window.doc
    good = doc.drawing
    with StallMeter() as stall:
        _set_rules(window, hostile_rules()[name])
        qtbot.waitUntil(lambda: "Derivation failed" in window.message_bar.text(), timeout=120_000)
        wait_idle(window)
    assert stall.longest < MAX_STALL_S  # the UI kept processing events
    _assert_one_line(window.message_bar.text(), f"^Derivation failed: .*{RULE_DERIVE_ERRORS[name]}")
    assert doc.error is None and not window.rules_panel.error_label.isVisible()  # the text itself parses
    assert doc.drawing is good and window.canvas._frame.drawing is good
    _assert_usable(window, qtbot, wait_idle)


# ---------------------------------------------------------------------------
# Saving and exporting where it cannot work

PRECIOUS = b"precious work \x00\xff that must survive\n"


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.parametrize("what", ["save", "export_svg", "export_png"])
def test_failed_save_or_export_shows_a_message_and_changes_no_file(
    what, helix_window, tmp_path, qtbot, wait_idle, no_logged_errors
):
    window, doc = helix_window, helix_window.doc
    _set_rules(window, doc.text.replace("P(119)", "P(30)"))
    qtbot.waitUntil(lambda: doc.drawing is not None and len(doc.drawing) == 31, timeout=120_000)
    wait_idle(window)
    assert doc.modified
    rules_file = Path(doc.path)
    (tmp_path / "out.svg").write_bytes(PRECIOUS)
    folder = tmp_path / "out.lsys"  # a folder named like the file to write
    folder.mkdir()
    (folder / "inside").write_bytes(PRECIOUS)
    before = _files(tmp_path)
    act = {"save": window._save_to, "export_svg": window.export_svg, "export_png": window.export_png}[what]
    for target, reason in (
        (tmp_path / "missing" / "out.lsys", "No such file or directory"),
        (folder, "Is a directory"),
    ):
        window.message_bar.hide()
        assert act(str(target)) is False
        _assert_one_line(window.message_bar.text(), f"^Could not (save|export): .*{reason}")
        assert _files(tmp_path) == before  # byte for byte, and no temporary file left
        assert not (tmp_path / "missing").exists()
    assert doc.path == str(rules_file) and doc.modified  # still unsaved, still the same file
    ok = tmp_path / "ok.out"
    assert act(str(ok)) is True and ok.stat().st_size > 0  # the window still saves and exports
    after = _files(tmp_path)
    assert {k: after[k] for k in before} == before
