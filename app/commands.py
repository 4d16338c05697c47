"""Undoable edits (QUndoCommand subclasses) of anything that implements :class:`EditTarget`.

Every command stores whole before/after values (rule text, settings), so undo and redo never
recompute anything expensive: undoing a weight change restores the previous rules text instead
of re-running inference.  Commands made during one gesture (a slider or handle drag) merge into
one undo step; consecutive typing in the rules editor merges too.

Commands know the document only through :class:`EditTarget`, two public methods that apply a
value; this module imports nothing of the editor.
"""

from __future__ import annotations

import time
from typing import Any, Protocol

from PySide6.QtGui import QUndoCommand

__all__ = ["EditTarget", "SettingsCommand", "TextCommand"]

_TYPING_MERGE_SECONDS = 1.5

_ID_TEXT = 1
_ID_SETTINGS = 2


class EditTarget(Protocol):
    """What a command edits: the document's rules text and inference settings."""

    def apply_text(
        self, text: str, *, grammar: Any = None, drawing: Any = None, typing: bool = False
    ) -> None:
        """Show ``text`` as the rules (``grammar``/``drawing``: its parse and derivation if known)."""

    def apply_settings(self, settings: Any) -> None:
        """Show ``settings`` as the settings the rules were inferred with (no inference runs)."""


class TextCommand(QUndoCommand):
    """Replace the rules text (typing, a parameter change, or an action on the grammar).

    Parameters
    ----------
    target : EditTarget
        The document edited.
    label : str
        Text of the Undo/Redo menu entries.
    old, new : str
        Rules text before and after.
    merge_key : object, optional
        Consecutive commands with the same non-None key merge into one step (a drag, or
        typing, which merges while keystrokes follow each other closely).
    grammar, drawing : optional
        The parsed grammar and derived drawing of ``new`` if already known (first redo only).
    """

    def __init__(
        self,
        target: EditTarget,
        label: str,
        old: str,
        new: str,
        *,
        merge_key: Any = None,
        grammar: Any = None,
        drawing: Any = None,
    ) -> None:
        super().__init__(label)
        self.target = target
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
        if self.new == self.old:
            self.setObsolete(True)  # the gesture came back to where it started: no step
        return True

    def redo(self) -> None:
        """Apply the new text."""
        self.target.apply_text(
            self.new, grammar=self._grammar, drawing=self._drawing, typing=self.merge_key == "typing"
        )
        self._grammar = self._drawing = None

    def undo(self) -> None:
        """Restore the old text."""
        self.target.apply_text(self.old)


class SettingsCommand(QUndoCommand):
    """A finished re-inference with new settings: the settings and the rules text they produced.

    Pushed when the inference result arrives (never before, so a cancelled run leaves no step);
    its first redo applies the result, later undo/redo only swap settings and texts.  Results
    of one slider drag merge into one step.
    """

    def __init__(
        self,
        target: EditTarget,
        old: Any,
        new: Any,
        old_text: str,
        new_text: str,
        *,
        merge_key: Any = None,
        grammar: Any = None,
        drawing: Any = None,
    ) -> None:
        super().__init__("Change inference settings")
        self.target = target
        self.old = old
        self.new = new
        self.old_text = old_text
        self.new_text = new_text
        self.merge_key = merge_key
        self._grammar = grammar
        self._drawing = drawing

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
        self.new_text = other.new_text
        if self.new == self.old and self.new_text == self.old_text:
            self.setObsolete(True)
        return True

    def redo(self) -> None:
        """Apply the new settings and the rules they produced."""
        self.target.apply_settings(self.new)
        self.target.apply_text(self.new_text, grammar=self._grammar, drawing=self._drawing)
        self._grammar = self._drawing = None

    def undo(self) -> None:
        """Restore the old settings and the rules text they had produced."""
        self.target.apply_settings(self.old)
        self.target.apply_text(self.old_text)
