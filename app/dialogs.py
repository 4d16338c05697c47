"""Dialogs of the editor: randomize amounts and seed, replace a symbol.

They only collect choices; the main window turns them into document edits.
"""

from __future__ import annotations

import random
from dataclasses import dataclass
from typing import Any

from PySide6.QtCore import QSize, Signal
from PySide6.QtGui import QIcon
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from lsys_core.grammar.model import Randomize

__all__ = ["RandomizeDialog", "ReplaceChoice", "ReplaceDialog"]

SEED_MAX = 2**31 - 1
THUMB = 32


def _icon(path: str, style: str) -> QIcon:
    """Return a thumbnail icon of a shape (empty if it cannot be drawn)."""
    from lsys_core.errors import LsysError
    from lsys_core.grammar.model import Terminal

    from .rule_card import thumbnail

    try:
        return QIcon(thumbnail(Terminal("T", path, style), THUMB))
    except (LsysError, ValueError):
        return QIcon()


class RandomizeDialog(QDialog):
    """Amounts of random perturbation (angle in degrees, distance and scale as fractions), a seed
    and whether each instance moves on its own or the perturbation accumulates along a sequence.

    *Apply* and *Re-roll* (a new seed) preview the shown values on the canvas; *OK* keeps
    them (one undo step, saved in the ``.lsys`` file), *Cancel* returns to the rules' own.

    Signals
    -------
    applied(randomize)
        Emitted on Re-roll and Apply with the shown :class:`~lsys_core.grammar.model.Randomize`.
    """

    applied = Signal(object)

    def __init__(self, current: Randomize | None, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Randomize")
        self.initial = current
        r = current or Randomize(angle=5.0, distance=0.05, scale=0.02, seed=1, jitter="instance")
        self.angle = self._spin(0, 180, r.angle, 1.0, " °")
        self.distance = self._spin(0, 1, r.distance, 0.01, "")
        self.scale = self._spin(0, 1, r.scale, 0.01, "")
        self.seed = QSpinBox(self)
        self.seed.setRange(0, SEED_MAX)
        self.seed.setValue(int(r.seed))
        self.jitter = QComboBox(self)
        self.jitter.addItem("Each instance on its own", "instance")
        self.jitter.addItem("Cumulative (drifts along a sequence)", "cumulative")
        self.jitter.setCurrentIndex(max(0, self.jitter.findData(r.jitter)))
        reroll = QPushButton("Re-roll", self)
        reroll.clicked.connect(self.reroll)
        seed_row = QHBoxLayout()
        seed_row.addWidget(self.seed, 1)
        seed_row.addWidget(reroll)
        form = QFormLayout()
        form.addRow("Angle (± degrees)", self.angle)
        form.addRow("Distance (± fraction)", self.distance)
        form.addRow("Scale (± fraction)", self.scale)
        form.addRow("Seed", seed_row)
        form.addRow("Jitter", self.jitter)
        buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Ok
            | QDialogButtonBox.StandardButton.Apply
            | QDialogButtonBox.StandardButton.Cancel,
            self,
        )
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        buttons.button(QDialogButtonBox.StandardButton.Apply).clicked.connect(self.apply)
        layout = QVBoxLayout(self)
        layout.addWidget(
            QLabel("Every instance drawn by a rule is perturbed by a seeded random amount.", self)
        )
        layout.addLayout(form)
        layout.addWidget(buttons)

    def _spin(self, low: float, high: float, value: float, step: float, suffix: str) -> QDoubleSpinBox:
        spin = QDoubleSpinBox(self)
        spin.setRange(low, high)
        spin.setDecimals(3)
        spin.setSingleStep(step)
        spin.setSuffix(suffix)
        spin.setValue(value)
        return spin

    def value(self) -> Randomize:
        """Return the randomization shown."""
        return Randomize(
            angle=self.angle.value(),
            distance=self.distance.value(),
            scale=self.scale.value(),
            seed=self.seed.value(),
            jitter=self.jitter.currentData(),
        )

    def apply(self) -> None:
        """Emit the shown randomization."""
        self.applied.emit(self.value())

    def reroll(self) -> None:
        """Pick a new seed and apply it."""
        seed = self.seed.value()
        while seed == self.seed.value():
            seed = random.randint(0, SEED_MAX)
        self.seed.setValue(seed)
        self.apply()


