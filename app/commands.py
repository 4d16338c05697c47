"""Undoable edits of a :class:`~app.document.Document` (QUndoCommand subclasses).

Every command stores whole before/after values (rule text, settings, randomization), so undo
and redo never recompute anything expensive: undoing a weight change restores the previous
rules text instead of re-running inference.  Commands made during one gesture (a slider drag)
merge into one undo step; consecutive typing in the rules editor merges too.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from PySide6.QtGui import QUndoCommand

if TYPE_CHECKING:
    from .document import Document

__all__ = ["RandomizeCommand", "SettingsCommand", "TextCommand"]

_TYPING_MERGE_SECONDS = 1.5

_ID_TEXT = 1
_ID_SETTINGS = 2
_ID_RANDOMIZE = 3


class TextCommand(QUndoCommand):
    """Replace the rules text (typing, a parameter change, or an action on the grammar).

    Parameters
    ----------
    doc : Document
        The document edited.
    label : str
        Text of the Undo/Redo menu entries.
    old, new : str
        Rules text before and after.
    merge_key : object, optional
        Consecutive commands with the same non-None key merge into one step (a slider drag,
        or typing, which merges while keystrokes follow each other closely).
    grammar, drawing : optional
        The parsed grammar and derived drawing of ``new`` if already known (first redo only).
    """

    def __init__(
        self,
        doc: Document,
        label: str,
        old: str,
        new: str,
        *,
        merge_key: Any = None,
        grammar: Any = None,
        drawing: Any = None,
    ) -> None:
        super().__init__(label)
        self.doc = doc
        self.old = old
        self.new = new
        self.merge_key = merge_key
        self._grammar = grammar
        self._drawing = drawing
        self._stamp = time.monotonic()

    def id(self) -> int:
        """Return the merge id shared by all text commands."""
        return _ID_TEXT

    def mergeWith(self, other: QUndoCommand) -> bool:
        """Absorb ``other`` if it continues the same gesture or typing burst."""
        if not isinstance(other, TextCommand) or other.merge_key is None or other.merge_key != self.merge_key:
            return False
        if self.merge_key == "typing" and other._stamp - self._stamp > _TYPING_MERGE_SECONDS:
            return False
        self.new = other.new
        self._stamp = other._stamp
        return True

    def redo(self) -> None:
        """Apply the new text."""
        self.doc._apply_text(
            self.new, grammar=self._grammar, drawing=self._drawing, typing=self.merge_key == "typing"
        )
        self._grammar = self._drawing = None

    def undo(self) -> None:
        """Restore the old text."""
        self.doc._apply_text(self.old)


class SettingsCommand(QUndoCommand):
    """Change the inference settings; the rules text follows when inference finishes.

    The first redo runs inference; its result is recorded in :attr:`new_text`, so later
    undo/redo only swap texts.  Commands of one slider drag merge.
    """

    def __init__(self, doc: Document, old: Any, new: Any, old_text: str, *, merge_key: Any = None) -> None:
        super().__init__("Change inference settings")
        self.doc = doc
        self.old = old
        self.new = new
        self.old_text = old_text
        self.new_text: str | None = None
        self.merge_key = merge_key

    def id(self) -> int:
        """Return the merge id shared by all settings commands."""
        return _ID_SETTINGS

    def mergeWith(self, other: QUndoCommand) -> bool:
        """Absorb ``other`` if it belongs to the same slider drag."""
        if (
            not isinstance(other, SettingsCommand)
            or other.merge_key is None
            or other.merge_key != self.merge_key
        ):
            return False
        self.new = other.new
        self.new_text = None
        self.doc._retarget_inference(other, self)
        return True

    def redo(self) -> None:
        """Apply the new settings; infer unless the resulting text is known."""
        self.doc._apply_settings(self.new, self.new_text, command=self)

    def undo(self) -> None:
        """Restore the old settings and the rules text they had produced."""
        self.doc._apply_settings(self.old, self.old_text, command=None)


class RandomizeCommand(QUndoCommand):
    """Set or clear the random perturbation of the derivation."""

    def __init__(self, doc: Document, old: Any, new: Any) -> None:
        super().__init__("Randomize" if new is not None else "Clear randomization")
        self.doc = doc
        self.old = old
        self.new = new

    def id(self) -> int:
        """Return the id of randomize commands (they do not merge)."""
        return _ID_RANDOMIZE

    def redo(self) -> None:
        """Apply the new randomization."""
        self.doc._apply_randomize(self.new)

    def undo(self) -> None:
        """Restore the previous randomization."""
        self.doc._apply_randomize(self.old)
