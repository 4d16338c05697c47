"""Two squares of different sizes: the derived drawing keeps each one's size (the deviation check)."""

from __future__ import annotations

from lsys_core.derive.derivation import derive
from lsys_core.pipeline import infer
from lsys_core.svg.parse import parse_svg
from lsys_core.testing import assert_scenes_close, drawing_scene


def test_a_square_and_a_larger_stroked_square_keep_their_sizes():
    scene = parse_svg(
        b'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 200 200">'
        b'<rect x="20" y="20" width="160" height="160" fill="green"/>'
        b'<rect x="1" y="1" width="198" height="198" fill="none" stroke="black" stroke-width="2"/></svg>'
    )
    result = infer(scene)
    assert_scenes_close(drawing_scene(derive(result.grammar)), scene)
