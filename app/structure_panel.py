"""The structure panel: the rule hierarchy, the colour legend, and the terminal palette.

* **Hierarchy**: a tree from the start (axiom) through the rules it uses down to the shapes they
  draw, each rule with its kind in words and how many instances it draws on the canvas.
  Selecting a rule selects its instances on the canvas (and a click on the canvas selects the
  rule here).
* **Legend**: what each colour means in *Colour by Similarity Group* / *Colour by Rule*.
* **Terminals**: every shape of the grammar as a thumbnail; selecting one shows its instances on
  the canvas; *Replace…* opens Replace Symbol for it, and its fill, stroke and opacity can be
  edited (one undo step each).

The panel only displays and forwards: the window turns its signals into document edits.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
from PySide6.QtCore import QSize, Qt, Signal
from PySide6.QtGui import QColor, QIcon, QPixmap
from PySide6.QtWidgets import (
    QColorDialog,
    QDoubleSpinBox,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QPushButton,
    QStyle,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from . import core
from .rule_card import thumbnail

__all__ = ["StructurePanel"]

ICON = 28
#: Tree items made per event-loop turn while new rules are shown (the tree of 120 rules and
#: their shapes, 241 items, took 5–9 ms in one turn, the longest of the panels' steps).
ITEMS_PER_STEP = 80
_ROLE = Qt.ItemDataRole.UserRole


def _swatch(color: str) -> QIcon:
    pixmap = QPixmap(14, 14)
    pixmap.fill(QColor(color))
    return QIcon(pixmap)


class StructurePanel(QWidget):
    """The dock content: hierarchy tree, colour legend and terminal palette.

    Signals
    -------
    ruleSelected(name)
        A rule (``axiom``: the start) was chosen in the tree.
    terminalSelected(name)
        A terminal was chosen in the palette (``""``: none).
    replaceRequested(name)
        *Replace…* for terminal ``name``.
    styleEdited(name, changes)
        New CSS declarations for terminal ``name`` (``{"fill": "#ff0000"}``).
    """

    ruleSelected = Signal(str)
    terminalSelected = Signal(str)
    replaceRequested = Signal(str)
    styleEdited = Signal(str, object)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.grammar: Any = None
        self._items: dict[str, list[QTreeWidgetItem]] = {}
        self._tree_key: tuple = ()
        self._palette_key: tuple = ()
        self._closures: tuple[Any, dict[str, frozenset[str]]] = (None, {})  # (grammar, rule_closures)
        # The newest content, and whether the tree still shows older content (the panel was hidden).
        self._cards: tuple | None = None
        self._drawing: Any = None
        self._stale = False
        self._updating = False
        self.tree = QTreeWidget(self)
        self.tree.setHeaderLabels(["Rule", "Draws", "Instances"])
        self.tree.headerItem().setToolTip(2, "Instances drawn by the rule and the rules it uses")
        self.tree.setIconSize(QSize(ICON - 8, ICON - 8))
        self.tree.itemSelectionChanged.connect(self._on_tree_selection)
        self.legend = QListWidget(self)
        self.legend.setSelectionMode(QListWidget.SelectionMode.NoSelection)
        self.legend.setMaximumHeight(120)
        self.legend_note = QLabel(
            "Original colours: choose View → Colour by … to colour the structure.", self
        )
        self.legend_note.setWordWrap(True)
        self.palette = QListWidget(self)
        self.palette.setViewMode(QListWidget.ViewMode.IconMode)
        self.palette.setIconSize(QSize(ICON * 2 - 8, ICON * 2 - 8))
        self.palette.setResizeMode(QListWidget.ResizeMode.Adjust)
        self.palette.setMovement(QListWidget.Movement.Static)
        self.palette.setMaximumHeight(150)
        self.palette.itemSelectionChanged.connect(self._on_palette_selection)
        self.palette.itemDoubleClicked.connect(lambda item: self.replaceRequested.emit(item.data(_ROLE)))
        self.replace_button = QPushButton("Replace…", self)
        self.fill_button = QPushButton("Fill…", self)
        self.stroke_button = QPushButton("Stroke…", self)
        self.opacity = QDoubleSpinBox(self)
        self.opacity.setRange(0.0, 1.0)
        self.opacity.setSingleStep(0.1)
        self.opacity.setDecimals(2)
        self.opacity.setKeyboardTracking(False)
        self.opacity.setPrefix("opacity ")
        self.replace_button.clicked.connect(lambda: self._emit_for_selected(self.replaceRequested.emit))
        self.fill_button.clicked.connect(lambda: self.pick_color("fill"))
        self.stroke_button.clicked.connect(lambda: self.pick_color("stroke"))
        self.opacity.valueChanged.connect(self._on_opacity)
        buttons = QHBoxLayout()
        for w in (self.replace_button, self.fill_button, self.stroke_button, self.opacity):
            buttons.addWidget(w)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        hierarchy = QGroupBox("Hierarchy", self)
        QVBoxLayout(hierarchy).addWidget(self.tree)
        legend = QGroupBox("Legend", self)
        legend_layout = QVBoxLayout(legend)
        legend_layout.addWidget(self.legend_note)
        legend_layout.addWidget(self.legend)
        terminals = QGroupBox("Terminals", self)
        term_layout = QVBoxLayout(terminals)
        term_layout.addWidget(self.palette)
        term_layout.addLayout(buttons)
        layout.addWidget(hierarchy, 3)
        layout.addWidget(legend, 1)
        layout.addWidget(terminals, 1)
        self._enable_terminal_buttons()

    # -- content --------------------------------------------------------------------------------
    def set_content(self, grammar: Any, cards: tuple, drawing: Any) -> None:
        """Show the hierarchy and palette of ``grammar`` (cards: its descriptions).

        While the panel is hidden (its dock is a tab behind another, as by default, or closed)
        the content waits for :meth:`showEvent`: rebuilding a hidden tree costs as much as a
        shown one (30 ms of Python and as much again in Qt for 120 rules).
        """
        for _ in self.content_steps(grammar, cards, drawing):
            pass

    def content_steps(self, grammar: Any, cards: tuple, drawing: Any) -> Iterator[None]:
        """Do :meth:`set_content`, yielding between every :data:`ITEMS_PER_STEP` items of a new tree.

        The window runs the steps in separate event-loop turns.  An interrupted run (newer
        rules) leaves the tree marked as changed, so the next run builds it again.
        """
        self.grammar, self._cards, self._drawing = grammar, cards, drawing
        if not self.isVisible():  # a tab behind another or a closed dock: fill it when it shows
            self._stale = True
            return
        self._stale = False
        selected = self.selected_rule()
        term_selected = self.selected_terminal()
        self._updating = True
        try:
            by_owner = {c.owner: c for c in cards}
            counts = self._count_texts(drawing)
            tree_key = tuple((c.owner, c.terminals, c.calls) for c in cards)
            if tree_key != self._tree_key:  # the structure changed: rebuild (else only the words)
                self._tree_key = ()  # until the whole tree is there
                yield from self._tree_steps(grammar, by_owner, counts)
                self._tree_key = tree_key
            else:
                for name, items in self._items.items():
                    card = by_owner.get(name)
                    text = card.summary.split(": ", 1)[-1] if card else ""
                    for item in items:
                        if item.text(1) != text:
                            item.setText(1, text)
            palette_key = tuple((t.name, t.path, t.style) for t in grammar.terminals)
            if palette_key != self._palette_key:
                self._palette_key = palette_key
                self._fill_palette(grammar)
            if drawing is not None:
                self._show_counts(counts)
            if selected:
                self.select_rule(selected)
            if term_selected:
                for i in range(self.palette.count()):
                    if self.palette.item(i).data(_ROLE) == term_selected:
                        self.palette.item(i).setSelected(True)
        finally:
            self._updating = False
        self._enable_terminal_buttons()

    def _tree_steps(self, grammar: Any, cards: dict[str, Any], counts: dict[str, str]) -> Iterator[None]:
        """Build the tree of rules from the start down, yielding every :data:`ITEMS_PER_STEP` items."""
        self.tree.clear()
        self._items = {}
        terms = {t.name: t for t in grammar.terminals}
        dpr = float(self.devicePixelRatioF())
        icons: dict[str, QIcon] = {}  # one thumbnail per terminal, however many rules draw it

        def icon(t: str) -> QIcon:
            if t not in icons:
                icons[t] = QIcon(thumbnail(terms[t], ICON - 8, dpr))
            return icons[t]

        made = [0]

        def add(parent: Any, name: str, path: tuple[str, ...]) -> Iterator[None]:
            card = cards.get(name)
            title = "Start (axiom)" if name == "axiom" else name
            summary = card.summary.split(": ", 1)[-1] if card else ""
            item = QTreeWidgetItem(parent, [title, summary, counts.get(name, "")])
            item.setData(0, _ROLE, name)
            self._items.setdefault(name, []).append(item)
            if card is None:
                return
            for t in card.terminals:
                leaf = QTreeWidgetItem(item, [t, "shape", ""])
                leaf.setIcon(0, icon(t))
                leaf.setData(0, _ROLE, None)
                leaf.setData(1, _ROLE, t)
            made[0] += 1 + len(card.terminals)
            if made[0] >= ITEMS_PER_STEP:
                made[0] = 0
                yield
            for child in card.calls:
                if child not in path:  # a rule never contains itself (recursion is its repetition)
                    yield from add(item, child, (*path, child))

        yield from add(self.tree, "axiom", ("axiom",))
        yield
        self.tree.expandToDepth(2)
        self._fit_columns()

    def _fit_columns(self) -> None:
        """Size the columns to their longest texts (``resizeColumnToContents`` asked every item
        for its size hint: 9 ms for 120 rules)."""
        fm = self.tree.fontMetrics()
        pad = 2 * self.tree.style().pixelMetric(QStyle.PixelMetric.PM_FocusFrameHMargin) + 12
        depth = {}
        stack = [(self.tree.invisibleRootItem(), 0)]
        texts: list[set[str]] = [set(), set(), {self.tree.headerItem().text(2), "0,000,000"}]
        while stack:  # the depth of every title, for the indentation of column 0
            parent, d = stack.pop()
            for i in range(parent.childCount()):
                item = parent.child(i)
                title = item.text(0)
                depth[title] = max(depth.get(title, 0), d)
                texts[1].add(item.text(1))
                stack.append((item, d + 1))
        icon = self.tree.iconSize().width() + 4
        col0 = max(
            (fm.horizontalAdvance(t) + (d + 1) * self.tree.indentation() for t, d in depth.items()), default=0
        )
        self.tree.setColumnWidth(0, col0 + icon + pad)
        self.tree.setColumnWidth(1, max((fm.horizontalAdvance(t) for t in texts[1]), default=0) + pad)
        self.tree.setColumnWidth(2, max(fm.horizontalAdvance(t) for t in texts[2]) + pad)

    def _fill_palette(self, grammar: Any) -> None:
        self.palette.clear()
        dpr = float(self.devicePixelRatioF())
        for t in grammar.terminals:
            item = QListWidgetItem(QIcon(thumbnail(t, ICON * 2 - 8, dpr)), t.name)
            item.setData(_ROLE, t.name)
            item.setToolTip(f"terminal {t.name}: {t.style or 'default style'}")
            self.palette.addItem(item)

    def set_drawing(self, drawing: Any) -> None:
        """Show how many instances each rule's structure draws (its own and its sub-rules')."""
        self._drawing = drawing
        if self.grammar is None or drawing is None:
            return
        if not self.isVisible():
            self._stale = True
            return
        self._show_counts(self._count_texts(drawing))

    def _show_counts(self, texts: dict[str, str]) -> None:
        for name, items in self._items.items():
            text = texts.get(name, "")
            for item in items:
                if item.text(2) != text:  # each set text costs the view ~50 µs
                    item.setText(2, text)

    def _count_texts(self, drawing: Any) -> dict[str, str]:
        """Return the instance count of ``axiom`` and of every rule's structure, as shown."""
        if self.grammar is None or drawing is None:
            return {}
        if self._closures[0] is not self.grammar:
            self._closures = (self.grammar, core.rule_closures(self.grammar))
        under = self._closures[1]
        rules = self.grammar.rules
        counts = np.bincount(np.asarray(drawing.rule, dtype=np.int64) + 1, minlength=len(rules) + 1)
        own = {r.name: int(counts[i + 1]) for i, r in enumerate(rules)}
        texts = {name: f"{sum(own.get(r, 0) for r in under.get(name, ())):,}" for name in own}
        texts["axiom"] = f"{sum(own.get(r, 0) for r in under.get('axiom', ())) + int(counts[0]):,}"
        return texts

    def showEvent(self, event) -> None:
        """Show the newest content if it arrived while the panel was hidden."""
        super().showEvent(event)
        if self._stale and self._cards is not None:
            self.set_content(self.grammar, self._cards, self._drawing)

    def set_legend(self, entries: list[tuple[str, str]]) -> None:
        """Show ``(colour, what)`` entries (empty: the original colours are shown)."""
        self.legend.clear()
        for color, what in entries:
            self.legend.addItem(QListWidgetItem(_swatch(color), what))
        self.legend.setVisible(bool(entries))
        self.legend_note.setVisible(not entries)

    # -- selection --------------------------------------------------------------------------------
    def selected_rule(self) -> str | None:
        """Return the rule selected in the tree (None: none)."""
        items = self.tree.selectedItems()
        return items[0].data(0, _ROLE) if items and items[0].data(0, _ROLE) else None

    def selected_terminal(self) -> str | None:
        """Return the terminal selected in the palette (None: none)."""
        items = self.palette.selectedItems()
        return items[0].data(_ROLE) if items else None

    def select_rule(self, name: str | None) -> None:
        """Select the tree items of rule ``name`` without emitting :attr:`ruleSelected`."""
        updating, self._updating = self._updating, True
        try:
            self.tree.clearSelection()
            for item in self._items.get(name or "", []):
                item.setSelected(True)
                self.tree.scrollToItem(item)
        finally:
            self._updating = updating

    def _on_tree_selection(self) -> None:
        if self._updating:
            return
        items = self.tree.selectedItems()
        if not items:
            return
        rule = items[0].data(0, _ROLE)
        if rule:
            self.ruleSelected.emit(rule)
        elif items[0].data(1, _ROLE):
            self.terminalSelected.emit(items[0].data(1, _ROLE))

    def _on_palette_selection(self) -> None:
        self._enable_terminal_buttons()
        if not self._updating:
            self.terminalSelected.emit(self.selected_terminal() or "")

    def _enable_terminal_buttons(self) -> None:
        name = self.selected_terminal()
        for w in (self.replace_button, self.fill_button, self.stroke_button, self.opacity):
            w.setEnabled(name is not None)
        term = self.grammar.terminal(name) if name and self.grammar is not None else None
        if term is not None:
            from lsys_core.render.paths import parse_style

            raw = parse_style(term.style).get("opacity", "1")
            try:
                value = float(raw)
            except ValueError:
                value = 1.0
            self.opacity.blockSignals(True)
            self.opacity.setValue(value)
            self.opacity.blockSignals(False)

    # -- edits ----------------------------------------------------------------------------------------
    def _emit_for_selected(self, emit) -> None:
        name = self.selected_terminal()
        if name:
            emit(name)

    def pick_color(self, what: str) -> None:
        """Ask for the ``fill`` or ``stroke`` colour of the selected terminal and forward it."""
        name = self.selected_terminal()
        if not name:
            return
        color = QColorDialog.getColor(QColor("#000000"), self, f"{what.capitalize()} of {name}")
        if color.isValid():
            self.styleEdited.emit(name, {what: color.name()})

    def _on_opacity(self, value: float) -> None:
        name = self.selected_terminal()
        if name:
            self.styleEdited.emit(name, {"opacity": f"{value:g}"})
