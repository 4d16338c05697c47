"""Published SVGs (spinners, loaders) and the public corpus: inferred rules redraw them.

The geometric check samples both scenes with lsys_core's own importer, which applies every
transform (``rotate(a cx cy)`` on rects and circles included).
"""

from __future__ import annotations

import json

import pytest

from lsys_core.derive.derivation import derive
from lsys_core.pipeline import infer
from lsys_core.svg.parse import load_svg
from lsys_core.testing import assert_scenes_close, drawing_scene

from .shared import CORPUS, REALWORLD

REALWORLD_FILES = sorted(p.name for p in REALWORLD.glob("*.svg")) if REALWORLD.exists() else []
CORPUS_FILES = sorted(p.stem for p in CORPUS.glob("*.json")) if CORPUS.exists() else []


@pytest.mark.parametrize("name", REALWORLD_FILES)
def test_realworld_is_reproduced(name: str) -> None:
    scene = load_svg(REALWORLD / name)
    result = infer(scene)
    assert_scenes_close(scene, drawing_scene(derive(result.grammar)), 0.005)
    if len(result.instancing.terminals) == 1 and len(scene.elements) >= 5:
        assert result.grammar.production_count < len(scene.elements)


@pytest.mark.parametrize("name", CORPUS_FILES)
def test_corpus_case(name: str) -> None:
    truth = json.loads((CORPUS / f"{name}.json").read_text())
    scene = load_svg(CORPUS / f"{name}.svg")
    result = infer(scene)
    assert_scenes_close(scene, drawing_scene(derive(result.grammar)), truth["tol"])
    if truth.get("max_rules") is not None:
        assert result.grammar.production_count <= truth["max_rules"]
