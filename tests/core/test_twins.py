"""Two copies of one shape in one pose, drawn once among other poses of it, are a sequence of two."""

from __future__ import annotations

import numpy as np

from lsys_core.derive.derivation import derive
from lsys_core.pipeline import infer
from lsys_core.testing import drawing_scene, hausdorff_rel

from .scenes import HOOK, LEAF, place, pose, scene


def _twins_and_others(turn: float = 0.0) -> list:
    """Two hooks side by side (the second turned by ``turn``), the hook in two other poses, a leaf."""
    return (
        place(HOOK, [pose(40, 20), pose(120, 20, heading=turn)])
        + place(HOOK, [pose(30, 140, heading=90.0, scale=3.0), pose(150, 90, heading=-35.0, scale=0.5)])
        + place(LEAF, [pose(80, 100, heading=10.0, scale=4.0)])
    )


def test_two_copies_in_one_pose_are_one_sequence() -> None:
    sc = scene(_twins_and_others())
    r = infer(sc)
    assert "P1: two copies in one pose" in r.log
    assert r.explained == 0.4  # the twins; the other hooks and the leaf are placed one by one
    assert hausdorff_rel(sc, drawing_scene(derive(r.grammar))) <= 1e-4


def test_two_copies_turned_apart_are_placed_one_by_one() -> None:
    r = infer(scene(_twins_and_others(turn=40.0)))  # not in one pose: no sequence of two
    assert r.explained == 0.0
    assert not any("two copies" in line for line in r.log)


def test_copies_in_one_pose_at_random_places_make_no_twins() -> None:
    rng = np.random.default_rng(4)
    xy = rng.uniform(0, 400, (40, 2))
    # in one pose, copies placed one by one write no heading or scale: a sequence saves nothing
    r = infer(scene(place(HOOK, [pose(x, y) for x, y in xy])))
    assert not any("two copies" in line for line in r.log)
