"""The user settings of the inference: one definition of each, read by the pipeline, CLI and editor.

Each :class:`Setting` names a field of :class:`InferenceSettings` with its default, its valid
range and the words a user interface shows for it.  The range is the one
:meth:`InferenceSettings.validated` checks (:func:`check`), so a slider built over it never
offers a value the pipeline refuses.  The module imports nothing heavy (no numpy), so a user
interface can read it at once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from lsys_core.errors import InferenceError

__all__ = ["RELAXED", "SETTINGS", "InferenceSettings", "Setting", "check", "setting"]

#: Bandwidth factor used by :func:`~lsys_core.pipeline.symmetrize` (the paper's "relaxed sensitivity").
RELAXED = 12.0


@dataclass(frozen=True)
class Setting:
    """One inference setting.

    Attributes
    ----------
    name : str
        Field name in ``InferenceSettings`` and CLI option (``--wn``).
    default : float
        Default value.
    low, high : float
        Valid range; ``low`` itself is excluded when ``low_open``.
    slider_high : float
        Upper end of a slider over the setting (at most ``high``; typed values may go beyond).
    low_open : bool
        Whether ``low`` is excluded from the range.
    label : str
        Short name for a user interface (``"wₙ  repetition"``).
    help : str
        One sentence for a tooltip or ``--help``.
    """

    name: str
    default: float
    low: float
    high: float
    slider_high: float
    low_open: bool
    label: str
    help: str

    def contains(self, value: float) -> bool:
        """Whether ``value`` is a finite number in the valid range."""
        if not math.isfinite(value) or value > self.high:
            return False
        return value > self.low if self.low_open else value >= self.low

    def range_text(self) -> str:
        """Return the range in interval notation, e.g. ``(0, 1000]``."""
        return f"{'(' if self.low_open else '['}{_short(self.low)}, {_short(self.high)}]"

    def slider_low(self) -> float:
        """Return the lower end of a slider: ``low``, or a little above it when ``low`` is excluded."""
        return self.low + 0.01 * (self.slider_high - self.low) if self.low_open else self.low


SETTINGS: tuple[Setting, ...] = (
    Setting("wn", 0.3, 0.0, 1.0, 1.0, False, "w\u2099  repetition", "weight of the repetition count n"),
    Setting("wh", 1.0, 0.0, 1.0, 1.0, False, "w\u2095  proximity", "weight of proximity h"),
    Setting("wphi", 0.3, 0.0, 1.0, 1.0, False, "w\u03c6  similarity", "weight of similarity \u03c6"),
    Setting("wl", 0.3, 0.0, 1.0, 1.0, False, "w\u2097  length", "weight of the sequence length l"),
    Setting(
        "similarity",
        0.6,
        0.0,
        1.0,
        1.0,
        True,
        "Similarity threshold",
        "similarity threshold \u03c6 for two elements to share a terminal",
    ),
    Setting(
        "tolerance",
        1.0,
        1e-6,  # below it no two transformations share a cluster anyway (and grids would overflow)
        1000.0,
        5.0,
        False,
        "Clustering tolerance",
        "factor on the clustering bandwidths; larger values merge jittered repetitions",
    ),
)
"""Every user setting, in the order a user interface lists them."""


def setting(name: str) -> Setting:
    """Return the :class:`Setting` called ``name`` (``KeyError`` if there is none)."""
    for s in SETTINGS:
        if s.name == name:
            return s
    raise KeyError(name)


def check(name: str, value: float) -> str | None:
    """Return a one-line problem with ``value`` for setting ``name``, or None when it is valid."""
    s = setting(name)
    if s.contains(value):
        return None
    return f"{name} must be in {s.range_text()}, got {_short(value)}"


def _short(x: float) -> str:
    """Return ``x`` in few characters: ``1``, ``0.6``, ``1e-6``."""
    return f"{x:g}".replace("e-0", "e-").replace("e+0", "e+")


@dataclass(frozen=True)
class InferenceSettings:
    """User settings of the inference.

    Attributes
    ----------
    wn, wh, wphi, wl : float
        Cluster importance weights in [0, 1] (§5.4): repetition count, proximity,
        similarity and sequence length.
    similarity : float
        Similarity threshold φ for two elements to share a terminal (§4.1).
    tolerance : float
        Factor on the clustering bandwidths; larger values merge jittered repetitions.
    neighbours : int
        Neighbours per node in the transformation spaces.
    deviation : float or None
        The tolerance: how far (document units) the derived drawing may deviate from the
        input, shapes and placements together.  Near-identical shapes within it share a
        terminal, and rules must place their elements within it.  None: 0.5 % of the
        drawing's diagonal (:data:`lsys_core.pipeline.DEFAULT_DEVIATION`); 0: exact copies only.
    """

    wn: float = setting("wn").default
    wh: float = setting("wh").default
    wphi: float = setting("wphi").default
    wl: float = setting("wl").default
    similarity: float = setting("similarity").default
    tolerance: float = setting("tolerance").default
    neighbours: int = 24
    deviation: float | None = None

    def relaxed(self, factor: float = RELAXED) -> InferenceSettings:
        """Return these settings with the tolerance multiplied by ``factor`` (for symmetrization)."""
        return replace(self, tolerance=self.tolerance * factor)

    def validated(self) -> InferenceSettings:
        """Return the settings, raising :class:`InferenceError` for values out of range.

        The ranges are those of :data:`SETTINGS` (which the editor's sliders
        and the CLI's help show too).
        """
        for s in SETTINGS:
            problem = check(s.name, float(getattr(self, s.name)))
            if problem is not None:
                raise InferenceError(problem)
        if self.deviation is not None and not (0.0 <= self.deviation < math.inf):
            raise InferenceError(f"deviation must be a length >= 0, got {self.deviation:g}")
        return self
