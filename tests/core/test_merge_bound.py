"""The batched lower bound of the tolerance merge never rules out a pair that the full check would merge."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from lsys_core.geometry.paths import d_from_cubics
from lsys_core.grammar.model import Terminal
from lsys_core.instancing import merge
from lsys_core.instancing.fidelity import deviations
from lsys_core.instancing.model import Instancing
from lsys_core.svg.model import Element, Scene


def _polygon(rng: np.random.Generator) -> np.ndarray:
    """A closed star polygon of 5 to 30 corners at random radii about the origin, as straight cubics."""
    k = int(rng.integers(5, 31))
    corners = rng.uniform(0.2, 1.0, k) * np.exp(2j * np.pi * np.arange(k) / k)
    ends = np.roll(corners, -1)
    return np.stack([corners, (2 * corners + ends) / 3, (corners + 2 * ends) / 3, ends], axis=1)


def _variant(rng: np.random.Generator, shape: np.ndarray, jitter: float) -> np.ndarray:
    """``shape`` turned, scaled, maybe mirrored and drawn the other way, its corners moved by ``jitter``."""
    out = np.conj(shape) if rng.random() < 0.5 else shape.copy()
    if rng.random() < 0.5:
        out = out[::-1, ::-1]
    corners = out[:, 0] + jitter * (rng.normal(size=len(out)) + 1j * rng.normal(size=len(out)))
    ends = np.roll(corners, -1)
    out = np.stack([corners, (2 * corners + ends) / 3, (corners + 2 * ends) / 3, ends], axis=1)
    return out * rng.uniform(0.5, 2.0) * np.exp(2j * np.pi * rng.random()) + complex(*rng.uniform(-50, 50, 2))


def _element(cubics: np.ndarray) -> Element:
    return Element(cubics, np.zeros(len(cubics), int), (True,), "fill:#000")


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([0.0, 0.003, 0.01, 0.05]), st.sampled_from([1, 8]))
def test_bound_is_below_the_exact_lower_bound(seed: int, jitter: float, stride: int) -> None:
    """For random shapes and their moved, turned, scaled, mirrored and jittered copies, every quarter turn."""
    rng = np.random.default_rng(seed)
    base = [_polygon(rng) for _ in range(6)]
    shapes = base + [_variant(rng, s, jitter) for s in base]
    frames = merge._frames([_element(s) for s in shapes])
    host, other = np.triu_indices(len(shapes), 1)
    host, other = np.concatenate([host, other]), np.concatenate([other, host])
    bound = merge._apart_bounds(frames, merge._Fields.of(frames), host, other, stride)
    exact = np.array(
        [
            [merge._apart(frames, int(h), int(o), q) for q in merge._QUARTERS]
            for h, o in zip(host, other, strict=True)
        ]
    )
    assert (bound <= exact).all(), float((bound - exact).max())
    # not vacuous: distinct shapes are told apart by the bound alone
    assert (bound.min(axis=1) > 0.2).any()


def test_merges_are_those_of_the_full_check() -> None:
    """Near-identical copies among distinct shapes merge, exactly as without the bound."""
    rng = np.random.default_rng(7)
    base = [_polygon(rng) * 10 for _ in range(12)]
    shapes = list(base)
    for s in base[:6]:  # copies of the first six, each corner moved by about 0.5 % of their size
        corners = s[:, 0] + 0.05 * (rng.normal(size=len(s)) + 1j * rng.normal(size=len(s)))
        ends = np.roll(corners, -1)
        shapes.append(np.stack([corners, (2 * corners + ends) / 3, (corners + 2 * ends) / 3, ends], axis=1))
    where = np.array([complex(30 * (k % 6), 30 * (k // 6)) for k in range(len(shapes))])
    scene = Scene(tuple(_element(s + z) for s, z in zip(shapes, where, strict=True)))
    terminals = tuple(
        Terminal(f"T{k}", d_from_cubics(s, np.zeros(len(s), int), (True,))) for k, s in enumerate(shapes)
    )
    n = len(shapes)
    inst = Instancing(np.arange(n), np.ones(n, complex), where, terminals, np.ones(n, int), np.full(n, -1))
    inst = replace(inst, deviation=deviations(scene, inst))
    full_check = merge._hopeless
    ruled_out = []
    try:
        merge._hopeless = lambda *args: ruled_out.append(full_check(*args)) or ruled_out[-1]
        fast = merge.merge_within(scene, inst, tolerance=1.0)
        merge._hopeless = lambda *args: np.zeros(len(args[3]), bool)
        full = merge.merge_within(scene, inst, tolerance=1.0)
    finally:
        merge._hopeless = full_check
    assert len(fast.terminals) == n - 6  # every jittered copy joined its original
    assert ruled_out and 0 < ruled_out[0].sum() < ruled_out[0].size  # the bound ruled out some pairs, not all
    assert fast.group.tolist() == full.group.tolist()
    assert np.array_equal(fast.a, full.a) and np.array_equal(fast.b, full.b)
    assert fast.terminals == full.terminals
