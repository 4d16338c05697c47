"""The inference panel: importance weights, similarity threshold and clustering tolerance.

Moving a slider forwards new ``InferenceSettings`` to the document, which re-runs inference in
the background (debounced; the previous run is cancelled).  The panel shows one progress bar
per pipeline stage as the stages report, and a Cancel button.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QProgressBar,
    QPushButton,
    QSlider,
    QVBoxLayout,
    QWidget,
)

from lsys_core.settings import SETTINGS, Setting

__all__ = ["InferencePanel"]

_STEPS = 1000


class _SettingRow(QWidget):
    """A slider and spin box over ``[low, high]`` for one settings field."""

    edited = Signal(str, float)

    def __init__(self, spec: Setting, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.name, self.low, self.high = spec.name, spec.slider_low(), spec.slider_high
        self.slider = QSlider(Qt.Orientation.Horizontal, self)
        self.slider.setRange(0, _STEPS)
        self.spin = QDoubleSpinBox(self)
        self.spin.setRange(self.low, spec.high)  # typed values may go beyond the slider
        low, high = self.low, self.high
        self.spin.setDecimals(3)
        self.spin.setSingleStep((high - low) / 100)
        self.spin.setKeyboardTracking(False)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.slider, 1)
        layout.addWidget(self.spin)
        self.slider.valueChanged.connect(self._on_slider)
        self.spin.valueChanged.connect(self._on_spin)

    def set_value(self, value: float) -> None:
        """Show ``value`` without emitting :attr:`edited`."""
        for w in (self.slider, self.spin):
            w.blockSignals(True)
        self.spin.setValue(value)
        self.slider.setValue(round((value - self.low) / (self.high - self.low) * _STEPS))
        for w in (self.slider, self.spin):
            w.blockSignals(False)

    def _on_slider(self, pos: int) -> None:
        value = self.low + (self.high - self.low) * pos / _STEPS
        self.spin.blockSignals(True)
        self.spin.setValue(value)
        self.spin.blockSignals(False)
        self.edited.emit(self.name, value)

    def _on_spin(self, value: float) -> None:
        self.slider.blockSignals(True)
        self.slider.setValue(round((value - self.low) / (self.high - self.low) * _STEPS))
        self.slider.blockSignals(False)
        self.edited.emit(self.name, value)


class InferencePanel(QWidget):
    """The dock content: settings sliders, per-stage progress, Cancel and Re-infer.

    Signals
    -------
    settingsEdited(settings)
        New ``InferenceSettings`` (a copy of the shown ones with one field changed).
    dragStarted(), dragFinished(), cancelRequested(), reinferRequested()
    """

    settingsEdited = Signal(object)
    dragStarted = Signal()
    dragFinished = Signal()
    cancelRequested = Signal()
    reinferRequested = Signal()

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._settings: Any = None
        self.rows: dict[str, _SettingRow] = {}
        weights = self.weights_box = QGroupBox("Cluster importance and similarity", self)
        form = QFormLayout(weights)
        for spec in SETTINGS:
            name = spec.name
            row = _SettingRow(spec, weights)
            row.setToolTip(f"{spec.help[0].upper()}{spec.help[1:]}, in {spec.range_text()}")
            row.edited.connect(self._on_edited)
            row.slider.sliderPressed.connect(self.dragStarted)
            row.slider.sliderReleased.connect(self.dragFinished)
            form.addRow(QLabel(spec.label, weights), row)
            self.rows[name] = row
        self._progress_box = QGroupBox("Progress", self)
        self._progress_form = QFormLayout(self._progress_box)
        self.bars: dict[str, QProgressBar] = {}
        self.status = QLabel("Idle", self)
        self.cancel_button = QPushButton("Cancel", self)
        self.cancel_button.setEnabled(False)
        self.cancel_button.clicked.connect(self.cancelRequested)
        self.reinfer_button = QPushButton("Re-infer", self)
        self.reinfer_button.clicked.connect(self.reinferRequested)
        buttons = QHBoxLayout()
        buttons.addWidget(self.status, 1)
        buttons.addWidget(self.reinfer_button)
        buttons.addWidget(self.cancel_button)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.addWidget(weights)
        layout.addWidget(self._progress_box)
        layout.addLayout(buttons)
        layout.addStretch(1)

    def set_settings(self, settings: Any) -> None:
        """Show ``settings`` (fields it does not have are disabled)."""
        self._settings = settings
        names = {f.name for f in dataclasses.fields(settings)} if settings is not None else set()
        for name, row in self.rows.items():
            row.setEnabled(name in names)
            if name in names and not row.slider.isSliderDown():  # never move a slider under the mouse
                row.set_value(float(getattr(settings, name)))
            elif name in names:
                self._settings = dataclasses.replace(self._settings, **{name: row.spin.value()})

    def set_editable(self, editable: bool) -> None:
        """Enable the settings and Re-infer (there is an input to infer from); Cancel stays usable."""
        self.weights_box.setEnabled(editable)
        self.reinfer_button.setEnabled(editable)

    def set_running(self, running: bool) -> None:
        """Enable Cancel while inference runs; reset the stage bars when a run starts."""
        self.cancel_button.setEnabled(running)
        if running:
            for bar in self.bars.values():
                bar.setValue(0)
            self.status.setText("Inferring…")
        else:
            self.status.setText("Idle")

    def set_progress(self, stage: str, fraction: float) -> None:
        """Show the progress of one stage (a bar is added the first time a stage reports)."""
        if stage == "done":
            self.status.setText("Finishing…")
            return
        bar = self.bars.get(stage)
        if bar is None:
            bar = QProgressBar(self._progress_box)
            bar.setRange(0, 1000)
            bar.setTextVisible(True)
            bar.setFormat("%p%")
            self._progress_form.addRow(QLabel(stage.replace("_", " "), self._progress_box), bar)
            self.bars[stage] = bar
        bar.setValue(round(fraction * 1000))
        self.status.setText(f"{stage.replace('_', ' ')}…")

    def _on_edited(self, name: str, value: float) -> None:
        if self._settings is None:
            return
        self._settings = dataclasses.replace(self._settings, **{name: value})
        self.settingsEdited.emit(self._settings)
