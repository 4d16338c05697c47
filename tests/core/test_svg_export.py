"""Tests of path data output, sampling and SVG export (including import → export → import round trips)."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from lsys_core.derive.model import Drawing
from lsys_core.errors import LsysError
from lsys_core.geometry import cubics_from_d, d_from_cubics, sample_cubics, sample_uniform
from lsys_core.grammar.model import Terminal
from lsys_core.render import drawing_bounds, drawing_to_structured_svg, drawing_to_svg, export_svg
from lsys_core.svg import load_svg, parse_svg

from .scenes import make_drawing

SHARED = Path(__file__).resolve().parents[2].parent / "shared"
SVG_NS = "{http://www.w3.org/2000/svg}"


@pytest.fixture
def shared() -> Path:
    """The shared input folder beside the repository (skip when absent)."""
    if not SHARED.is_dir():
        pytest.skip("../shared is not present")
    return SHARED


def drawing_of(terminals, symbol, a, b, viewbox=None, size=None) -> Drawing:
    return make_drawing(terminals, symbol, a, b, viewbox, size, rule=-1)


def identity_drawing(scene) -> Drawing:
    """A drawing whose instances are the scene's elements themselves (identity poses)."""
    terms = [
        Terminal(f"T{i}", d_from_cubics(e.cubics, e.subpaths, e.closed), e.style)
        for i, e in enumerate(scene.elements)
    ]
    n = len(terms)
    return drawing_of(terms, np.arange(n), np.ones(n), np.zeros(n), scene.viewbox, scene.size)


# ---------------------------------------------------------------------------
# Path data


def test_rect_stays_lines_and_z():
    c, sub, closed = cubics_from_d("M0 0 H10 V5 H0 Z")
    assert d_from_cubics(c, sub, closed) == "M0 0 L10 0 L10 5 L0 5 Z"


def test_open_and_multiple_subpaths():
    d = "M0 0 C1 2 3 4 5 5 L7 1 M20 20 L30 20 L25 28 Z"
    c, sub, closed = cubics_from_d(d)
    assert closed == (False, True)
    assert d_from_cubics(c, sub, closed) == d


def test_closed_curve_ending_at_start_keeps_curve():
    d = "M0 0 C6 -6 16 -5 22 0 C15 3 6 6 0 0 Z"
    c, sub, closed = cubics_from_d(d)
    assert len(c) == 2
    assert d_from_cubics(c, sub, closed) == d


def test_numbers_are_precise_and_compact():
    rng = np.random.default_rng(3)
    c = (rng.normal(size=(50, 4)) + 1j * rng.normal(size=(50, 4))) * 10.0 ** rng.uniform(-3, 5, size=(50, 1))
    sub = np.arange(50)  # separate subpaths: each segment writes all its points
    d = d_from_cubics(c, sub, [False] * 50)
    back, sub2, closed2 = cubics_from_d(d)
    assert (sub2 == sub).all() and closed2 == (False,) * 50
    rel = np.abs(back - c) / np.abs(c)
    assert rel.max() < 1e-6
    mantissas = [
        t.lstrip("-").split("e")[0].replace(".", "").lstrip("0") for t in re.findall(r"[-\d.e+]+", d)
    ]
    assert max(len(m) for m in mantissas) <= 9
    assert "-0 " not in d


def test_tiny_noise_written_as_zero():
    c = np.array([[0, 1 / 3, 2 / 3, 1]], dtype=complex) * 100 + 1e-15j
    assert d_from_cubics(c, [0], [False]) == "M0 0 L100 0"


def test_empty_path_data():
    assert d_from_cubics(np.zeros((0, 4), complex), np.zeros(0, int), ()) == ""


def test_sample_cubics_and_uniform():
    c, _, _ = cubics_from_d("M0 0 L10 0 L10 30")
    s = sample_cubics(c, 5)
    assert s.shape == (10,)
    assert s[0] == 0 and s[4] == 10 and s[-1] == 10 + 30j
    u = sample_uniform(c, 41)
    assert u[0] == 0 and u[-1] == pytest.approx(10 + 30j)
    steps = np.abs(np.diff(u))
    assert steps == pytest.approx(np.full(40, 1.0), abs=1e-9)


def test_sample_uniform_on_curve_and_across_subpaths():
    c, _, _ = cubics_from_d("M0 0 C0 10 20 10 20 0 M100 100 L110 100")
    u = sample_uniform(c, 200)
    # Uniform along the curve: nearly equal steps except the one jump between subpaths.
    steps = np.sort(np.abs(np.diff(u)))[:-1]
    assert steps.max() / steps.min() < 1.01
    assert u[-1] == pytest.approx(110 + 100j)


# ---------------------------------------------------------------------------
# Export


def test_export_structure_and_matrix_order():
    leaf = Terminal("A", "M0 0 L10 0 L10 2 Z", 'fill:#2e7d32;font-family:"a&b"')
    a = np.array([2 * np.exp(1j * np.pi / 6), 1.0])
    b = np.array([5 + 7j, -3 - 4j])
    text = drawing_to_svg(drawing_of([leaf], [0, 0], a, b, (0, 0, 50, 40), ("50mm", "40mm")))
    root = ET.fromstring(text)
    assert root.tag == SVG_NS + "svg"
    assert root.get("viewBox") == "0 0 50 40"
    assert (root.get("width"), root.get("height")) == ("50mm", "40mm")
    paths = root.findall(SVG_NS + "path")
    assert len(paths) == 2
    assert paths[0].get("d") == leaf.path
    assert paths[0].get("style") == leaf.style
    nums = [float(v) for v in re.findall(r"[-\d.e+]+", paths[0].get("transform"))]
    expected = [a[0].real, a[0].imag, -a[0].imag, a[0].real, 5, 7]
    assert nums == pytest.approx(expected, rel=1e-6)
    assert paths[1].get("transform") == "matrix(1 0 0 1 -3 -4)"


