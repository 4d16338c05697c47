"""The parameters panel: a slider and a spin box for every numeric parameter of the rules.

Rows are built from ``lsys_core.grammar.list_params``; moving a slider forwards
``(key, value)`` to the document, which re-derives and repaints without re-running inference.
A slider drag is one gesture (one undo step, draft rendering while it lasts).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QDoubleSpinBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QScrollArea,
    QSlider,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from . import core

__all__ = ["OPEN_ROWS", "ROWS_PER_PAGE", "ParamRow", "ParamsPanel", "scroll_column", "slider_range"]

SLIDER_STEPS = 1000
#: Rows a section shows at once (more on request).
ROWS_PER_PAGE = 24
#: Sections open on a new grammar until about this many rows are shown.
OPEN_ROWS = 40
#: Sections configured per event-loop turn (:meth:`ParamsPanel.param_steps`).
SECTIONS_PER_STEP = 30
COUNT_MAX = 2**31 - 1
_SPIN_LIMIT = 1e9


def slider_range(kind: str, value: float) -> tuple[float, float]:
    """Return the slider's ``(low, high)`` for a parameter of ``kind`` currently at ``value``.

    The range is fixed when the row is built (so it does not move under a dragging mouse);
    the spin box accepts values outside it.
    """
    v = float(value)
    mag = abs(v)
    if kind == "angle":
        return -180.0, 180.0
    if kind == "angle_delta":
        span = max(10.0, 3 * mag)
        return -span, span
    if kind == "distance":
        hi = max(2 * mag, 1.0)
        return (-hi, hi) if v < 0 else (0.0, hi)
    if kind == "scale":  # a constant scale must stay positive
        return 0.01, max(2.0, 2 * mag)
    if kind == "scale_delta":
        span = max(0.05, 3 * mag)
        return -span, span
    if kind == "count":
        return 0.0, float(max(10, 2 * math.ceil(mag)))
    span = max(1.0, 3 * mag)  # distance_delta and anything new
    return -span, span


def scroll_column(
    owner: QWidget, empty_text: str, *, spacing: int
) -> tuple[QScrollArea, QWidget, QVBoxLayout, QLabel]:
    """Fill ``owner`` with a scrolled column of widgets and a note shown while it is empty.

    Returns the scroll area (hidden), the column's widget, its layout (ending in a stretch:
    insert before it) and the note.
    """
    scroll = QScrollArea(owner)
    scroll.setWidgetResizable(True)
    content = QWidget()
    column = QVBoxLayout(content)
    column.setContentsMargins(4, 4, 4, 4)
    column.setSpacing(spacing)
    column.addStretch(1)
    scroll.setWidget(content)
    empty = QLabel(empty_text, owner)
    empty.setWordWrap(True)
    empty.setAlignment(Qt.AlignmentFlag.AlignCenter)
    layout = QVBoxLayout(owner)
    layout.setContentsMargins(0, 0, 0, 0)
    layout.addWidget(empty)
    layout.addWidget(scroll, 1)
    scroll.hide()
    return scroll, content, column, empty


class CleanSpinBox(QDoubleSpinBox):
    """A spin box that shows ``46`` and ``18.5``, not ``46.000`` and ``18.500``."""

    def textFromValue(self, value: float) -> str:
        """Return ``value`` at the box's decimals without trailing zeros."""
        text = f"{value:.{self.decimals()}f}"
        if "." in text:
            text = text.rstrip("0").rstrip(".")
        return "0" if text in ("-0", "") else text


