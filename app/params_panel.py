"""The parameters panel: a slider and a spin box for every numeric parameter of the rules.

Rows are built from ``lsys_core.grammar.list_params``; moving a slider forwards
``(key, value)`` to the document, which re-derives and repaints without re-running inference.
A slider drag is one gesture (one undo step, draft rendering while it lasts).
"""

from __future__ import annotations

import math
from typing import Any

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QAbstractSpinBox,
    QDoubleSpinBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QScrollArea,
    QSlider,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

__all__ = ["ParamRow", "ParamsPanel", "slider_range"]

SLIDER_STEPS = 1000
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


class ParamRow(QWidget):
    """One parameter: a slider over :func:`slider_range` and an exact spin box.

    Signals
    -------
    valueEdited(key, value), dragStarted(), dragFinished()
    """

    valueEdited = Signal(str, float)
    dragStarted = Signal()
    dragFinished = Signal()

    def __init__(self, param: Any, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.key = param.key
        self.kind = param.kind
        self.integer = param.kind == "count"
        self.lo, self.hi = slider_range(param.kind, param.value)
        self.slider = QSlider(Qt.Orientation.Horizontal, self)
        self.slider.setRange(0, SLIDER_STEPS)
        self.slider.setMinimumWidth(120)
        if self.integer:
            self.spin: QAbstractSpinBox = QSpinBox(self)
            self.spin.setRange(0, 2**31 - 1)
        else:
            self.spin = QDoubleSpinBox(self)
            self.spin.setRange(-_SPIN_LIMIT, _SPIN_LIMIT)
            self.spin.setDecimals(4 if "scale" in param.kind or "delta" in param.kind else 3)
            self.spin.setSingleStep((self.hi - self.lo) / 100)
        self.spin.setKeyboardTracking(False)
        self.spin.setMinimumWidth(90)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.slider, 1)
        layout.addWidget(self.spin)
        self.set_value(param.value)
        self.slider.valueChanged.connect(self._on_slider)
        self.slider.sliderPressed.connect(self.dragStarted)
        self.slider.sliderReleased.connect(self.dragFinished)
        self.spin.valueChanged.connect(self._on_spin)

    def value(self) -> float:
        """Return the spin box value."""
        return float(self.spin.value())

    def set_value(self, value: float) -> None:
        """Show ``value`` without emitting :attr:`valueEdited`.

        A value outside the slider's range (typed, or set by undo) widens the range, unless the
        slider is being dragged.
        """
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
        v = self.lo + (self.hi - self.lo) * pos / SLIDER_STEPS
        return float(round(v)) if self.integer else v

    def _on_slider(self, pos: int) -> None:
        value = self._from_slider(pos)
        self.spin.blockSignals(True)
        self.spin.setValue(int(value) if self.integer else value)
        self.spin.blockSignals(False)
        self.valueEdited.emit(self.key, value)

    def _on_spin(self, value: float) -> None:
        self.slider.blockSignals(True)
        self.slider.setValue(self._to_slider(value))
        self.slider.blockSignals(False)
        self.valueEdited.emit(self.key, float(value))


class ParamsPanel(QWidget):
    """The dock content: one :class:`ParamRow` per parameter, in a scroll area.

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
        self._kinds: list[tuple[str, str]] = []
        self._scroll = QScrollArea(self)
        self._scroll.setWidgetResizable(True)
        self._empty = QLabel("Open an SVG or .lsys file to edit its parameters.", self)
        self._empty.setWordWrap(True)
        self._empty.setAlignment(Qt.AlignmentFlag.AlignCenter)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self._empty)
        layout.addWidget(self._scroll, 1)
        self._scroll.hide()

    def set_params(self, params: list) -> None:
        """Show ``params`` (``Param(key, label, value, kind)``): update values, or rebuild rows
        when the set of parameters changed."""
        kinds = [(p.key, p.kind) for p in params]
        if kinds == self._kinds:
            for p in params:
                row = self.rows[p.key]
                if not row.slider.isSliderDown() and not row.spin.hasFocus():
                    row.set_value(p.value)
                elif row.slider.isSliderDown():
                    row.spin.blockSignals(True)
                    row.spin.setValue(round(p.value) if row.integer else p.value)
                    row.spin.blockSignals(False)
            return
        self._kinds = kinds
        self.rows = {}
        content = QWidget()
        form = QFormLayout(content)
        form.setFieldGrowthPolicy(QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
        for p in params:
            row = ParamRow(p, content)
            row.valueEdited.connect(self.paramEdited)
            row.dragStarted.connect(self.dragStarted)
            row.dragFinished.connect(self.dragFinished)
            label = QLabel(p.label, content)
            label.setToolTip(f"{p.key} ({p.kind.replace('_', ' ')})")
            form.addRow(label, row)
            self.rows[p.key] = row
        self._scroll.setWidget(content)
        self._scroll.setVisible(bool(params))
        self._empty.setVisible(not params)
        if not params:
            self._empty.setText("These rules have no numeric parameters.")
