"""Tests of element similarity detection and inverse instancing (paper §4.1–§4.2, §5.4 flips)."""

from __future__ import annotations

from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest

from lsys_core.cancel import CancelToken
from lsys_core.errors import Cancelled, InferenceError
from lsys_core.instancing.sampling import arc_fractions, element_features, sample_elements
from lsys_core.instancing.similarity import (
    detect_similarity,
    symmetry_order,
    terminal_name,
    terminal_similarity,
)
from lsys_core.svg.model import Element, Scene

CORPUS = Path("/work/shared/corpus")
STYLE = "fill:none;stroke:#1b5e20;stroke-width:1"
K = 0.5522847498307936

#: An asymmetric closed leaf (as in the corpus), four cubics.
LEAF = np.array(
    [
        [0, 4 - 1.5j, 11.5 - 3j, 19.25 - 3.375j],
        [19.25 - 3.375j, 27 - 3.75j, 35 - 3j, 40],
        [40, 35 + 2j, 28.5 + 3.25j, 21.5 + 3.375j],
        [21.5 + 3.375j, 14.5 + 3.5j, 7 + 2.5j, 0],
    ]
)
CIRCLE = np.array(
    [
        [1, 1 + K * 1j, K + 1j, 1j],
        [1j, -K + 1j, -1 + K * 1j, -1],
        [-1, -1 - K * 1j, -K - 1j, -1j],
        [-1j, K - 1j, 1 - K * 1j, 1],
    ]
)
#: An open hook (three lines), as in the corpus.
HOOK = [0, 20j, 12 + 15j, 11j]


def lines(points, closed: bool = True, degenerate: bool = False) -> np.ndarray:
    """Return cubics for a polyline: control points at thirds, or at the ends if ``degenerate``."""
    p = list(points) + ([points[0]] if closed else [])
    rows = []
    for p0, p3 in pairwise(p):
        if degenerate:
            rows.append([p0, p0, p3, p3])
        else:
            rows.append([p0, p0 + (p3 - p0) / 3, p0 + 2 * (p3 - p0) / 3, p3])
    return np.array(rows, dtype=complex)


def split(cubics: np.ndarray, t: float = 0.5) -> np.ndarray:
    """Split every cubic in two with de Casteljau."""
    p0, p1, p2, p3 = cubics.T
    a, b, c = p0 + t * (p1 - p0), p1 + t * (p2 - p1), p2 + t * (p3 - p2)
    d, e = a + t * (b - a), b + t * (c - b)
    f = d + t * (e - d)
    out = np.empty((2 * len(cubics), 4), complex)
    out[0::2] = np.column_stack([p0, a, d, f])
    out[1::2] = np.column_stack([f, e, c, p3])
    return out


def reverse(cubics: np.ndarray) -> np.ndarray:
    """Draw the same path in the opposite direction."""
    return cubics[::-1, ::-1].copy()


def el(cubics, style: str = STYLE, closed: bool = True, subpaths=None) -> Element:
    cubics = np.asarray(cubics, dtype=complex)
    if subpaths is None:
        subpaths = np.zeros(len(cubics), dtype=int)
        closed_t: tuple[bool, ...] = (closed,)
    else:
        subpaths = np.asarray(subpaths)
        closed_t = (closed,) * (int(subpaths.max()) + 1)
    return Element(cubics, subpaths, closed_t, style)