@dataclass(frozen=True)
class ReplaceChoice:
    """What to replace by what.

    ``kind`` is ``"terminal"`` (``target`` is a terminal; the shape comes from ``path``/``style``)
    or ``"nonterminal"`` (``target`` is a rule's non-terminal, replaced by terminal ``terminal``).
    """

    kind: str
    target: str
    terminal: str = ""
    path: str = ""
    style: str = ""


class ReplaceDialog(QDialog):
    """Pick a symbol of the grammar and what replaces it.

    A terminal can take the shape of another terminal, of an element of the input (its
    similarity groups' representatives) or of a shape loaded from an SVG file; a non-terminal
    can be replaced by a terminal (the paper's Fig. 11).

    Parameters
    ----------
    grammar : Grammar
        The current grammar.
    input_terminals : sequence of Terminal
        Shapes of the input's similarity groups (may be empty).
    load_shape : callable, optional
        ``load_shape(path) -> (path_d, style)`` for *From SVG file…*; raises ``LsysError``.
    """

    def __init__(
        self,
        grammar: Any,
        input_terminals=(),
        load_shape=None,
        parent: QWidget | None = None,
        *,
        target: str | None = None,
    ) -> None:
        super().__init__(parent)
        self.setWindowTitle("Replace symbol")
        self.grammar = grammar
        self._load_shape = load_shape
        self._sources: list[tuple[str, str, str, str]] = []  # (label, terminal name, path, style)
        for t in grammar.terminals:
            self._sources.append((f"terminal {t.name}", t.name, t.path, t.style))
        for i, t in enumerate(input_terminals):
            self._sources.append((f"input element group {i + 1}", "", t.path, t.style))
        self.target = QComboBox(self)
        self.target.setIconSize(QSize(THUMB, THUMB))
        for t in grammar.terminals:
            self.target.addItem(_icon(t.path, t.style), f"{t.name} (terminal)", ("terminal", t.name))
        for r in grammar.rules:
            self.target.addItem(f"{r.name} (non-terminal)", ("nonterminal", r.name))
        self.source = QComboBox(self)
        self.source.setIconSize(QSize(THUMB, THUMB))
        self.load_button = QPushButton("From SVG file…", self)
        self.load_button.clicked.connect(self._load_file)
        self.error = QLabel(self)
        self.error.setStyleSheet("color: #c62828;")
        self.error.setWordWrap(True)
        row = QHBoxLayout()
        row.addWidget(self.source, 1)
        row.addWidget(self.load_button)
        form = QFormLayout()
        form.addRow("Replace", self.target)
        form.addRow("By", row)
        buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel, self
        )
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        self._ok = buttons.button(QDialogButtonBox.StandardButton.Ok)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(self.error)
        layout.addWidget(buttons)
        self.target.currentIndexChanged.connect(self._fill_sources)
        if target is not None:
            for i in range(self.target.count()):
                if self.target.itemData(i) == ("terminal", target):
                    self.target.setCurrentIndex(i)
        self._fill_sources()

    def _fill_sources(self, _index: int = 0) -> None:
        kind, name = self.target.currentData() or ("terminal", "")
        self.source.clear()
        for i, (label, term, path, style) in enumerate(self._sources):
            if kind == "nonterminal" and not term:
                continue  # a non-terminal is replaced by a terminal of the grammar
            if kind == "terminal" and term == name:
                continue
            self.source.addItem(_icon(path, style), label, i)
        self.load_button.setEnabled(kind == "terminal" and self._load_shape is not None)
        self._ok.setEnabled(self.source.count() > 0)

    def _load_file(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Shape from SVG", "", "SVG files (*.svg)")
        if path:
            self.add_shape_from(path)

    def add_shape_from(self, path: str) -> bool:
        """Add the shape of the SVG file ``path`` as a source and select it."""
        from lsys_core.errors import LsysError

        try:
            d, style = self._load_shape(path)
        except LsysError as exc:
            self.error.setText(str(exc))
            return False
        self.error.clear()
        self._sources.append((f"shape from {path.rsplit('/', 1)[-1]}", "", d, style))
        self._fill_sources()
        self.source.setCurrentIndex(self.source.count() - 1)
        return True

    def choice(self) -> ReplaceChoice | None:
        """Return the selected replacement (None if nothing can be chosen)."""
        data = self.target.currentData()
        idx = self.source.currentData()
        if data is None or idx is None:
            return None
        kind, name = data
        _, term, path, style = self._sources[idx]
        if kind == "nonterminal":
            return ReplaceChoice("nonterminal", name, terminal=term)
        return ReplaceChoice("terminal", name, path=path, style=style)
