"""Each documented limit of the SVG reader (docs/limits.md): at the limit it works, one past it fails cleanly.

Limits that are parameters are set small here; module-level limits are lowered with monkeypatch,
so every case stays small and fast.
"""

from __future__ import annotations

import gzip

import pytest

from lsys_core.errors import LimitError, LsysError
from lsys_core.svg import css, pathcache, walk, xmlsafe
from lsys_core.svg.parse import load_svg, parse_svg
from tests.robustness.generators import svg

RECT = '<rect width="1" height="1"/>'


def _refused(data, message: str, **kw) -> None:
    with pytest.raises(LimitError) as info:
        parse_svg(data, **kw)
    assert message in str(info.value)
    assert "\n" not in str(info.value)


def test_file_size(tmp_path):
    text = svg(RECT).encode()
    n = len(text)
    assert parse_svg(text, max_bytes=n).elements
    _refused(text, "is too large", max_bytes=n - 1)
    f = tmp_path / "a.svg"
    f.write_bytes(text)
    assert load_svg(f, max_bytes=n).elements
    with pytest.raises(LimitError, match="too large"):
        load_svg(f, max_bytes=n - 1)


def test_decompressed_size():
    text = svg(RECT).encode()
    packed = gzip.compress(text)
    assert parse_svg(packed, max_bytes=len(text)).elements
    _refused(packed, "decompresses to more than", max_bytes=len(text) - 1)


def test_elements_in_the_file():
    text = svg(RECT * 9)  # the root and 9 rectangles: 10 elements
    assert len(parse_svg(text, max_elements=10).elements) == 9
    _refused(text, "has more than 9 elements", max_elements=9)


def test_nesting_depth():
    text = svg("<g>" * 8 + RECT + "</g>" * 8)  # root, 8 groups, the rectangle: 10 levels
    assert parse_svg(text, max_depth=10).elements
    _refused(text, "nested more than 9 levels deep", max_depth=9)


def _fan(levels: int, width: int) -> str:
    defs = ['<rect id="l0" width="1" height="1"/>']
    for i in range(1, levels + 1):
        defs.append(f'<g id="l{i}">' + f'<use href="#l{i - 1}"/>' * width + "</g>")
    return svg(f"<defs>{''.join(defs)}</defs><use href='#l{levels}'/>")


def test_elements_once_use_is_expanded():
    text = _fan(3, 4)  # 4**3 = 64 rectangles drawn
    size = 1  # the expansion counts every element: rectangles, groups, <use> elements and the root
    for _ in range(3):
        size = 1 + 4 * (1 + size)  # a group of 4 uses of the level below
    total = 1 + (1 + size)  # the root and its <use> of the top level
    assert len(parse_svg(text, max_elements=total).elements) == 64
    _refused(text, f"expands to more than {total - 1:,} elements (<use> fan-out)", max_elements=total - 1)


def test_use_nesting():
    chain = ['<rect id="c0" width="1" height="1"/>'] + [
        f'<use id="c{i}" href="#c{i - 1}"/>' for i in range(1, 20)
    ]
    text = svg(f"<defs>{''.join(chain)}</defs><use href='#c19'/>")  # root, use, 19 uses, rect: 22 levels
    assert parse_svg(text, max_depth=22).elements
    _refused(text, "<use> references nest more than 21 levels deep", max_depth=21)


def test_450_nested_uses_are_fast_or_refused():
    """A chain of 450 levels, each drawing the previous twice: refused from the memoised count."""
    _refused(_fan(450, 2), "expands to more than 200,000 elements")
    chain = ['<rect id="c0" width="1" height="1"/>'] + [
        f'<use id="c{i}" href="#c{i - 1}"/>' for i in range(1, 450)
    ]
    scene = parse_svg(svg(f"<defs>{''.join(chain)}</defs><use href='#c449'/>"))
    assert len(scene.elements) == 1