def random_poses(n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    a = rng.uniform(0.3, 3.0, n) * np.exp(1j * rng.uniform(-np.pi, np.pi, n))
    b = rng.uniform(-500, 500, n) + 1j * rng.uniform(-500, 500, n)
    return a, b


def assert_poses(inst, idx, a_true, b_true, size: float, rep: int = 0):
    """Check recovered poses against the true placements ``element = a_true * base + b_true``.

    The representative ``rep`` defines the terminal frame, so the expected pose of element i
    is ``a_i / a_rep`` and ``b_i + (a_i / a_rep) * (origin - b_rep)``.
    """
    origin = inst.b[rep]
    exp_a = a_true / a_true[rep]
    exp_b = b_true + exp_a * (origin - b_true[rep])
    ang = np.abs(np.angle(inst.a[idx] / exp_a[idx], deg=True))
    scale = np.abs(np.abs(inst.a[idx]) / np.abs(exp_a[idx]) - 1)
    shift = np.abs(inst.b[idx] - exp_b[idx]) / (np.abs(exp_a[idx]) * size)
    assert ang.max() < 0.01, ang.max()
    assert scale.max() < 1e-4, scale.max()
    assert shift.max() < 1e-4, shift.max()


# --------------------------------------------------------------------------- grouping and poses


def test_copies_under_random_similarities_form_one_group_with_exact_poses():
    a, b = random_poses(40)
    inst = detect_similarity(Scene(tuple(el(a[i] * LEAF + b[i]) for i in range(40))))
    assert inst.group.tolist() == [0] * 40
    assert len(inst.terminals) == 1 and inst.terminals[0].name == "A"
    assert inst.symmetry.tolist() == [1]
    assert inst.mirrored_of.tolist() == [-1]
    assert inst.a[0] == 1
    assert_poses(inst, np.arange(40), a, b, 40.0)


def test_resegmented_reversed_and_restarted_copies_join_the_group_with_exact_poses():
    a, b = random_poses(24, seed=3)
    shapes = [
        LEAF,
        split(LEAF),
        reverse(LEAF),
        np.roll(LEAF, 2, axis=0),
        reverse(split(np.roll(LEAF, 1, axis=0), 0.3)),
        split(split(LEAF, 0.7)),
    ]
    els = [el(a[i] * shapes[i % len(shapes)] + b[i]) for i in range(24)]
    inst = detect_similarity(Scene(tuple(els)))
    assert inst.group.tolist() == [0] * 24
    assert_poses(inst, np.arange(24), a, b, 40.0)


def test_lines_and_degenerate_cubics_are_the_same_shape():
    pts = [0, 10, 10 + 14j, 14j]
    a, b = random_poses(6, seed=5)
    els = [el(a[i] * lines(pts, degenerate=bool(i % 2)) + b[i]) for i in range(6)]
    inst = detect_similarity(Scene(tuple(els)))
    assert inst.group.tolist() == [0] * 6
    assert inst.symmetry.tolist() == [2]
    # poses are only defined up to the 2-fold symmetry: compare the drawn geometry instead
    for i in range(6):
        local = lines(pts) * a[0] + b[0] - inst.b[0]
        mapped = inst.a[i] * local + inst.b[i]
        target = lines(pts) * a[i] + b[i]
        d = np.abs(mapped[:, 0][:, None] - target[:, 0][None, :]).min(axis=1)
        assert d.max() < 1e-4 * abs(a[i]) * 14


def test_shape_with_two_subpaths_is_recognised_resegmented():
    body = lines([0, 10, 10 + 14j, 14j])
    base = lines([-1 + 14j, 11 + 14j, 11 + 16j, -1 + 16j])
    shape = np.concatenate([body, base])
    sub = np.repeat([0, 1], 4)
    a, b = random_poses(5, seed=7)
    els = [el(a[0] * shape + b[0], subpaths=sub)]
    for i in range(1, 5):
        parts = np.concatenate([split(body), np.roll(base, i, axis=0)])
        els.append(el(a[i] * parts + b[i], subpaths=np.repeat([0, 1], [8, 4])))
    inst = detect_similarity(Scene(tuple(els)))
    assert inst.group.tolist() == [0] * 5
    assert_poses(inst, np.arange(5), a, b, 16.0)


def test_jittered_coordinates_still_group():
    a, b = random_poses(30, seed=11)
    els = [el(np.round(a[i] * LEAF + b[i], 3)) for i in range(30)]
    inst = detect_similarity(Scene(tuple(els)))
    assert inst.group.tolist() == [0] * 30


def test_mirrored_copy_is_a_separate_linked_group():
    a, b = random_poses(8, seed=2)
    els = []
    for i in range(8):
        shape = np.conj(LEAF) if i % 2 else LEAF
        if i % 4 == 3:
            shape = split(reverse(shape))  # also through the sampled path
        els.append(el(a[i] * shape + b[i]))
    inst = detect_similarity(Scene(tuple(els)))
    assert inst.group.tolist() == [0, 1] * 4
    assert inst.mirrored_of.tolist() == [-1, 0]
    assert inst.terminals[1].mirror_of == "A" and inst.terminals[0].mirror_of is None
    odd = np.arange(1, 8, 2)
    assert_poses(inst, odd, a, b, 40.0, rep=1)


def test_open_mirrored_hook_and_no_flips():
    a, b = random_poses(4, seed=4)
    els = [
        el(a[i] * lines(HOOK if i < 2 else np.conj(HOOK), closed=False) + b[i], closed=False)
        for i in range(4)
    ]
    inst = detect_similarity(Scene(tuple(els)))
    assert inst.group.tolist() == [0, 0, 1, 1]
    assert inst.mirrored_of.tolist() == [-1, 0]
    plain = detect_similarity(Scene(tuple(els)), flips=False)
    assert plain.group.tolist() == [0, 0, 1, 1]
    assert plain.mirrored_of.tolist() == [-1, -1]
    assert all(t.mirror_of is None for t in plain.terminals)


def test_mirror_symmetric_shapes_have_no_mirrored_group():
    sym_leaf = np.array([[0, 10 - 6j, 30 - 6j, 40], [40, 30 + 6j, 10 + 6j, 0]])
    a, b = random_poses(6, seed=8)
    els = [el(a[i] * (np.conj(sym_leaf) if i % 2 else sym_leaf) + b[i]) for i in range(6)]
    inst = detect_similarity(Scene(tuple(els)))
    assert inst.group.tolist() == [0] * 6
    assert inst.mirrored_of.tolist() == [-1]


def test_different_shapes_are_different_groups_whatever_their_fills():
    tri = lines([0, 14, 3 + 9j])
    els = [
        el(LEAF),
        el(tri + 100),
        el(2 * LEAF + 50j),
        el(LEAF + 200, style="fill:#ff0000;stroke:#1b5e20;stroke-width:1"),
        el(LEAF * 1j + 300, style="fill:none;stroke:#1b5e20;stroke-width:2.5"),
        el(3 * tri - 40),
    ]
    inst = detect_similarity(Scene(tuple(els)))
    # a terminal is geometry: the red leaf is the same terminal (styles travel with instances)
    assert inst.group.tolist() == [0, 1, 0, 0, 0, 1]
    assert [t.name for t in inst.terminals] == ["A", "B"]
    assert inst.terminals[0].style == STYLE


def test_circle_grid_has_continuous_symmetry_and_real_scales():
    els = []
    for i in range(4):
        for j in range(5):
            start = np.roll(CIRCLE, (i + j) % 4, axis=0)  # drawn from another start point
            els.append(el((1 + 0.5 * j) * start + 10 * i + 10j * j))
    inst = detect_similarity(Scene(tuple(els)))
    assert inst.group.tolist() == [0] * 20
    assert inst.symmetry.tolist() == [0]
    assert np.abs(inst.a.imag).max() < 1e-12
    assert np.allclose(inst.a.real, [1 + 0.5 * (k % 5) for k in range(20)], rtol=1e-6)
    assert np.allclose(inst.b, [10 * (k // 5) + 10j * (k % 5) for k in range(20)], atol=1e-5)


def test_rect_rotated_by_180_degrees_is_the_same_unrotated_shape():
    rect = lines([0, 20, 20 + 8j, 8j])
    els = [el(rect), el(-rect + 100), el(np.exp(0.3j) * rect + 50j), el(-np.exp(0.3j) * rect - 50j)]
    inst = detect_similarity(Scene(tuple(els)))
    assert inst.group.tolist() == [0] * 4
    assert inst.mirrored_of.tolist() == [-1]
    assert inst.symmetry.tolist() == [2]
    assert np.allclose(inst.a, [1, 1, np.exp(0.3j), np.exp(0.3j)], atol=1e-9)


def test_square_has_fourfold_symmetry_and_smallest_pose_angle():
    sq = lines([0, 10, 10 + 10j, 10j])
    ang = np.deg2rad([0, 100, -170, 44, 46])
    els = [el(np.exp(1j * t) * sq + 30 * k) for k, t in enumerate(ang)]
    inst = detect_similarity(Scene(tuple(els)))
    assert inst.group.tolist() == [0] * 5
    assert inst.symmetry.tolist() == [4]
    assert np.allclose(np.angle(inst.a, deg=True), [0, 10, 10, 44, -44], atol=1e-6)


def test_threshold_decides_whether_a_deformed_copy_joins():
    deformed = LEAF.copy()
    deformed[1, 1:3] += [-1.5j, -1.5j]  # bulge one quarter of the outline
    deformed[2, 0] += 0.0
    els = (el(LEAF), el(2 * deformed * np.exp(0.4j) + 80))
    loose = detect_similarity(Scene(els), threshold=0.6)
    strict = detect_similarity(Scene(els), threshold=0.99)
    assert loose.group.tolist() == [0, 0]
    assert strict.group.tolist() == [0, 1]
    assert abs(np.angle(loose.a[1]) - 0.4) < 0.05 and abs(abs(loose.a[1]) - 2) < 0.1


# --------------------------------------------------------------------------- terminals


def test_terminal_path_is_the_representative_about_its_centroid():
    from lsys_core.geometry import paths as pathdata

    shape = 3 * np.exp(0.7j) * LEAF + (120 + 40j)
    inst = detect_similarity(Scene((el(shape), el(LEAF))))
    cubics, _, closed = pathdata.cubics_from_d(inst.terminals[0].path)
    samples = sample_elements([el(shape)], arc_fractions(768))
    centroid = samples.points.mean()
    assert abs(inst.b[0] - centroid) < 1e-3
    assert closed == (True,)
    assert np.allclose(cubics, shape - inst.b[0], atol=1e-5)
    # the other element is the terminal scaled back down and turned back
    assert abs(inst.a[1] - np.exp(-0.7j) / 3) < 1e-9


def test_terminal_names():
    assert [terminal_name(i) for i in (0, 1, 25, 26, 27, 52, 701, 702)] == [
        "A",
        "B",
        "Z",
        "AA",
        "AB",
        "BA",
        "ZZ",
        "AAA",
    ]


def test_symmetry_orders_of_basic_shapes():
    def order(cubics):
        s = sample_elements([el(cubics)], arc_fractions(768))
        z = s.points[0] - s.points[0].mean()
        z /= np.sqrt(np.mean(np.abs(z) ** 2))
        return symmetry_order(z, s.normals[0])[0]

    tri = lines([np.exp(2j * np.pi * k / 3) for k in range(3)])
    hexagon = lines([np.exp(2j * np.pi * k / 6) for k in range(6)])
    many = lines([np.exp(2j * np.pi * k / 20) for k in range(20)])
    assert order(tri) == 3
    assert order(hexagon) == 6
    assert order(many) == 0
    assert order(CIRCLE) == 0
    assert order(LEAF) == 1


def test_degenerate_and_empty_elements_do_not_break_grouping():
    dot = np.array([[5 + 5j] * 4])
    els = (el(dot), el(LEAF), el(np.zeros((0, 4), complex)), el(dot + 7), el(LEAF * 2))
    inst = detect_similarity(Scene(els))
    assert inst.group[1] == inst.group[4]
    assert inst.group[0] == inst.group[3] != inst.group[1]
    assert np.isfinite(inst.a).all() and np.isfinite(inst.b).all()
    assert len(detect_similarity(Scene(())).terminals) == 0


# --------------------------------------------------------------------------- contract details


def test_bad_threshold_is_a_user_error():
    with pytest.raises(InferenceError):
        detect_similarity(Scene((el(LEAF),)), threshold=1.5)


def test_cancel_and_progress():
    token = CancelToken()
    token.cancel()
    with pytest.raises(Cancelled):
        detect_similarity(Scene((el(LEAF), el(LEAF + 50))), cancel=token)
    seen: list[tuple[str, float]] = []
    detect_similarity(Scene((el(LEAF), el(LEAF + 50))), progress=lambda s, f: seen.append((s, f)))
    assert {s for s, _ in seen} == {"similarity"}
    assert seen[-1][1] == 1.0 and all(0 <= f <= 1 for _, f in seen)


def test_descriptors_are_invariant_to_redrawing():
    a, b = random_poses(4, seed=9)
    shapes = [LEAF, reverse(split(LEAF)), np.conj(np.roll(LEAF, 1, axis=0)), split(split(LEAF))]
    s = sample_elements([el(a[i] * shapes[i] + b[i]) for i in range(4)], arc_fractions(96))
    _, _, desc = element_features(s)
    assert np.abs(desc - desc[0]).max() < 0.02


# --------------------------------------------------------------------------- corpus


def _load(name: str):
    parse = pytest.importorskip("lsys_core.svg.parse")
    path = CORPUS / name
    if not path.exists():
        pytest.skip(f"{path} missing")
    return parse.load_svg(path)


def test_corpus_resegmented_has_two_shapes():
    scene = _load("resegmented.svg")
    inst = detect_similarity(scene)
    assert len(inst.terminals) == 2
    assert sorted(np.bincount(inst.group).tolist()) == [8, 16]
    assert inst.mirrored_of.tolist() == [-1, -1]


def test_corpus_mirrored_has_a_shape_and_its_mirror():
    scene = _load("mirrored.svg")
    inst = detect_similarity(scene)
    assert len(inst.terminals) == 2
    assert inst.mirrored_of.tolist() == [-1, 0]
    assert inst.terminals[1].mirror_of == inst.terminals[0].name
    assert np.bincount(inst.group).tolist() == [10, 10]


def test_noisy_copies_group_without_a_spurious_mirror():
    comma = np.array([[0, 10 - 8j, 30 - 6j, 40], [40, 25 + 2j, 10 + 4j, 0]])  # no symmetry at all
    rng = np.random.default_rng(21)
    a, b = random_poses(16, seed=22)
    els = [el(a[0] * comma + b[0])]
    for i in range(1, 16):
        noisy = comma + 0.4 * (
            rng.normal(size=comma.shape) + 1j * rng.normal(size=comma.shape)
        )  # 1 % of size
        noisy[1:, 0] = noisy[:-1, 3]
        noisy[0, 0] = noisy[-1, 3]
        els.append(el(a[i] * split(noisy) + b[i]))
    inst = detect_similarity(Scene(tuple(els)))
    assert inst.group.tolist() == [0] * 16
    assert inst.mirrored_of.tolist() == [-1]
    assert np.abs(np.angle(inst.a / (a / a[0]), deg=True)).max() < 2.0


def test_open_arc_poses_are_pinned_down_by_arc_length():
    arc = np.array([[1, 1 + K * 1j, K + 1j, 1j], [1j, -K + 1j, -1 + K * 1j, -1]])  # half circle
    a, b = random_poses(8, seed=13)
    els = [el(a[i] * (split(arc, 0.37) if i % 2 else reverse(arc)) + b[i], closed=False) for i in range(8)]
    inst = detect_similarity(Scene(tuple(els)))
    assert inst.group.tolist() == [0] * 8
    assert inst.symmetry.tolist() == [1]
    assert_poses(inst, np.arange(8), a, b, 2.0)


def test_terminal_similarity_counts_mirror_images_as_alike():
    tri = lines([0, 14, 10 + 5j])  # scalene
    inst = detect_similarity(Scene((el(LEAF), el(np.conj(LEAF)), el(tri), el(np.conj(tri)))))
    assert [t.name for t in inst.terminals] == ["A", "B", "C", "D"]
    sim = terminal_similarity(inst.terminals)
    assert np.allclose(sim, sim.T) and np.allclose(np.diag(sim), 1)
    assert sim[0, 1] > 0.95 and sim[2, 3] > 0.95
    assert sim[0, 2] < 0.6 and sim[1, 3] < 0.6
    plain = terminal_similarity(inst.terminals, flips=False)
    assert plain[2, 3] < sim[2, 3] - 0.2  # without flips a mirror image is only partly alike


def test_cancel_from_progress_callback_stops_the_run():
    token = CancelToken()
    els = (*(el(LEAF * (1 + 0.01 * i) + 50 * i) for i in range(20)), el(lines([0, 14, 10 + 5j])))

    def progress(stage: str, fraction: float) -> None:
        if fraction > 0:
            token.cancel()

    with pytest.raises(Cancelled):
        detect_similarity(Scene(els), cancel=token, progress=progress)


def test_many_sided_polygon_reports_continuous_but_keeps_its_true_period():
    poly = lines([np.exp(2j * np.pi * k / 16) for k in range(16)])
    els = (el(10 * poly), el(20 * np.exp(np.deg2rad(30) * 1j) * poly + 100))
    inst = detect_similarity(Scene(els))
    assert inst.group.tolist() == [0, 0]
    assert inst.symmetry.tolist() == [0]
    assert np.isclose(np.angle(inst.a[1], deg=True), 7.5) and np.isclose(abs(inst.a[1]), 2)


def test_progress_counts_every_grouped_element_once():
    # a degenerate (zero-size) element, distinct shapes (a representative each) and copies
    square = np.array([[0, 0, 0, 0], [0, 10, 10, 10], [10, 10 + 10j, 10 + 10j, 10 + 10j]], complex)
    els = [el(np.zeros((1, 4), complex) + 7), el(LEAF), el(LEAF + 50), el(LEAF * 1j + 100), el(square + 200)]
    seen: list[float] = []
    detect_similarity(Scene(tuple(els)), progress=lambda s, f: seen.append(f))
    assert seen == sorted(seen)  # never goes back
    assert seen[-1] == 1.0 and seen[-2] == pytest.approx(0.95)  # all elements grouped before the end
