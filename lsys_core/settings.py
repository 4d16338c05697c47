"""The user settings of the inference: one definition of each, read by the pipeline, CLI and editor.

Each :class:`Setting` names a field of :class:`~lsys_core.pipeline.InferenceSettings` with its
default, its valid range and the words a user interface shows for it.  The range is the one
the pipeline validates (:func:`check`), so a slider built over it never offers a value the
pipeline refuses.  The module imports nothing, so a user interface can read it at once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["SETTINGS", "Setting", "check", "setting"]


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
