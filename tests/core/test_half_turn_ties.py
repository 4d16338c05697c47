"""Copies of a half-turn symmetric shape keep one rotation beside a copy turned by 90° (instancing.orientation)."""

from __future__ import annotations

import numpy as np

from lsys_core.derive.derivation import derive
from lsys_core.hierarchy.explain import repeating_rules
from lsys_core.instancing.orientation import unwrap_turns
from lsys_core.pipeline import infer
from lsys_core.testing import assert_scenes_close, drawing_scene
from tests.core.scenes import LEAF, place, pose, scene

#: A straight stroke 5 long about the origin (symmetric under a half turn).
TICK = np.array([[-2.5j, -2.5j / 3, 2.5j / 3, 2.5j]])


def test_turns_half_a_period_from_the_parent_keep_their_own_side() -> None:
    # an axis line (turned 90°) and ticks upright right beside it: the ticks are half a period
    # (180° symmetry) from the line, so 0° and 180° are as near; they must all stay at 0°
    a = np.array([1, 1, 1j, 1, 1], complex)
    b = np.array([10 + 2.5j, 30 + 2.5j, 40, 50 + 2.5j, 70 + 2.5j])
    theta = unwrap_turns(a, b, np.pi)
    assert np.allclose(theta[[0, 1, 3, 4]], 0.0)


def test_ticks_on_an_axis_line_are_one_sequence() -> None:
    ticks = [pose(10 + 20 * i, 102.5) for i in range(4)]
    axis = [pose(40, 100, 90, 16)]
    s = scene(
        place(TICK, ticks + axis, "fill:none;stroke:#888"),
        place(LEAF, [pose(5, 5), pose(80, 20, 60)]),
    )
    g = infer(s).grammar
    d = derive(g)
    names = [r.name for r in g.rules]
    repeating = repeating_rules(g)
    placed = [names[r] if r >= 0 else "" for r in d.rule]
    assert sum(n in repeating for n in placed) >= 4  # every tick, not three and one apart
    assert_scenes_close(s, drawing_scene(d))