def test_exported_instances_reimport_at_their_poses():
    leaf = Terminal("A", "M0 0 C6 -6 16 -5 22 0 C15 3 6 6 0 0 Z", "fill:none;stroke:#000;stroke-width:1")
    stem = Terminal("B", "M0 0 L0 10", "fill:none;stroke:#123456;stroke-width:0.5")
    rng = np.random.default_rng(7)
    n = 40
    a = rng.uniform(0.2, 3, n) * np.exp(1j * rng.uniform(-np.pi, np.pi, n))
    b = rng.uniform(-100, 100, n) + 1j * rng.uniform(-100, 100, n)
    symbol = rng.integers(0, 2, n)
    scene = parse_svg(drawing_to_svg(drawing_of([leaf, stem], symbol, a, b)))
    assert len(scene.elements) == n
    local = [cubics_from_d(t.path)[0] for t in (leaf, stem)]
    for i, el in enumerate(scene.elements):
        expected = a[i] * local[symbol[i]] + b[i]
        assert np.abs(el.cubics - expected).max() < 1e-5 * (1 + np.abs(b[i]))
        width = float(dict(p.split(":") for p in el.style.split(";"))["stroke-width"])
        assert width == pytest.approx((1.0, 0.5)[symbol[i]], rel=1e-5)  # canvas units at every scale


def test_round_trip_corpus_and_realworld(shared):
    files = sorted((shared / "corpus").glob("*.svg")) + sorted((shared / "realworld").glob("*.svg"))
    assert files
    for path in files:
        scene = load_svg(path)
        again = parse_svg(drawing_to_svg(identity_drawing(scene)))
        assert len(again.elements) == len(scene.elements), path.name
        _, _, w, h = scene.viewbox
        diag = np.hypot(w, h)
        for e1, e2 in zip(scene.elements, again.elements, strict=True):
            assert e1.closed == e2.closed
            assert e1.style == e2.style, path.name
            p1 = sample_uniform(e1.cubics, 64)
            p2 = sample_uniform(e2.cubics, 64)
            assert np.abs(p1 - p2).max() < 1e-6 * diag, path.name
        assert again.viewbox == pytest.approx(scene.viewbox)


def test_viewbox_computed_from_bounds():
    square = Terminal("S", "M0 0 L1 0 L1 1 L0 1 Z", "fill:#000")
    dr = drawing_of([square], [0, 0], [10, 10j], [100 + 100j, 300 + 50j])
    bounds = drawing_bounds(dr)
    assert bounds == pytest.approx((100, 50, 300, 110))
    root = ET.fromstring(drawing_to_svg(dr))
    vx, vy, vw, vh = (float(v) for v in root.get("viewBox").split())
    assert vx < 100 and vy < 50 and vx + vw > 300 and vy + vh > 110
    assert vw < 220 and vh < 80
    assert float(root.get("width")) == pytest.approx(vw, rel=1e-6)


def test_bounds_include_stroke():
    line = Terminal("L", "M0 0 L10 0", "fill:none;stroke:#000;stroke-width:2")
    assert drawing_bounds(drawing_of([line], [0], [3], [0])) == pytest.approx((-1, -1, 31, 1))
    scaled = Terminal("L", "M0 0 L10 0", "fill:none;stroke:#000;stroke-width:2", scaled=True)
    assert drawing_bounds(drawing_of([scaled], [0], [3], [0])) == pytest.approx((-3, -3, 33, 3))


def test_empty_drawing():
    text = drawing_to_svg(drawing_of([Terminal("A", "M0 0 L1 1")], [], [], []))
    root = ET.fromstring(text)
    assert root.findall(SVG_NS + "path") == []
    assert drawing_bounds(drawing_of([Terminal("A", "M0 0 L1 1")], [], [], [])) is None


def test_export_svg_writes_atomically(tmp_path):
    dr = drawing_of([Terminal("A", "M0 0 L10 0 L5 5 Z", "fill:red")], [0], [1], [0], (0, 0, 10, 10))
    out = tmp_path / "out.svg"
    out.write_text("old")
    export_svg(dr, out)
    assert out.read_text() == drawing_to_structured_svg(dr)
    export_svg(dr, out, flat=True)
    assert out.read_text() == drawing_to_svg(dr)
    with pytest.raises(LsysError, match="cannot write"):
        export_svg(dr, tmp_path / "missing" / "out.svg")


def test_export_of_100k_instances():
    leaf = Terminal("A", "M0 0 C6 -6 16 -5 22 0 C15 3 6 6 0 0 Z", "fill:#2e7d32")
    stem = Terminal("B", "M0 0 L10 0", "fill:none;stroke:#000")
    n = 100_000
    rng = np.random.default_rng(0)
    dr = drawing_of(
        [leaf, stem],
        rng.integers(0, 2, n),
        np.exp(1j * rng.uniform(0, 6.3, n)),
        rng.uniform(0, 1000, n) + 1j * rng.uniform(0, 1000, n),
        (0, 0, 1000, 1000),
    )
    text = drawing_to_svg(dr)  # speed: tests/bench/bench_svg.py
    assert text.count("<path ") == n
