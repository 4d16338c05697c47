"""The main window: canvas, docks, menus, files, status bar and the wiring between them.

Widgets show the :class:`~app.document.Document` and forward edits to it; every action here is
a call on the document or into ``lsys_core``.  Errors reach the user as a message bar above the
canvas (and in the status bar), never as a crash or a modal box that stops the event loop.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from PySide6.QtCore import QSettings, Qt, QTimer
from PySide6.QtGui import QCloseEvent
from PySide6.QtWidgets import (
    QDockWidget,
    QLabel,
    QMainWindow,
    QVBoxLayout,
    QWidget,
)

from lsys_core.errors import LsysError

from . import core
from .actions import create_actions, create_menus, redo_keys, undo_keys
from .canvas import Canvas
from .coloring import legend
from .document import Document
from .handles import HandleEditor, HandleOverlay
from .inference_panel import InferencePanel
from .message_bar import MessageBar
from .pacing import GesturePacing
from .params_panel import ParamsPanel
from .recent_files import RecentFiles
from .recovery import Recovery
from .rules_panel import RulesPanel
from .rules_view import RulesView
from .structure_panel import StructurePanel
from .window_edits import WindowEdits
from .window_files import WindowFiles

__all__ = ["MainWindow"]

#: Rule descriptions made per event-loop turn while new rules are shown (120 took 14–23 ms; 40
#: took 6–10 ms, the longest steps after the text and the structure panel).
CARDS_PER_TURN = 20


class MainWindow(WindowFiles, WindowEdits, QMainWindow):
    """The editor window.

    Parameters
    ----------
    settings : QSettings, optional
        Where layout and recent files are kept (default: the application's settings).
    restore_layout : bool
        Restore the saved window geometry and dock layout, and save them on close.
    autosave : bool
        Autosave the document for crash recovery.
    infer_compute : callable, optional
        How inference jobs run (see :class:`~app.document.Document`; default: own process).
    """

    def __init__(
        self,
        settings: QSettings | None = None,
        *,
        restore_layout: bool = True,
        autosave: bool = True,
        infer_compute: Any = None,
    ):
        super().__init__()
        self.settings = settings or QSettings()
        self.recent = RecentFiles(self.settings, self)
        self.recent.openRequested.connect(self.open_path)
        self.doc = Document(self, infer_compute=infer_compute)
        QTimer.singleShot(0, self.doc.warm_up)
        self.setAcceptDrops(True)
        self.resize(1400, 900)

        self.canvas = Canvas(self)
        self.canvas.overlay = self.handles = HandleOverlay(self.canvas)
        self.message_bar = MessageBar(self.canvas)  # over the canvas: a message does not resize it
        central = QWidget(self)
        lay = QVBoxLayout(central)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(0)
        lay.addWidget(self.canvas, 1)
        self.setCentralWidget(central)

        self.rules_panel = RulesPanel(self)
        self.params_panel = ParamsPanel(self)
        self.rules_view = RulesView(self)
        self.inference_panel = InferencePanel(self)
        self.structure_panel = StructurePanel(self)
        self.rules_dock = self._dock(
            "Rules", "rules", self.rules_panel, Qt.DockWidgetArea.RightDockWidgetArea
        )
        self.params_dock = self._dock(
            "Parameters", "params", self.params_panel, Qt.DockWidgetArea.RightDockWidgetArea
        )
        self.cards_dock = self._dock(
            "Rule Cards", "cards", self.rules_view, Qt.DockWidgetArea.RightDockWidgetArea
        )
        self.tabifyDockWidget(self.params_dock, self.cards_dock)
        self.cards_dock.raise_()
        self.inference_dock = self._dock(
            "Inference", "inference", self.inference_panel, Qt.DockWidgetArea.LeftDockWidgetArea
        )
        self.structure_dock = self._dock(
            "Structure", "structure", self.structure_panel, Qt.DockWidgetArea.LeftDockWidgetArea
        )
        self.resizeDocks([self.rules_dock, self.params_dock], [460, 380], Qt.Orientation.Vertical)
        self.resizeDocks([self.rules_dock, self.inference_dock], [520, 320], Qt.Orientation.Horizontal)
        self.tabifyDockWidget(self.inference_dock, self.structure_dock)
        self.inference_dock.raise_()

        self._status_labels = {
            k: QLabel(self) for k in ("elements", "symbols", "rules", "compression", "time")
        }
        for label in self._status_labels.values():
            self.statusBar().addPermanentWidget(label)

        self._panels_timer = QTimer(self)
        self._panels_timer.setSingleShot(True)
        self._panels_timer.setInterval(0)
        self._panels_timer.timeout.connect(self._update_panels)
        self._panel_steps: tuple[Any, Iterator[None]] | None = None
        create_actions(self)
        create_menus(
            self,
            (self.rules_dock, self.cards_dock, self.params_dock, self.inference_dock, self.structure_dock),
        )
        self._connect()
        self.inference_panel.set_settings(self.doc.settings)
        self._update_actions()
        self._update_status()
        self._update_title()

        self.recovery = Recovery(self.doc, parent=self) if autosave else None
        self._keep_layout = restore_layout
        if restore_layout:
            geometry = self.settings.value("window/geometry")
            state = self.settings.value("window/state")
            if geometry is not None:
                self.restoreGeometry(geometry)
            if state is not None:
                self.restoreState(state)

    # -- construction ---------------------------------------------------------------------------------
    def _dock(self, title: str, name: str, widget: QWidget, area: Qt.DockWidgetArea) -> QDockWidget:
        dock = QDockWidget(title, self)
        dock.setObjectName(f"dock-{name}")
        dock.setWidget(widget)
        self.addDockWidget(area, dock)
        return dock

    def _connect(self) -> None:
        d = self.doc
        editor = self.rules_panel.editor
        self.pacing = GesturePacing(d, self.rules_panel.set_text, self._panels_timer.start, self, editor)
        d.textChanged.connect(self.pacing.text_changed)
        d.grammarError.connect(self.rules_panel.set_error)
        d.grammarError.connect(self._on_grammar_error)
        d.grammarChanged.connect(self._on_grammar_changed)
        d.drawingChanged.connect(self.canvas.set_drawing)
        d.drawingChanged.connect(self._update_status)
        d.settingsChanged.connect(self.inference_panel.set_settings)
        d.sceneChanged.connect(self._on_scene_changed)
        d.inferenceStarted.connect(lambda: self.inference_panel.set_running(True))
        d.inferenceStarted.connect(self._update_actions)
        d.inferenceProgress.connect(self.inference_panel.set_progress)
        d.inferenceFinished.connect(self._on_inference_finished)
        d.message.connect(self.show_message)
        d.pathChanged.connect(self._update_title)
        d.pathChanged.connect(self._update_actions)
        d.undo_stack.cleanChanged.connect(self._update_title)
        d.gestureFinished.connect(self.canvas.request_full_quality)
        self.canvas.elementClicked.connect(self._on_element_clicked)
        self.canvas.message.connect(self.show_message)
        self.rules_panel.textEdited.connect(d.edit_text)
        self.rules_panel.editor.set_history_keys(undo_keys(), redo_keys())
        self.rules_panel.editor.undoRequested.connect(d.undo_stack.undo)
        self.rules_panel.editor.redoRequested.connect(d.undo_stack.redo)
        self.params_panel.paramEdited.connect(d.set_param)
        self.rules_view.controlEdited.connect(self._on_control_edited)
        self.rules_view.dragStarted.connect(d.begin_gesture)
        self.rules_view.dragFinished.connect(d.end_gesture)
        self.rules_view.ruleSelected.connect(self.select_rule)
        self.handle_editor = HandleEditor(d, self.handles, self.rules_view.control)
        self.structure_panel.ruleSelected.connect(self.select_rule)
        self.structure_panel.terminalSelected.connect(self.highlight_terminal)
        self.structure_panel.replaceRequested.connect(self.replace_dialog)
        self.structure_panel.styleEdited.connect(self.restyle_terminal)
        d.drawingChanged.connect(self.structure_panel.set_drawing)
        self.params_panel.dragStarted.connect(d.begin_gesture)
        self.params_panel.dragFinished.connect(d.end_gesture)
        self.inference_panel.settingsEdited.connect(d.set_settings)
        self.inference_panel.dragStarted.connect(d.begin_gesture)
        self.inference_panel.dragFinished.connect(d.end_gesture)
        self.inference_panel.cancelRequested.connect(d.cancel_inference)
        self.inference_panel.reinferRequested.connect(d.reinfer)
        self.canvas.set_interactive_source(lambda: d.interactive)

    def set_color_mode(self, mode: str) -> None:
        """Colour the canvas by ``"group"``, ``"rule"`` or not at all (``"none"``)."""
        self.canvas.set_color_mode(mode)
        self.act_colors[mode].setChecked(True)
        self.structure_panel.set_legend(legend(self.doc.grammar, mode))

    def restyle_terminal(self, name: str, changes: dict) -> None:
        """Set fill, stroke or opacity of terminal ``name``: one undo step."""
        grammar = self.doc.editable_grammar()
        if grammar is None:
            return
        try:
            new = core.restyle_terminal(grammar, name, changes)
        except LsysError as exc:
            self.show_message(str(exc))
            return
        what = ", ".join(f"{k} {v}" for k, v in changes.items())
        self.doc.apply_grammar(new, f"Set {what} of {name}", merge_key=self.doc.merge_key(f"style:{name}"))

    def highlight_terminal(self, name: str) -> None:
        """Show the instances of terminal ``name`` on the canvas (``""``: none)."""
        grammar = self.doc.grammar
        names = [t.name for t in grammar.terminals] if grammar is not None else []
        self.select_rule(None)
        self.canvas.set_highlight_terminal(names.index(name) if name in names else None)

    # -- messages and state -------------------------------------------------------------------------
    def show_message(self, text: str) -> None:
        """Show an error or note above the canvas and in the status bar."""
        self.message_bar.show_message(text)
        self.statusBar().showMessage(text, 10000)

    def _on_grammar_error(self, error: Any) -> None:
        self.params_panel.setEnabled(error is None)
        self._update_actions()

    def _on_grammar_changed(self, grammar: Any) -> None:
        self.pacing.grammar_changed()  # the panels follow in their own event-loop turn (paced in gestures)
        self._update_status()
        self._update_actions()

    def _update_panels(self) -> None:
        """Show the newest grammar in the panels, one panel per event-loop turn.

        Each step runs in its own turn of the event loop, so input and painting are served
        between them: applying rules with 833 parameters stalled the UI thread 168 ms in one
        turn, now its longest turn is one panel's update.  A newer grammar restarts the steps.
        """
        grammar = self.doc.grammar
        if grammar is None:
            self._panel_steps = None
            return
        if self._panel_steps is None or self._panel_steps[0] is not grammar:
            self._panel_steps = (grammar, self._panel_work(grammar))
        try:
            next(self._panel_steps[1])
        except StopIteration:
            self._panel_steps = None
            return
        except LsysError as exc:
            self._panel_steps = None
            self.show_message(str(exc))
            return
        self._panels_timer.start()

    def _panel_work(self, grammar: Any) -> Iterator[None]:
        """Update the panels for ``grammar``, yielding between panels."""
        params = core.list_params(grammar)  # a turn of its own: 833 parameters take ~3 ms
        yield
        yield from self.params_panel.param_steps(params)
        yield
        made: list[Any] = []
        for card in core.describe_iter(grammar):
            made.append(card)
            if len(made) % CARDS_PER_TURN == 0:
                yield
        cards = tuple(made)
        yield
        yield from self.rules_view.card_steps(grammar, cards)
        yield
        yield from self.structure_panel.content_steps(grammar, cards, self.doc.drawing)
        yield
        self.structure_panel.set_legend(legend(grammar, self.canvas.color_mode))

    def _on_control_edited(self, owner: str, label: str, value: float) -> None:
        """A semantic control moved: set every parameter it writes, as one edit."""
        control = self.rules_view.control(owner, label)
        if control is None:
            return
        name = "the start" if owner == "axiom" else owner
        self.doc.set_params(control.values(value), f"Change {label} of {name}", f"control:{owner}:{label}")

    def select_rule(self, name: str | None) -> None:
        """Select rule ``name`` (``"axiom"``: the start; None: nothing) in every view."""
        grammar = self.doc.grammar
        index: Any = None
        if name and grammar is not None:  # the rule's instances and those of the rules it uses
            under = core.rules_under(grammar, name)
            index = [i for i, r in enumerate(grammar.rules) if r.name in under] + (
                [-1] if name == "axiom" else []
            )
        self.rules_panel.highlight_rule(name)
        self.rules_view.select(name)
        self.structure_panel.select_rule(name)
        self.canvas.set_highlight_rule(index)

    def _on_scene_changed(self) -> None:
        self.canvas.set_overlay_svg(self.doc.scene_path)
        self.select_rule(None)
        if self.doc.scene_path:
            self.recent.add(self.doc.scene_path)
            self.canvas.fit_on_next_drawing()
        self.message_bar.hide()
        self._update_actions()
        self._update_title()

    def _on_inference_finished(self) -> None:
        self.inference_panel.set_running(False)
        self.statusBar().clearMessage()
        self._update_status()
        self._update_actions()

    def _on_element_clicked(self, index: int) -> None:
        drawing, grammar = self.doc.drawing, self.doc.grammar
        if drawing is None or grammar is None or index < 0:
            self.select_rule(None)
            self.handles.select(None, grammar, drawing)
            return
        rule = int(drawing.rule[index])
        name = "axiom" if rule < 0 or rule >= len(grammar.rules) else grammar.rules[rule].name
        self.select_rule(name)
        self.handles.select(index, grammar, drawing)
        self.statusBar().showMessage(f"element {index} drawn by {name}", 5000)

    def _update_actions(self, *_args: Any) -> None:
        d = self.doc
        has_grammar = d.grammar is not None
        self.act_symmetrize.setEnabled(d.can_infer)
        self.inference_panel.set_editable(d.can_infer)
        for act in (
            self.act_randomize,
            self.act_replace,
            self.act_clean,
            self.act_grow,
            self.act_shrink,
            self.act_export_svg,
            self.act_export_png,
            self.act_save,
            self.act_save_as,
        ):
            act.setEnabled(has_grammar)

    def _update_status(self, *_args: Any) -> None:
        s = self.doc.stats()
        labels = self._status_labels

        def show(key: str, text: str | None) -> None:
            labels[key].setText(text or "")
            labels[key].setVisible(bool(text))

        show("elements", f"{s['elements']:,} elements" if s["elements"] is not None else None)
        if s["terminals"] is not None:
            show("symbols", f"{s['terminals']} terminals, {s['nonterminals']} non-terminals")
            show("rules", f"{s['rules']} rules")
        else:
            show("symbols", None)
            show("rules", None)
        show("compression", f"compression {s['compression']:.1f}×" if s["compression"] else None)
        show("time", f"inference {s['seconds']:.2f} s" if s["seconds"] is not None else None)

    def _update_title(self, *_args: Any) -> None:
        self.setWindowTitle(f"{self.doc.display_name()}[*] — L-system Editor")
        self.setWindowModified(self.doc.modified)

    # -- idle (used by --screenshot and tests) -----------------------------------------------------------
    def is_idle(self) -> bool:
        """Whether nothing is pending: no inference, parse or derivation, and the canvas is final."""
        return (
            not self.doc.busy
            and self.canvas.is_idle()
            and not self._panels_timer.isActive()
            and not self.pacing.pending
            and not self.rules_panel.editor.highlighter.pending
        )

    # -- close ---------------------------------------------------------------------------------------------
    def closeEvent(self, event: QCloseEvent) -> None:
        """Offer to save, keep the layout, stop the workers and remove the recovery file."""
        if not self.maybe_save():
            event.ignore()
            return
        if self._keep_layout:
            self.settings.setValue("window/geometry", self.saveGeometry())
            self.settings.setValue("window/state", self.saveState())
        self.shutdown()
        event.accept()

    def shutdown(self) -> None:
        """Stop every background computation (idempotent)."""
        self.doc.shutdown()
        self.canvas.shutdown()
        if self.recovery is not None:
            self.recovery.close()
            self.recovery = None