class ParamRow(QWidget):
    """One parameter: a slider over :func:`slider_range` and an exact spin box.

    A row can show another parameter later (:meth:`configure`), so a new grammar reuses the rows
    of the previous one instead of building new widgets.

    Signals
    -------
    valueEdited(key, value), dragStarted(), dragFinished()
    """

    valueEdited = Signal(str, float)
    dragStarted = Signal()
    dragFinished = Signal()

    def __init__(self, param: Any, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.slider = QSlider(Qt.Orientation.Horizontal, self)
        self.slider.setRange(0, SLIDER_STEPS)
        self.slider.setMinimumWidth(120)
        self.spin = CleanSpinBox(self)
        self.spin.setRange(-_SPIN_LIMIT, _SPIN_LIMIT)
        self.spin.setKeyboardTracking(False)
        self.spin.setMinimumWidth(90)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.slider, 1)
        layout.addWidget(self.spin)
        self.configure(param)
        self.slider.valueChanged.connect(self._on_slider)
        self.slider.sliderPressed.connect(self.dragStarted)
        self.slider.sliderReleased.connect(self.dragFinished)
        self.spin.valueChanged.connect(self._on_spin)

    def configure(self, param: Any) -> None:
        """Show ``param`` (``Param(key, label, value, kind)``), the range fixed for its value."""
        self.key = param.key
        self.kind = param.kind
        self.integer = param.kind == "count"
        self.lo, self.hi = slider_range(param.kind, param.value)
        self.spin.blockSignals(True)
        if self.integer:
            self.spin.setDecimals(0)
            self.spin.setRange(0, COUNT_MAX)
            self.spin.setSingleStep(1)
        else:
            self.spin.setDecimals(4 if "scale" in param.kind or "delta" in param.kind else 3)
            self.spin.setRange(-_SPIN_LIMIT, _SPIN_LIMIT)
            self.spin.setSingleStep((self.hi - self.lo) / 100)
        self.spin.blockSignals(False)
        self._shown: float | None = None
        self.set_value(param.value)

    def value(self) -> float:
        """Return the spin box value."""
        return float(self.spin.value())

    def set_value(self, value: float) -> None:
        """Show ``value`` without emitting :attr:`valueEdited`.

        A value outside the slider's range (typed, or set by undo) widens the range, unless the
        slider is being dragged.
        """
        if value == self._shown:
            return
        self._shown = value
        if not self.lo <= value <= self.hi and not self.slider.isSliderDown():
            self.lo, self.hi = slider_range(self.kind, value)
        self.slider.blockSignals(True)
        self.spin.blockSignals(True)
        try:
            self.spin.setValue(round(value) if self.integer else float(value))
            self.slider.setValue(self._to_slider(value))
        finally:
            self.slider.blockSignals(False)
            self.spin.blockSignals(False)

    def _to_slider(self, value: float) -> int:
        t = (float(value) - self.lo) / (self.hi - self.lo)
        return round(min(1.0, max(0.0, t)) * SLIDER_STEPS)

    def _from_slider(self, pos: int) -> float:
        """Return the value at slider position ``pos``: the simplest within half a slider step."""
        v = self.lo + (self.hi - self.lo) * pos / SLIDER_STEPS
        if self.integer:
            return float(round(v))
        half = (self.hi - self.lo) / SLIDER_STEPS / 2
        if self.kind == "scale":  # snap takes a relative tolerance for scales
            half = half / abs(v) if v else 0.0
        return core.snap(v, half, self.kind)

    def _on_slider(self, pos: int) -> None:
        value = self._from_slider(pos)
        self._shown = value
        self.spin.blockSignals(True)
        self.spin.setValue(value)
        self.spin.blockSignals(False)
        self.valueEdited.emit(self.key, value)

    def _on_spin(self, value: float) -> None:
        self._shown = float(value)
        self.slider.blockSignals(True)
        self.slider.setValue(self._to_slider(value))
        self.slider.blockSignals(False)
        self.valueEdited.emit(self.key, float(value))


class _Line(QWidget):
    """A label and a :class:`ParamRow`."""

    def __init__(self, param: Any, parent: QWidget) -> None:
        super().__init__(parent)
        self.label = QLabel(self)
        self.label.setMinimumWidth(70)
        self.row = ParamRow(param, self)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.label)
        layout.addWidget(self.row, 1)
        self.set_label(param)

    def set_label(self, param: Any) -> None:
        """Show the label of ``param`` (its rule name is the section's title, so it is left out)."""
        text = param.label.split(": ", 1)[-1]
        self.label.setText(text)
        self.label.setToolTip(f"{param.label} — {param.key} ({param.kind.replace('_', ' ')})")


class _Section(QWidget):
    """The parameters of one rule (or the axiom) under a header that folds them away.

    Rows exist only while the section is open, at most :data:`ROWS_PER_PAGE` more at a time
    (*Show more*), and are reused when the section shows another rule.
    """

    def __init__(self, panel: ParamsPanel) -> None:
        super().__init__(panel._content)
        self.panel = panel
        self.params: list[Any] = []
        self.limit = ROWS_PER_PAGE
        self.header = QToolButton(self)
        self.header.setCheckable(True)
        self.header.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextBesideIcon)
        self.header.setAutoRaise(True)
        self.header.toggled.connect(self._on_toggled)
        self.body = QWidget(self)
        self.rows_layout = QVBoxLayout(self.body)
        self.rows_layout.setContentsMargins(14, 0, 0, 0)
        self.rows_layout.setSpacing(2)
        self.more = QPushButton(self.body)
        self.more.setFlat(True)
        self.more.clicked.connect(self._show_more)
        self.rows_layout.addWidget(self.more)
        self.lines: list[_Line] = []
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(0)
        layout.addWidget(self.header)
        layout.addWidget(self.body)

    def configure(self, owner: str, params: list[Any], open_: bool) -> None:
        """Show the parameters ``params`` of ``owner``; ``open_`` unfolds the section."""
        self.params = params
        self.limit = ROWS_PER_PAGE
        n = len(params)
        self.header.setText(f"{owner}  ({n} number{'s' if n != 1 else ''})")
        self.header.blockSignals(True)
        self.header.setChecked(open_)
        self.header.blockSignals(False)
        self._refresh()

    def _on_toggled(self, _checked: bool) -> None:
        self._refresh()

    def _show_more(self) -> None:
        self.limit += ROWS_PER_PAGE
        self._refresh()

    def _refresh(self) -> None:
        open_ = self.header.isChecked()
        self.header.setArrowType(Qt.ArrowType.DownArrow if open_ else Qt.ArrowType.RightArrow)
        shown = self.params[: self.limit] if open_ else []
        for i, p in enumerate(shown):
            if i < len(self.lines):
                line = self.lines[i]
                line.row.configure(self.panel.current(p))
                line.set_label(p)
            else:
                line = _Line(self.panel.current(p), self.body)
                self.panel.connect_row(line.row)
                self.rows_layout.insertWidget(len(self.lines), line)
                self.lines.append(line)
            line.show()
            self.panel.rows[p.key] = line.row
        for line in self.lines[len(shown) :]:
            line.hide()
            if self.panel.rows.get(line.row.key) is line.row:
                del self.panel.rows[line.row.key]
        rest = len(self.params) - len(shown)
        self.more.setVisible(open_ and rest > 0)
        self.more.setText(f"Show {min(rest, ROWS_PER_PAGE)} more of {rest}…")
        self.body.setVisible(open_)


