"""What a robust importer or parser must do with any input: the checks shared by tests and fuzzer.

Each ``check_*`` function feeds one input to the library and fails with :class:`AssertionError`
unless the outcome is acceptable: a clean result (checked for invariants) or one of the
project's own errors with a one-line message.  Any other exception propagates and is a bug.
"""

from __future__ import annotations

import numpy as np

from lsys_core.errors import GrammarSyntaxError, LsysError
from lsys_core.geometry.paths import MAX_COORD
from lsys_core.grammar import Grammar, format_grammar, parse_grammar
from lsys_core.svg.model import Scene
from lsys_core.svg.parse import parse_svg

__all__ = ["check_lsys_text", "check_message", "check_scene", "check_svg_import"]


def check_message(exc: LsysError) -> None:
    """Assert that an error reads as one non-empty line."""
    text = str(exc)
    assert text.strip(), f"empty message from {type(exc).__name__}"
    assert "\n" not in text and "\r" not in text, f"multi-line message: {text!r}"
    assert "Traceback" not in text


def check_scene(scene: Scene) -> None:
    """Assert the invariants of an imported scene: something drawable, finite and bounded geometry."""
    assert scene.elements, "a scene without elements must be an SvgError"
    for el in scene.elements:
        c = el.cubics
        assert c.ndim == 2 and c.shape[1] == 4 and len(c) > 0 and c.dtype == complex
        assert np.isfinite(c).all(), f"non-finite coordinates in {el.source}"
        assert np.abs(c).max() <= MAX_COORD, f"huge coordinates in {el.source}"
        assert el.subpaths.shape == (len(c),)
        assert len(el.closed) == int(el.subpaths.max()) + 1
        assert isinstance(el.style, str) and "nan" not in el.style and "inf" not in el.style
    if scene.viewbox is not None:
        x, y, w, h = scene.viewbox
        assert np.isfinite([x, y, w, h]).all() and w > 0 and h > 0
    for w in scene.warnings:
        assert "\n" not in w


def check_svg_import(data: bytes | str, *, max_elements: int = 20_000) -> Scene | None:
    """Import ``data``; return the scene, or None after a clean one-line :class:`LsysError`."""
    try:
        scene = parse_svg(data, max_elements=max_elements)
    except LsysError as exc:
        check_message(exc)
        return None
    check_scene(scene)
    return scene


def check_lsys_text(text: str) -> Grammar | None:
    """Parse ``text``; return the grammar (which must format and parse back equal) or None.

    The only acceptable failure is a :class:`GrammarSyntaxError` whose line and column lie
    inside the text (or just past its end).
    """
    try:
        g = parse_grammar(text)
    except GrammarSyntaxError as exc:
        check_message(exc)
        lines = text.splitlines() or [""]
        assert 1 <= exc.line <= len(lines) + 1, (exc.line, len(lines))
        assert exc.column >= 1
        assert str(exc).startswith(f"{exc.line}:{exc.column}: ")
        return None
    back = parse_grammar(format_grammar(g))
    assert back == g
    return g
