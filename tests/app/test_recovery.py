"""Crash recovery: autosave while dirty, offer the leftover after a crash, nothing after a clean exit."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from app.recovery import Recovery, discard_orphan, find_orphans

ROOT = Path(__file__).resolve().parents[2]

CRASHING_EDITOR = """
import os, sys
os.environ["QT_QPA_PLATFORM"] = "offscreen"
from PySide6.QtWidgets import QApplication
from pathlib import Path
app = QApplication([])
from app.document import Document
from app.recovery import Recovery
doc = Document()
doc.open_lsys(sys.argv[2])
rec = Recovery(doc, directory=Path(sys.argv[1]), interval_ms=60000)
doc.edit_text(doc.text.replace("P(119)", "P(7)"))
assert rec.save_now()
os._exit(3)  # a crash: no clean exit, the lock is left behind
"""


def test_autosave_writes_only_when_dirty_and_clean_exit_removes(qtbot, tmp_path, helix_lsys):
    from app.document import Document

    doc = Document()
    doc.open_lsys(str(helix_lsys))
    rec = Recovery(doc, directory=tmp_path, interval_ms=50)
    qtbot.wait(120)
    assert not rec.path.exists()  # nothing to recover: unmodified
    doc.edit_text(doc.text.replace("P(119)", "P(9)"))
    qtbot.waitUntil(rec.path.exists, timeout=120_000)
    state = json.loads(rec.path.read_text())["state"]
    assert "P(9)" in state["text"] and state["path"] == str(helix_lsys)
    assert find_orphans(tmp_path) == []  # our own file, locked while we run
    doc.save(str(tmp_path / "saved.lsys"))
    assert not rec.path.exists()  # saved: nothing to recover
    doc.edit_text(doc.text.replace("P(9)", "P(10)"))
    assert rec.save_now()
    rec.close()
    assert not rec.path.exists() and not list(tmp_path.glob("recovery-*"))
    doc.shutdown()


def test_leftover_of_a_crash_is_offered_and_restored(qtbot, tmp_path, helix_lsys):
    from app.document import Document

    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.run(
        [sys.executable, "-c", CRASHING_EDITOR, str(tmp_path), str(helix_lsys)],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 3, proc.stderr
    orphans = find_orphans(tmp_path)
    assert len(orphans) == 1
    path, data = orphans[0]
    doc = Document()
    doc.restore(data["state"])
    qtbot.waitUntil(lambda: doc.drawing is not None, timeout=120_000)
    assert "P(7)" in doc.text and len(doc.drawing) == 8
    assert doc.modified and doc.path == str(helix_lsys)
    discard_orphan(path)
    assert find_orphans(tmp_path) == []
    doc.shutdown()