class ParamsPanel(QWidget):
    """The dock content: the numbers of the rules, one folding section per rule.

    Only open sections have widgets, and they open a page of :data:`ROWS_PER_PAGE` rows at a
    time; sections and rows are reused from one grammar to the next.  So a grammar with hundreds
    of parameters costs a few dozen widgets, and applying new rules never blocks the window.
    Sections open at first until :data:`OPEN_ROWS` rows are shown.

    Signals
    -------
    paramEdited(key, value), dragStarted(), dragFinished()
    """

    paramEdited = Signal(str, float)
    dragStarted = Signal()
    dragFinished = Signal()

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.rows: dict[str, ParamRow] = {}
        self._values: dict[str, Any] = {}
        self._sections: list[_Section] = []
        self._kinds: list[tuple[str, str]] = []
        self._scroll, self._content, self._column, self._empty = scroll_column(
            self, "Open an SVG or .lsys file to edit its parameters.", spacing=0
        )

    def current(self, param: Any) -> Any:
        """Return ``param`` with the newest value known for its key."""
        return self._values.get(param.key, param)

    def connect_row(self, row: ParamRow) -> None:
        """Forward a new row's signals."""
        row.valueEdited.connect(self.paramEdited)
        row.dragStarted.connect(self.dragStarted)
        row.dragFinished.connect(self.dragFinished)

    def set_params(self, params: list) -> None:
        """Show ``params`` (``Param(key, label, value, kind)``): update the values of the rows
        shown, or re-configure the sections when the set of parameters changed."""
        for _ in self.param_steps(params):
            pass

    def param_steps(self, params: list) -> Iterator[None]:
        """Do :meth:`set_params` a few sections at a time, yielding between them.

        The window runs the steps in separate event-loop turns: configuring the sections of
        120 rules took 14–26 ms in one turn.  An interrupted run leaves the panel marked as
        changed, so the next run configures every section again.
        """
        self._values = {p.key: p for p in params}
        kinds = [(p.key, p.kind) for p in params]
        if kinds == self._kinds:
            for key, row in self.rows.items():
                value = self._values[key].value
                if not row.slider.isSliderDown() and not row.spin.hasFocus():
                    row.set_value(value)
                elif row.slider.isSliderDown():
                    row.spin.blockSignals(True)
                    row.spin.setValue(round(value) if row.integer else value)
                    row.spin.blockSignals(False)
            return
        self._kinds = []
        groups: dict[str, list[Any]] = {}
        for p in params:
            groups.setdefault(p.key.split(".", 1)[0], []).append(p)
        self.rows = {}
        budget = OPEN_ROWS
        for i, (owner, group) in enumerate(groups.items()):
            if i < len(self._sections):
                section = self._sections[i]
            else:
                section = _Section(self)
                self._column.insertWidget(len(self._sections), section)
                self._sections.append(section)
            open_ = budget > 0
            section.configure(owner, group, open_)
            section.show()
            if open_:
                budget -= min(len(group), ROWS_PER_PAGE)
            if i % SECTIONS_PER_STEP == SECTIONS_PER_STEP - 1:
                yield
        for section in self._sections[len(groups) :]:
            section.configure("", [], False)
            section.hide()
        self._scroll.setVisible(bool(params))
        self._empty.setVisible(not params)
        if not params:
            self._empty.setText("These rules have no numeric parameters.")
        self._kinds = kinds
