"""Tests of the renderer's batching: draft flattening and chunks, full-mode runs of disjoint instances."""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.derive.model import Drawing
from lsys_core.grammar.model import Terminal
from lsys_core.render import paths as render_paths
from lsys_core.render import raster as render
from lsys_core.render.raster import Renderer

from .scenes import make_drawing

LEAF = "M0 0 C6 -6 16 -5 22 0 C15 3 6 6 0 0 Z"
SQUARE = "M0 0 L10 0 L10 10 L0 10 Z"


def drawing_of(terminals, symbol, a, b, viewbox=(0.0, 0.0, 400.0, 300.0)) -> Drawing:
    return make_drawing(terminals, symbol, a, b, viewbox, None, rule=0)


def grid(rows: int, cols: int, step: float, turn: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Return poses of a rows x cols grid, every instance turned a little more than the last."""
    k = np.arange(rows * cols)
    b = (k % cols) * step + 1j * (k // cols) * step + complex(step, step)
    a = np.exp(1j * np.radians(turn * k))
    return a, b


def one_by_one(monkeypatch, renderer: Renderer, drawing: Drawing) -> np.ndarray:
    """Render in full mode with batching switched off (every instance with its own matrix)."""
    with monkeypatch.context() as m:
        m.setattr(render, "FULL_MIN_RUN", 10**9)
        return renderer.draw(drawing, background=(255, 255, 255, 255)).copy()


# ---------------------------------------------------------------------------
# Draft mode


@pytest.mark.parametrize("scale", [0.2, 1.0, 4.0, 40.0])
def test_flattened_outline_stays_within_tolerance(scale):
    geo = render_paths._geometry(LEAF + " M 30 0 L 40 0 L 40 5 Z")
    points, verbs = render_paths._flatten(geo, scale, 0.5)
    counts = {
        render_paths._VERB_MOVE: 1,
        render_paths._VERB_LINE: 1,
        render_paths._VERB_CUBIC: 3,
        render_paths._VERB_CLOSE: 0,
    }
    assert sum(counts[v] for v in verbs.tolist()) == len(points)
    assert (verbs == render_paths._VERB_MOVE).sum() == 2 and (verbs == render_paths._VERB_CLOSE).sum() == 2
    if (verbs == render_paths._VERB_CUBIC).any():  # too many lines would be needed: skia subdivides
        assert scale >= 40
        return
    # every point of the true curves lies within 0.5 px of the polyline
    t = np.linspace(0, 1, 400)[:, None]
    p0, p1, p2, p3 = geo.cubics[:2].T
    curve = ((1 - t) ** 3 * p0 + 3 * (1 - t) ** 2 * t * p1 + 3 * (1 - t) * t**2 * p2 + t**3 * p3).ravel()
    first_close = int(np.flatnonzero(verbs == render_paths._VERB_CLOSE)[0])
    ring = points[: sum(counts[v] for v in verbs[:first_close].tolist())]  # the leaf's contour
    p, q = ring, np.roll(ring, -1)
    u = np.clip(((curve[:, None] - p) * np.conj(q - p)).real / np.maximum(np.abs(q - p) ** 2, 1e-30), 0, 1)
    distance = np.abs(curve[:, None] - (p + u * (q - p))).min(axis=1) * scale
    assert distance.max() <= 0.5
    assert len(ring) <= 1 + 2 * render_paths.DRAFT_MAX_LINES


def test_draft_draws_every_chunk_with_fill_and_stroke():
    n = 3 * render.DRAFT_CHUNK + 5
    a, b = grid(60, 52, 7.0)
    filled = Terminal("F", SQUARE, "fill:#ff0000")
    outlined = Terminal("O", SQUARE, "fill:#00ff00;stroke:#0000ff;stroke-width:4")
    symbol = (np.arange(n) % 3 == 0).astype(int)
    dr = drawing_of([filled, outlined], symbol, 0.5 * a[:n], b[:n], (0, 0, 400, 440))
    r = Renderer(400, 440)
    full = r.draw(dr, background=(255, 255, 255, 255)).copy()
    draft = r.draw(dr, draft=True, background=(255, 255, 255, 255))
    ink_full, ink_draft = full[..., :3].min(-1) < 128, draft[..., :3].min(-1) < 128
    assert (ink_full & ink_draft).sum() / (ink_full | ink_draft).sum() > 0.9  # the last chunk is there
    blue = (draft[..., 2] > 200) & (draft[..., 0] < 50) & (draft[..., 1] < 50)
    green = (draft[..., 1] > 200) & (draft[..., 2] < 50)
    assert blue.sum() > 1000 and green.sum() > 1000  # fill and stroke from the same batched path


# ---------------------------------------------------------------------------
# Full mode: runs of disjoint instances


def brute_runs(rects, min_length):
    """Greedy runs by testing every pair of rectangles with shapely, one pair at a time."""
    from shapely.geometry import Polygon

    c, u, w, h = rects
    corners = [c + u * (sx * w + 1j * sy * h) for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
    shapes = [Polygon([(z[k].real, z[k].imag) for z in corners]) for k in range(len(c))]
    runs, start = [], 0
    for j in range(len(c)):
        if any(shapes[i].intersects(shapes[j]) for i in range(start, j)):
            runs.append((start, j))
            start = j
    runs.append((start, len(c)))
    return [(s, e) for s, e in runs if e - s >= min_length]


@pytest.mark.parametrize("seed", range(6))
def test_disjoint_runs_match_pairwise_tests(seed):
    rng = np.random.default_rng(seed)
    n = 150
    spread = [40, 120, 400][seed % 3]
    c = rng.uniform(0, spread, n) + 1j * rng.uniform(0, spread, n)
    u = np.exp(1j * rng.uniform(0, 2 * np.pi, n))
    w, h = np.full(n, 6.0), np.full(n, 2.0)
    rects = (c, u, w, h)
    runs = render_paths._disjoint_runs(*rects, 1)
    if spread == 400:  # crowded scenes may give up: no runs, all drawn one by one
        assert len(runs) > 1
    if runs:
        assert runs == brute_runs(rects, 1)
        assert render_paths._disjoint_runs(*rects, 4) == [(s, e) for s, e in runs if e - s >= 4]


def test_rectangles_overlap_is_exact_for_turned_rectangles():
    u1, u2 = np.array([1.0 + 0j]), np.array([np.exp(1j * np.pi / 4)])
    one = np.array([1.0])
    # a diamond of half side 1 beside a unit square: corners 1 + sqrt(2) apart along x
    gap = np.array([1 + np.sqrt(2) + 0.01 + 0j])
    assert not render_paths._rectangles_overlap(gap, u1, one, one, u2, one, one)[0]
    assert render_paths._rectangles_overlap(gap - 0.02, u1, one, one, u2, one, one)[0]
    # axis-aligned bounds overlap, rectangles do not (thin diagonal bars side by side)
    bars = np.array([np.exp(1j * np.pi / 4)])
    apart = np.array([1.5j * np.exp(1j * np.pi / 4)])
    assert not render_paths._rectangles_overlap(
        apart, bars, np.array([5.0]), one * 0.5, bars, one * 5, one * 0.5
    )[0]


def test_full_mode_batches_disjoint_grid_with_the_same_picture(monkeypatch):
    leaf = Terminal("A", LEAF, "fill:#66bb6a;stroke:#1b5e20;stroke-width:0.6")
    a, b = grid(25, 20, 26.0, turn=0.2)
    dr = drawing_of([leaf], np.zeros(500, int), a, b, (0, 0, 560, 700))
    r = Renderer(560, 700)
    full = render._FullPass(r._canvas, [r._terminal(LEAF, leaf.style)], dr.symbol, a, b, True)
    assert full.compact_runs() == [(0, 500)]  # drawing unit = pixel: one batched run of everything
    batched = r.draw(dr, background=(255, 255, 255, 255)).copy()
    single = one_by_one(monkeypatch, r, dr)
    # skia anti-aliases a big batched path by supersampling, a single leaf analytically: edge
    # pixels differ by a few levels, the shapes and the amount of ink do not
    diff = np.abs(batched.astype(int) - single.astype(int)).max(axis=-1)
    ink = (batched[..., :3].min(-1) < 250) | (single[..., :3].min(-1) < 250)
    assert diff.max() <= 48 and diff[ink].mean() < 4 and diff[~ink].max() <= 5
    darkness = [(255 - img[..., :3].astype(int)).sum() for img in (batched, single)]
    assert darkness[0] == pytest.approx(darkness[1], rel=0.03)


def test_full_mode_keeps_the_order_of_overlapping_instances(monkeypatch):
    red = Terminal("R", SQUARE, "fill:#ff0000")
    blue = Terminal("B", SQUARE, "fill:#0000ff;stroke:#000000;stroke-width:0.5")
    a, b = grid(10, 20, 14.0)
    # 200 disjoint red squares, a big blue one over the middle, then 200 red ones again shifted by
    # half a square (each overlapping the blue one or an earlier red one)
    symbol = np.r_[np.zeros(200), 1, np.zeros(200)].astype(int)
    poses_a = np.r_[a, 8.0, a]
    poses_b = np.r_[b, 100 + 40j, b + 5 + 5j]
    dr = drawing_of([red, blue], symbol, poses_a, poses_b, (0, 0, 300, 160))
    r = Renderer(300, 160)
    img = r.draw(dr, background=(255, 255, 255, 255)).copy()
    assert tuple(img[10, 10, :3]) == (255, 255, 255)
    assert tuple(img[60, 105, :3]) == (0, 0, 255)  # blue covers the first red squares
    assert tuple(img[66, 122, :3]) == (255, 0, 0)  # a shifted red square, drawn after it: on top
    assert tuple(img[130, 18, :3]) == (255, 0, 0)  # first layer outside the blue square
    single = one_by_one(monkeypatch, r, dr)
    assert np.abs(img.astype(int) - single.astype(int)).max() <= 48


def test_full_mode_batches_evenodd_and_translucent_terminals_exactly(monkeypatch):
    donut = Terminal("D", "M0 0 L10 0 L10 10 L0 10 Z M3 3 L7 3 L7 7 L3 7 Z", "fill:#000;fill-rule:evenodd")
    glass = Terminal("G", SQUARE, "fill:#0000ff;fill-opacity:0.5")
    a, b = grid(12, 16, 16.0)
    symbol = np.arange(192) % 2
    dr = drawing_of([donut, glass], symbol, a, b, (0, 0, 290, 220))
    r = Renderer(290, 220)
    img = r.draw(dr, background=(255, 255, 255, 255)).copy()
    assert np.array_equal(img, one_by_one(monkeypatch, r, dr))  # disjoint and pixel-aligned: identical
    assert tuple(img[16 + 5, 16 + 5, :3]) == (255, 255, 255)  # the donut's hole stays open
    assert abs(int(img[16 + 5, 32 + 5, 0]) - 127) <= 1  # half-transparent blue over white
