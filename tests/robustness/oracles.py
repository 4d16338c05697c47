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

__all__ = [
    "check_css_text",
    "check_lsys_text",
    "check_message",
    "check_path_data",
    "check_scene",
    "check_svg_import",
]


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


_CSS_TREE = (
    '<svg xmlns="http://www.w3.org/2000/svg"><g class="a" id="i"><rect x="1" class="b a"/>'
    '<path id="x" fill="red"/></g><rect/></svg>'
)


def check_css_text(text: str) -> None:
    """Read a style sheet and match it against a small tree, then as a ``style`` attribute.

    The only acceptable failure is a one-line :class:`LsysError` (the matching work limit).
    """
    import xml.etree.ElementTree as ET

    from lsys_core.svg.css import StyleSheet, parse_declarations
    from lsys_core.svg.tree import Tree

    tree = Tree(ET.fromstring(_CSS_TREE))
    sheet = StyleSheet()
    try:
        sheet.add(text)
        for el in tree.root.iter():
            for rule in sheet.matching(el, tree):
                assert all(isinstance(d.value, str) for d in rule.declarations)
        ascii_lower = str.maketrans("ABCDEFGHIJKLMNOPQRSTUVWXYZ", "abcdefghijklmnopqrstuvwxyz")
        for d in parse_declarations(text):
            assert d.name == d.name.translate(ascii_lower)  # CSS names are ASCII case-insensitive
    except LsysError as exc:
        check_message(exc)
    for note in sheet.notes:
        assert "\n" not in note


def check_path_data(text: str) -> None:
    """Read path data strictly, leniently and in a batch; the three must agree."""
    from lsys_core.errors import SvgError
    from lsys_core.geometry.paths import cubics_from_d, path_from_d, paths_from_ds

    path, error = path_from_d(text)
    c = path.cubics
    assert c.ndim == 2 and c.shape[1] == 4 and path.subpaths.shape == (len(c),)
    assert len(path.closed) == (int(path.subpaths.max()) + 1 if len(c) else 0)
    try:
        strict, _, _ = cubics_from_d(text)
    except SvgError as exc:
        check_message(exc)
        assert error is not None
    else:
        assert error is None and np.array_equal(strict, c, equal_nan=True)
    (batched, batch_error), _ = paths_from_ds([text, "M0 0 L1 1"])
    assert batch_error == error
    assert batched.cubics.shape == c.shape
