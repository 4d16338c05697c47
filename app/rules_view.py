"""The rules view: one card per rule, in a designer's words, beside the rules text.

Each card shows the rule's kind in words ("ring of 8", "row of 12, 46 apart"), thumbnails of
the terminals it draws, the rules it uses, and one control per *semantic* parameter (count,
step distance and direction, turn and scale per step).  The cards come from
``lsys_core.grammar.semantics.describe``; a control writes every place its value occurs, so the
``+(α) … +(-α)`` pair of a step moves as one.  Editing a control forwards
``(rule, control, value)``; the window turns it into one document edit, and the text follows.

Like the parameters panel, cards fold: only open cards have control rows, a page of
:data:`~app.params_panel.ROWS_PER_PAGE` at a time ("Show more" adds one: a start with 240
controls built them all in 39 ms, and Qt took 77 ms more to lay them out), and cards and rows
are reused from one grammar to the next.

Cards are made lazily: new rules show the cards of the first :data:`CARD_PAGE` rules, and
the next ones are made as the view is scrolled near its end (or asked for, or selected).  Every
change of a shown card lays out all shown cards again: with a card for each of 120 rules, that
layout took the UI thread 20–35 ms per event-loop turn while new rules were shown.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from PySide6.QtCore import QCoreApplication, QEvent, QTimer, Signal
from PySide6.QtWidgets import QPushButton, QWidget

from .params_panel import ROWS_PER_PAGE, scroll_column
from .rule_card import RuleCard

__all__ = ["OPEN_CONTROLS", "RulesView"]

#: Cards open on a new grammar until about this many controls are shown.
OPEN_CONTROLS = 30
#: Cards configured per event-loop turn (:meth:`RulesView.card_steps`, and as more are shown).
CARDS_PER_STEP = 12
#: Cards shown at first on new rules; more as the view is scrolled near its end.
CARD_PAGE = 16


class RulesView(QWidget):
    """The dock content: a card per rule, made as they are scrolled to.

    Signals
    -------
    controlEdited(rule, label, value)
        A control of rule ``rule`` (``axiom`` for the start) was moved to ``value``.
    ruleSelected(rule)
        A card was clicked.
    dragStarted(), dragFinished()
    """

    controlEdited = Signal(str, str, float)
    ruleSelected = Signal(str)
    dragStarted = Signal()
    dragFinished = Signal()

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.cards: dict[str, Any] = {}
        self._order: tuple = ()  # the cards of the rules, in order (the first ``_shown`` have widgets)
        self._terminals: dict[str, Any] = {}
        self._shown = 0
        self._budget = 0  # controls still to open on cards made later
        self._widgets: list[RuleCard] = []
        self._shape: list[tuple[str, tuple[str, ...]]] = []
        self._selected: str | None = None
        self._reveal: str | None = None  # a selected rule whose card is being made
        self._scroll, self._content, self._column, self._empty = scroll_column(
            self, "Open an SVG or .lsys file to see its rules.", spacing=4
        )
        self.more = QPushButton(self._content)
        self.more.setFlat(True)
        self.more.clicked.connect(lambda: self.show_cards(self._shown + CARD_PAGE))
        self._column.insertWidget(0, self.more)
        self.more.hide()
        self._fill = QTimer(self)  # shows more cards, a step per turn, while the view's end is near
        self._fill.setSingleShot(True)
        self._fill.setInterval(0)
        self._fill.timeout.connect(self._fill_step)
        bar = self._scroll.verticalScrollBar()
        bar.valueChanged.connect(self._near_end)
        bar.rangeChanged.connect(self._near_end)

    @property
    def shown(self) -> int:
        """How many rules have a card (the first ones; the others are made when scrolled to)."""
        return self._shown

    def widget_of(self, owner: str) -> RuleCard | None:
        """Return the card widget of rule ``owner``, made now if not yet (None if it has none)."""
        index = self._index(owner)
        if index is None or not self._shape:
            return None
        self.show_cards(index + 1)
        return self._widgets[index]

    def control(self, owner: str, label: str) -> Any:
        """Return the current :class:`~lsys_core.grammar.semantics.Control` of a rule, or None."""
        card = self.cards.get(owner)
        return next((c for c in card.controls if c.label == label), None) if card is not None else None

    def set_cards(self, grammar: Any, cards: tuple) -> None:
        """Show the cards of ``grammar`` (values only, if the rules and controls are the same)."""
        for _ in self.card_steps(grammar, cards):
            pass

    def card_steps(self, grammar: Any, cards: tuple) -> Iterator[None]:
        """Show the cards of ``grammar`` a few at a time, yielding between them.

        The window runs the steps in separate event-loop turns: configuring 120 cards took
        the UI thread 100–160 ms in one turn.  Only the cards shown get widgets (the first
        :data:`CARD_PAGE`, or as many as were shown of the same rules).  An interrupted run (a
        newer grammar) leaves the view marked as changed, so the next run configures every
        card again.
        """
        self.cards = {c.owner: c for c in cards}
        self._order = tuple(cards)
        shape = [(c.owner, tuple(k.label for k in c.controls)) for c in cards]
        if shape == self._shape:
            for i, (widget, card) in enumerate(zip(self._widgets[: self._shown], cards, strict=False)):
                widget.update_values(card)
                if i % CARDS_PER_STEP == CARDS_PER_STEP - 1:
                    yield
            return
        self._shape = []
        self._fill.stop()
        self.more.hide()
        self._terminals = {t.name: t for t in grammar.terminals}
        self._budget = OPEN_CONTROLS
        self._shown = 0
        count = min(len(cards), CARD_PAGE)
        for i in range(count):
            self._make(i)
            if i % CARDS_PER_STEP == CARDS_PER_STEP - 1:
                yield
        for widget in self._widgets[count:]:
            widget.hide()
        self._scroll.setVisible(bool(cards))
        self._empty.setVisible(not cards)
        self._shape = shape
        self._show_more_button()
        if self._reveal:  # a rule selected while the cards were made
            self._fill.start()

    def show_cards(self, count: int) -> None:
        """Make the cards of the first ``count`` rules (those not made yet) and show them."""
        if not self._shape:
            return  # new rules are being shown: their steps make the first cards
        count = min(count, len(self._order))
        while self._shown < count:
            self._make(self._shown)
        self._show_more_button()

    def _make(self, i: int) -> None:
        """Configure and show the card of rule ``i`` (the ``i``-th widget, made if needed)."""
        card = self._order[i]
        if i == len(self._widgets):
            widget = RuleCard(self._content)
            widget.controlEdited.connect(self.controlEdited)
            widget.clicked.connect(self.ruleSelected)
            widget.dragStarted.connect(self.dragStarted)
            widget.dragFinished.connect(self.dragFinished)
            self._column.insertWidget(self._column.count() - 1, widget)  # before the stretch
            self._widgets.append(widget)
        widget = self._widgets[i]
        open_ = self._budget > 0 and bool(card.controls)
        widget.configure(card, open_, self._terminals)
        widget.set_selected(card.owner == self._selected)
        widget.show()
        if open_:
            self._budget -= min(len(card.controls), ROWS_PER_PAGE)
        self._shown = i + 1

    def _show_more_button(self) -> None:
        rest = len(self._order) - self._shown
        self._column.removeWidget(self.more)
        self._column.insertWidget(self._shown, self.more)  # after the shown cards
        self.more.setText(f"Show {min(rest, CARD_PAGE)} more of {rest} rules…")
        self.more.setVisible(rest > 0)

    def _near_end(self, *_args: Any) -> None:
        """More cards when the view shows (nearly) its end, a step per event-loop turn."""
        bar = self._scroll.verticalScrollBar()
        if (
            self._shape
            and self._shown < len(self._order)
            and bar.value() >= bar.maximum() - self._scroll.viewport().height() // 2
        ):
            self._fill.start()

    def _fill_step(self) -> None:
        if not self._reveal:
            self.show_cards(self._shown + CARDS_PER_STEP)  # the view's range changes: _near_end again
            return
        reveal = self._index(self._reveal)
        if reveal is None or not self._shape:  # the rule has gone, or new rules are being shown
            self._reveal = None if reveal is None else self._reveal
            return
        self.show_cards(min(self._shown + CARDS_PER_STEP, reveal + 1))
        if self._shown > reveal:
            self._reveal = None
            self._scroll_to(self._widgets[reveal])
        else:
            self._fill.start()

    def _index(self, owner: str | None) -> int | None:
        return next((i for i, c in enumerate(self._order) if c.owner == owner), None)

    def select(self, owner: str | None) -> None:
        """Frame the card of rule ``owner`` and scroll to it (None: no selection).

        A card not made yet is made with those before it, a step per event-loop turn (a click
        on the canvas may select the last of 120 rules), and scrolled to when it is there.
        """
        self._selected = owner
        self._reveal = None
        for widget in self._widgets[: self._shown]:
            widget.set_selected(widget.card is not None and widget.card.owner == owner)
        index = self._index(owner) if owner else None
        if index is None or not self._shape:
            return
        if index < self._shown:
            self._scroll_to(self._widgets[index])
        else:
            self._reveal = owner
            self._fill.start()

    def _scroll_to(self, widget: RuleCard) -> None:
        """Scroll to a card now, and again in the next turn: cards made just now may still move
        when they are laid out (their titles wrap), and the view grows with them."""
        self._content.layout().activate()
        QCoreApplication.sendPostedEvents(None, QEvent.Type.LayoutRequest)
        self._scroll.ensureWidgetVisible(widget, 0, 8)
        card = widget.card

        def again() -> None:  # unless another rule was selected, or new rules came meanwhile
            if card is not None and widget.card is card and card.owner == self._selected:
                self._scroll.ensureWidgetVisible(widget, 0, 8)

        QTimer.singleShot(0, self, again)