def test_elements_drawn(monkeypatch):
    marker = '<marker id="m" markerUnits="userSpaceOnUse"><rect width="1" height="1"/></marker>'
    points = " ".join(f"{i},0" for i in range(5))  # 5 vertices: 5 marker instances + the line
    text = svg(
        marker + f'<polyline points="{points}" stroke="black" fill="none" marker-mid="url(#m)" '
        'marker-start="url(#m)" marker-end="url(#m)"/>'
    )
    assert len(parse_svg(text, max_elements=6).elements) == 6
    _refused(text, "draws more than 5 elements", max_elements=5)


def test_numbers_in_path_data(monkeypatch):
    text = svg('<path d="M0 0 L1 1 2 2"/>')  # 6 numbers
    monkeypatch.setattr(pathcache, "DEFAULT_MAX_PATH_NUMBERS", 6)
    assert parse_svg(text).elements
    monkeypatch.setattr(pathcache, "DEFAULT_MAX_PATH_NUMBERS", 5)
    _refused(text, "more than 5 numbers in path data")


def test_path_segments(monkeypatch):
    text = svg('<path d="M0 0 L1 1 2 0 3 1"/>')  # 3 segments
    monkeypatch.setattr(pathcache, "DEFAULT_MAX_SEGMENTS", 3)
    monkeypatch.setattr(walk, "DEFAULT_MAX_SEGMENTS", 3)
    assert parse_svg(text).elements
    monkeypatch.setattr(pathcache, "DEFAULT_MAX_SEGMENTS", 2)
    _refused(text, "has more than 2 path segments")
    monkeypatch.setattr(pathcache, "DEFAULT_MAX_SEGMENTS", 100)
    monkeypatch.setattr(walk, "DEFAULT_MAX_SEGMENTS", 5)  # drawn twice through <use>: 6 segments
    used = svg('<path id="p" d="M0 0 L1 1 2 0 3 1"/><use href="#p" x="5"/>')
    _refused(used, "draws more than 5 path segments")


def _entities(n: int, uses: int = 1) -> str:
    decls = "".join(f'<!ENTITY e{i} "x">' for i in range(n))
    refs = "&e0;" * uses
    return f"<!DOCTYPE svg [{decls}]>" + svg(f'<rect width="1" height="1" data-x="{refs}"/>')


def test_entity_declarations(monkeypatch):
    monkeypatch.setattr(xmlsafe, "MAX_ENTITIES", 3)
    assert parse_svg(_entities(3)).elements
    _refused(_entities(4), "declares more than 3 entities")


def test_entity_expansion(monkeypatch):
    monkeypatch.setattr(xmlsafe, "MAX_ENTITY_EXPANSION", 10)
    assert parse_svg(_entities(1, uses=10)).elements
    _refused(_entities(1, uses=11), "entity references expand to more than 10 bytes")


def test_css_matching_work(monkeypatch):
    sheet = "<style>g g g rect { fill: red }</style>"
    text = svg(sheet + "<g>" * 4 + RECT + "</g>" * 4)
    steps = []
    original = css.StyleSheet._match

    def counting(self, *a):
        steps.append(1)
        return original(self, *a)

    monkeypatch.setattr(css.StyleSheet, "_match", counting)
    parse_svg(text)
    needed = len(steps)
    monkeypatch.setattr(css.StyleSheet, "_match", original)
    monkeypatch.setattr(css, "MAX_MATCH_WORK", needed)
    assert parse_svg(text).elements
    monkeypatch.setattr(css, "MAX_MATCH_WORK", needed - 1)
    _refused(text, f"need more than {needed - 1:,} steps to match")


@pytest.mark.parametrize("what", ["string", "comment", "block"])
def test_megabyte_of_unterminated_css(what):
    """An unterminated string, comment or block of 1 MB ends in one pass (speed: make bench)."""
    body = {
        "string": "rect { fill: 'red" + "x" * 1_000_000,
        "comment": "/*" + "x" * 1_000_000,
        "block": "rect { fill: red; " + "x:y;" * 250_000,
    }[what]
    scene = parse_svg(svg(f"<style>{body}</style>" + RECT))
    assert len(scene.elements) == 1


def test_errors_are_lsys_errors():
    for bad in (b"", svg("<g>" * 600 + "</g>" * 600), _fan(30, 3)):
        with pytest.raises(LsysError):
            parse_svg(bad)
