"""Fixtures for the editor's tests: offscreen Qt, isolated settings, corpus files, a main window."""

from __future__ import annotations

import os

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import threading
from pathlib import Path

import pytest

CORPUS = Path(os.environ.get("LSYS_CORPUS", Path(__file__).resolve().parents[3] / "shared" / "corpus"))

HELIX_LSYS = """lsys 1
terminal A "M 0 0 Q 5 -8 14 -2 Q 9 2 0 0 Z" style "fill:none;stroke:#1b5e20;stroke-width:1"
axiom: P(119)
P(m): m > 0 -> A f(24) *(0.99) +(11) P(m-1)
P(m): m == 0 -> A
"""


@pytest.fixture(autouse=True, scope="session")
def _isolated_qt_paths(tmp_path_factory):
    """Keep QSettings and QStandardPaths (recovery files) out of the user's home."""
    from PySide6.QtCore import QCoreApplication, QSettings, QStandardPaths

    QStandardPaths.setTestModeEnabled(True)
    QCoreApplication.setOrganizationName("lsys-editor-tests")
    QCoreApplication.setApplicationName("lsys-editor-tests")
    base = tmp_path_factory.mktemp("qsettings")
    QSettings.setDefaultFormat(QSettings.Format.IniFormat)
    QSettings.setPath(QSettings.Format.IniFormat, QSettings.Scope.UserScope, str(base))


@pytest.fixture
def corpus():
    """Return a function giving the path of a corpus SVG, skipping the test if it is absent."""

    def get(name: str) -> Path:
        path = CORPUS / name
        if not path.is_file():
            pytest.skip(f"corpus file {path} not available")
        return path

    return get


@pytest.fixture
def helix_lsys(tmp_path) -> Path:
    """Write the paper's helix grammar (Fig. 3) to an .lsys file."""
    path = tmp_path / "helix.lsys"
    path.write_text(HELIX_LSYS, encoding="utf-8")
    return path


@pytest.fixture(scope="session")
def inference_process():
    """One inference worker process shared by the session's windows (as each window's own would be)."""
    from app.document import INFER_PRELOAD
    from app.jobs import run_inference
    from app.workers import ProcessCompute

    compute = ProcessCompute(run_inference, preload=INFER_PRELOAD)
    yield compute
    compute.close()


@pytest.fixture
def make_window(qtbot, tmp_path, inference_process):
    """Return a factory of main windows with their own settings file and no autosave.

    At teardown every window is closed and no worker thread may be left running.
    """
    from PySide6.QtCore import QSettings

    from app.main_window import MainWindow

    before = set(threading.enumerate())
    windows = []

    def make(**kwargs):
        settings = QSettings(str(tmp_path / "settings.ini"), QSettings.Format.IniFormat)
        kwargs.setdefault("restore_layout", False)
        kwargs.setdefault("autosave", False)
        kwargs.setdefault("infer_compute", inference_process)
        win = MainWindow(settings, **kwargs)  # closed below (qtbot's own closing would ask to save)
        win.resize(1400, 900)
        win.show()
        windows.append(win)
        return win

    yield make
    for win in windows:
        win.doc.undo_stack.setClean()
        win.close()
        win.shutdown()
        win.deleteLater()
    left = [
        t for t in threading.enumerate() if t not in before and t.is_alive() and t.name.startswith("lsys-")
    ]
    assert not left, f"worker threads still running after close: {left}"


@pytest.fixture
def window(make_window):
    """One main window (see :func:`make_window`)."""
    return make_window()


@pytest.fixture
def wait_idle(qtbot):
    """Return ``wait(win)``: wait until inference, derivation and rendering have finished."""

    def wait(win, timeout: int = 120_000) -> None:
        qtbot.waitUntil(win.is_idle, timeout=timeout)

    return wait


@pytest.fixture
def open_rules(window, tmp_path, wait_idle):
    """Return ``open_rules(text)``: write ``text`` to an .lsys file, open it in the window, wait."""

    def open_(text: str, name: str = "rules.lsys"):
        path = tmp_path / name
        path.write_text(text, encoding="utf-8")
        window.open_path(str(path))
        wait_idle(window)
        return window

    return open_


@pytest.fixture
def many_rules():
    """Return ``many_rules(n, shift)``: .lsys text whose start places ``n`` rows, each a rule of its own."""

    def text(rules: int, shift: int = 0) -> str:
        lines = ["lsys 1", 'terminal A "M 0 0 L 4 0 L 4 4 Z" style "fill:#789"']
        lines.append("axiom: " + " ".join(f"[ f({i * 7 + shift}) +(90) P{i}(3) ]" for i in range(rules)))
        for i in range(rules):
            lines.append(f"P{i}(m): m > 0 -> A +({i % 7 + 1}) f({10 + i}) P{i}(m-1)")
            lines.append(f"P{i}(m): m == 0 -> A")
        return "\n".join(lines) + "\n"

    return text
