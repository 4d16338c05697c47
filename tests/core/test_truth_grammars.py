"""Hand-written .lsys files of the corpus truth derive the corpus SVGs (issue acceptance)."""

from __future__ import annotations

import pytest

from lsys_core.derive.derivation import derive
from lsys_core.grammar import parse_grammar
from lsys_core.render.svg import export_svg

from .shared import CORPUS, ROOT, compare_svg, need


@pytest.mark.parametrize("name", ["helix", "branching"])
def test_truth_lsys_reproduces_corpus(name, tmp_path) -> None:
    svg = need(CORPUS / f"{name}.svg")
    g = parse_grammar((ROOT / "tests" / "data" / f"{name}_truth.lsys").read_text())
    out = tmp_path / "out.svg"
    export_svg(derive(g), out)
    res = compare_svg()(str(svg), str(out))
    assert res["output_elements"] == res["input_elements"]
    assert res["hausdorff_rel"] <= 0.005
