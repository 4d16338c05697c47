"""The main window's grammar edits: randomize, replace a symbol, grow or shrink the structure.

:class:`WindowEdits` is mixed into :class:`~app.main_window.MainWindow`; each edit asks the
document for its editable grammar, applies one ``lsys_core`` edit as one undo step, and turns
every failure into a message.
"""

from __future__ import annotations

from typing import Any

from lsys_core.errors import LsysError

from . import core
from .dialogs import RandomizeDialog, ReplaceDialog

__all__ = ["WindowEdits"]


class WindowEdits:
    """Grammar edits of the main window (mixed into :class:`~app.main_window.MainWindow`)."""

    doc: Any

    def randomize_dialog(self) -> None:
        """Show the randomize dialog: Apply and Re-roll preview, OK is one undo step, Cancel none."""
        if self.doc.editable_grammar() is None:
            return
        dialog = RandomizeDialog(self.doc.randomize, self)
        dialog.applied.connect(self.doc.preview_randomize)
        if dialog.exec():
            self.doc.set_randomize(dialog.value())
        else:
            self.doc.preview_randomize(None)

    def replace_dialog(self, target: str | None = None) -> None:
        """Show the replace-symbol dialog (for terminal ``target`` if given) and apply the choice."""
        grammar = self.doc.editable_grammar()
        if grammar is None:
            return
        inst = getattr(self.doc.result, "instancing", None)
        dialog = ReplaceDialog(
            grammar, getattr(inst, "terminals", ()), core.shape_from_svg, self, target=target or None
        )
        if dialog.exec():
            choice = dialog.choice()
            if choice is not None:
                self.replace_symbol(choice)

    def replace_symbol(self, choice) -> None:
        """Apply a :class:`~app.dialogs.ReplaceChoice` to the grammar (undoable)."""
        g = self.doc.editable_grammar()
        if g is None:
            return
        try:
            if choice.kind == "nonterminal":
                new = core.replace_with_terminal(g, choice.target, choice.terminal)
                label = f"Replace {choice.target} by {choice.terminal}"
            else:
                new = core.replace_terminal(g, choice.target, choice.path, choice.style)
                label = f"Replace shape of {choice.target}"
        except LsysError as exc:
            self.show_message(f"Cannot replace: {exc}")
            return
        except ImportError:
            self.show_message("Replacing symbols needs lsys_core.grammar.edit, which is not installed.")
            return
        self.doc.apply_grammar(new, label)

    def change_count(self, step: int) -> None:
        """Grow (``step > 0``) or shrink the structure by changing the axiom's counter m."""
        g = self.doc.editable_grammar()
        if g is None:
            return
        try:
            m = core.axiom_count(g)
            if m is None:
                self.show_message("The axiom has no counter m to change.")
                return
            new_m = max(0, m + step * max(1, round(abs(m) * 0.1)))
            self.doc.apply_grammar(core.set_param(g, "m", new_m), "Grow" if step > 0 else "Shrink")
        except LsysError as exc:
            self.show_message(str(exc))
