"""The example gallery: every shipped rule file redraws its SVG, and the README's API example runs."""

from __future__ import annotations

import dataclasses
import re
import shutil
from pathlib import Path

import pytest

from lsys_core.derive.derivation import Randomize, derive
from lsys_core.grammar import parse_grammar
from lsys_core.pipeline import symmetrize
from lsys_core.render.svg import drawing_to_svg
from lsys_core.svg.model import Scene
from lsys_core.svg.parse import load_svg, parse_svg
from lsys_core.testing import hausdorff_rel, regularity

from .shared import ROOT

EXAMPLES = ROOT / "resources" / "examples"
SOURCES = EXAMPLES / "sources"
NAMES = sorted(p.stem for p in EXAMPLES.glob("*.svg"))
#: Reproduction tolerance (Hausdorff distance / bounding-box diagonal), as for the corpus.
TOL = 0.005
JITTER_TOL = 0.03


def rules(path: Path):
    return parse_grammar(path.read_text(encoding="utf-8"))


def drawn(grammar, randomize: Randomize | None = None) -> Scene:
    """Derive ``grammar`` and read the result back through the SVG importer."""
    return parse_svg(drawing_to_svg(derive(grammar, randomize=randomize)))


def jitter() -> Randomize:
    """Return the perturbation build.sh applies to the jittered example."""
    script = (EXAMPLES / "build.sh").read_text(encoding="utf-8")
    amounts = re.search(r'^JITTER="([^"]+)"', script, re.M).group(1)
    seed = int(re.search(r"^JITTER_SEED=(\d+)", script, re.M).group(1))
    kw = {k: float(v) for k, v in (part.split("=") for part in amounts.split(","))}
    return Randomize(seed=seed, **kw)


def test_gallery_has_the_six_kinds_with_sources() -> None:
    assert len(NAMES) >= 6
    for kind in ("helix", "branching", "facade", "ornament", "flower", "jitter"):
        assert any(kind in n for n in NAMES), kind
    for name in NAMES:
        assert (EXAMPLES / f"{name}.lsys").is_file(), f"{name}.lsys is not shipped"
        assert (SOURCES / f"{name}.lsys").is_file(), f"sources/{name}.lsys is missing"


@pytest.mark.parametrize("name", NAMES)
def test_shipped_rules_redraw_their_svg(name: str) -> None:
    original = load_svg(EXAMPLES / f"{name}.svg")
    grammar = rules(EXAMPLES / f"{name}.lsys")
    again = drawn(grammar)
    n = len(original.elements)
    assert len(again.elements) == n
    assert hausdorff_rel(original, again) <= (JITTER_TOL if name.startswith("jittered") else TOL)
    assert grammar.production_count <= n / 5, "the inferred rules should be far shorter than the art"


@pytest.mark.parametrize("name", NAMES)
def test_svg_is_the_derivation_of_its_source(name: str) -> None:
    """The shipped SVG is up to date with its hand-written grammar (see build.sh)."""
    randomize = jitter() if name.startswith("jittered") else None
    again = drawn(rules(SOURCES / f"{name}.lsys"), randomize)
    original = load_svg(EXAMPLES / f"{name}.svg")
    assert len(again.elements) == len(original.elements)
    assert hausdorff_rel(original, again) < 1e-5


def test_jittered_example_is_regularised_by_symmetrize() -> None:
    scene = load_svg(EXAMPLES / "jittered-tiles.svg")
    result = symmetrize(scene)
    out = drawn(result.grammar)
    assert len(out.elements) == len(scene.elements)
    assert hausdorff_rel(scene, out) <= 0.05
    assert regularity(out) < 0.2 * regularity(scene)


def test_hausdorff_helper_sees_a_moved_element() -> None:
    scene = load_svg(EXAMPLES / "facade.svg")
    drawing = derive(rules(SOURCES / "facade.lsys"))
    assert hausdorff_rel(scene, parse_svg(drawing_to_svg(drawing))) < 1e-5
    b = drawing.b.copy()
    b[1] += 100j  # the door, 100 px down
    moved = parse_svg(drawing_to_svg(dataclasses.replace(drawing, b=b)))
    assert len(moved.elements) == len(scene.elements)
    assert hausdorff_rel(scene, moved) > 0.1


def python_blocks(doc: Path) -> list[str]:
    """Return the ```python code blocks of a Markdown file."""
    blocks = re.findall(r"```python\n(.*?)```", doc.read_text(encoding="utf-8"), re.S)
    assert blocks, f"{doc.name} has no ```python block"
    return blocks


def run_blocks(doc: Path, where: Path) -> None:
    """Run every Python block of ``doc`` in one namespace, in ``where`` (holding the examples)."""
    shutil.copytree(EXAMPLES, where / "resources" / "examples")
    namespace: dict = {"__name__": doc.stem}
    for block in python_blocks(doc):
        exec(compile(block, str(doc), "exec"), namespace)


def test_readme_api_example_runs(tmp_path, monkeypatch, capsys) -> None:
    monkeypatch.chdir(tmp_path)
    run_blocks(ROOT / "README.md", tmp_path)
    out = capsys.readouterr().out
    assert "axiom:" in out and "->" in out
    assert re.search(r"^\w+\.\d+\.\d+\.v\s", out, re.M), "no parameter keys printed"
    svg, png = tmp_path / "longer-helix.svg", tmp_path / "longer-helix.png"
    assert len(load_svg(svg).elements) == 201
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_api_doc_examples_run(tmp_path, monkeypatch, capsys) -> None:
    monkeypatch.chdir(tmp_path)
    run_blocks(ROOT / "docs" / "api.md", tmp_path)
    out = capsys.readouterr().out
    assert "72 elements ->" in out and "inference cancelled" in out
    assert len(load_svg(tmp_path / "plant.svg").elements) == 31
