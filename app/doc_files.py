"""The file side of the document: open, save, crash recovery.

:class:`DocumentFiles` is a part of :class:`~app.document.Document` (a mixin): it reads and
writes files and starts the background load of an SVG, using the document's public state
(``rules``, ``inference``, ``undo_stack``, ``settings``) and its command interface.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

from lsys_core.errors import LsysError

from . import core
from .commands import TextCommand
from .inference_control import Purpose
from .jobs import InferRequest

__all__ = ["DocumentFiles"]


class DocumentFiles:
    """Opening, saving and recovering the document (mixed into :class:`~app.document.Document`)."""

    rules: Any
    inference: Any
    undo_stack: Any
    settings: Any
    text: str
    scene: Any
    scene_path: str | None
    path: str | None
    result: Any

    def open_svg(self, path: str) -> None:
        """Load an SVG and infer its grammar in the background (replaces the document when done)."""
        request = InferRequest(None, self.settings, svg_path=str(path))
        self.inference.submit(Purpose("open", path=str(path)), request)

    def open_lsys(self, path: str) -> None:
        """Open an .lsys rules file; the input scene is cleared.

        Raises
        ------
        LsysError
            If the file cannot be read (a parse error only marks the text).
        """
        text = core.read_text(path)
        self.inference.cancel()
        self.replace_document(None, None, str(path), text)
        self.pathChanged.emit()

    def save(self, path: str | None = None) -> None:
        """Write the rules text to ``path`` (default: the current path) atomically."""
        target = str(path or self.path or "")
        if not target:
            raise LsysError("no file name to save to")
        core.write_atomic(target, self.text.encode("utf-8"))
        self.path = target
        self.undo_stack.setClean()
        self.pathChanged.emit()

    def restore(self, state: dict[str, Any]) -> None:
        """Restore a recovered session (rules text, settings, file names)."""
        self.inference.cancel()
        self.undo_stack.clear()
        self.apply_settings(core.settings_from_dict(state.get("settings") or {}))
        self.path = state.get("path")
        scene_path = state.get("scene_path")
        self.scene, self.scene_path, self.result = None, None, None
        self.sceneChanged.emit()
        self.undo_stack.push(TextCommand(self, "Restore unsaved work", self.text, state.get("text", "")))
        self.pathChanged.emit()
        if scene_path and Path(scene_path).is_file():  # load the input in the background, no inference
            request = InferRequest(None, self.settings, svg_path=scene_path, load_only=True)
            self.inference.submit(Purpose("reload", path=scene_path), request)

    def snapshot(self) -> dict[str, Any]:
        """Return the state autosave writes (see :meth:`restore`)."""
        return {
            "text": self.text,
            "settings": dataclasses.asdict(self.settings),
            "path": self.path,
            "scene_path": self.scene_path,
        }

    def replace_document(
        self, scene: Any, scene_path: str | None, path: str | None, text: str, **known: Any
    ) -> None:
        """Make a new document of ``text`` (``known``: its grammar and drawing); no undo history."""
        self.scene, self.scene_path, self.path = scene, scene_path, path
        self._restore_settings()
        self.rules.clear()
        self.undo_stack.clear()
        self.sceneChanged.emit()
        self.rules.apply_text(text, **known)
        self.undo_stack.setClean()
