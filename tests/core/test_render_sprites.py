"""Drafts stamp small opaque instances as sprites: the same picture as drawing them as paths."""

from __future__ import annotations

import numpy as np

from lsys_core.grammar.model import Terminal
from lsys_core.render.raster import Renderer
from lsys_core.render.sprites import SPRITE_MAX_PX

from .scenes import make_drawing

LEAF = "M 0 0 Q 5 -8 14 -2 Q 9 2 0 0 Z"


def _leaves(style: str, scale: float = 0.5, n: int = 12):
    """``n`` × ``n`` leaves on a 20-unit grid, each turned 30° more than the one before."""
    k = np.arange(n * n)
    a = scale * np.exp(1j * np.deg2rad(30.0 * k))
    b = 10 + 20 * (k % n) + 1j * (10 + 20 * (k // n))
    return make_drawing([Terminal("A", LEAF, style)], np.zeros(k.size), a, b, (0.0, 0.0, 20.0 * n, 20.0 * n))


def _draft(drawing, stamp: bool, highlight=None) -> np.ndarray:
    r = Renderer(240, 240)
    if not stamp:
        r._sprites.plan = lambda *args: None  # every instance as a path
    return r.draw(drawing, None, False, True, background=(255, 255, 255, 255), highlight=highlight).copy()


def test_stamped_draft_paints_the_instances_where_the_full_frame_does():
    """Stamped small leaves cover the pixels a full frame without anti-aliasing covers (which the
    exact curves of a sprite follow closer than the draft's flattened paths)."""
    drawing = _leaves("fill:#66bb6a")
    stamped = _draft(drawing, True)
    exact = Renderer(240, 240).draw(drawing, None, False, False, background=(255, 255, 255, 255))
    ink_s, ink_e = stamped[..., 0] < 250, exact[..., 0] < 250
    assert ink_s.sum() > 144 * 8  # every leaf paints pixels
    assert abs(int(ink_s.sum()) - int(ink_e.sum())) <= 0.05 * ink_e.sum()
    assert (ink_s != ink_e).sum() <= 0.25 * ink_e.sum()  # edge pixels: positions rounded to the pixel
    for k in (0, 37, 143):  # every leaf where it belongs: its ink's centre within a pixel
        x, y = 10 + 20 * (k % 12), 10 + 20 * (k // 12)
        box = (slice(y - 9, y + 10), slice(x - 9, x + 10))
        ys, xs = np.nonzero(ink_s[box])
        ye, xe = np.nonzero(ink_e[box])
        assert abs(ys.mean() - ye.mean()) < 1.0 and abs(xs.mean() - xe.mean()) < 1.0
    stroked = _leaves("fill:#66bb6a;stroke:#1b5e20;stroke-width:0.6")
    stamped, paths = _draft(stroked, True), _draft(stroked, False)
    colours = {tuple(c) for c in stamped[stamped[..., 0] < 250][:, :3].tolist()}
    assert {(0x66, 0xBB, 0x6A), (0x1B, 0x5E, 0x20)} <= colours  # fill and hairline stroke
    ink_s, ink_p = stamped[..., 0] < 250, paths[..., 0] < 250
    assert abs(int(ink_s.sum()) - int(ink_p.sum())) <= 0.2 * ink_p.sum()


def test_highlighted_instances_get_highlighted_sprites():
    drawing = _leaves("fill:#66bb6a")
    mask = np.zeros(len(drawing), bool)
    mask[:12] = True  # the first row
    img = _draft(drawing, True, mask)
    lit, plain = img[:20], img[40:]
    assert ((lit[..., 0] == 255) & (lit[..., 2] == 0)).any()  # the orange outline
    assert not ((plain[..., 0] == 255) & (plain[..., 2] == 0)).any()
    assert (
        np.abs(img.astype(int) - _draft(drawing, False, mask)).max(axis=2).astype(bool).sum()
        < 0.3 * (img[..., 0] < 250).sum()
    )


def test_translucent_large_or_thick_instances_are_drawn_as_paths():
    r = Renderer(240, 240)
    for style, scale in (
        ("fill:#66bb6a;fill-opacity:0.5", 0.5),  # blends: a sprite would not
        ("fill:#66bb6a", 4 * SPRITE_MAX_PX / 14),  # too big for a sprite
        ("fill:#66bb6a;stroke:#000;stroke-width:5", 0.5),  # a stroke wider than a hairline
    ):
        drawing = _leaves(style, scale, 3)
        calls: list = []
        plan = r._sprites.plan
        r._sprites.plan = lambda *args, plan=plan, calls=calls: calls.append(plan(*args)) or calls[-1]
        img = r.draw(drawing, None, False, True, background=(255, 255, 255, 255))
        r._sprites.plan = plan
        assert calls == [None] and (img[..., 0] < 250).any()


def test_sprites_follow_the_terminals_of_each_drawing():
    """One renderer draws drawings of other terminals: each gets sprites of its own."""
    r = Renderer(240, 240)
    for colour in ("#ff0000", "#0000ff", "#ff0000"):
        img = r.draw(_leaves(f"fill:{colour}"), None, False, True, background=(255, 255, 255, 255))
        ink = img[img[..., 1] < 250][:, :3]
        assert ink.size and {tuple(c) for c in ink.tolist()} == {
            (int(colour[1:3], 16), 0, int(colour[5:], 16))
        }


def test_a_sprite_is_drawn_only_for_enough_instances():
    """Instances all at different angles (a sprite each) are drawn as paths: a sprite costs as
    much to draw as several instances."""
    k = np.arange(100)
    drawing = make_drawing(
        [Terminal("A", LEAF, "fill:#66bb6a")],
        np.zeros(k.size),
        0.5 * np.exp(1j * np.deg2rad(3.3 * k)),
        10 + 20 * (k % 10) + 1j * (10 + 20 * (k // 10)),
        (0.0, 0.0, 200.0, 200.0),
    )
    r = Renderer(200, 200)
    calls: list = []
    plan = r._sprites.plan
    r._sprites.plan = lambda *args: calls.append(plan(*args)) or calls[-1]
    r.draw(drawing, None, False, True)
    assert calls == [None]


def test_instances_across_the_border_are_clipped_not_wrapped():
    """Stamped instances half outside the image paint only their inside part: nothing wraps
    around to the other side of the image."""
    k = np.arange(20)
    drawing = make_drawing(
        [Terminal("A", "M -6 -3 L 6 -3 L 6 3 L -6 3 Z", "fill:#ff0000")],
        np.zeros(k.size),
        np.ones(k.size),
        1 + 1j * (1 + 10 * k),  # across the left edge (and the top one)
        (0.0, 0.0, 200.0, 200.0),
    )
    stamped = _draft(drawing, True)[:, :, :3]
    paths = _draft(drawing, False)[:, :, :3]
    assert (stamped[:, :2] == (255, 0, 0)).all(axis=2).sum() >= 20 * 3  # the half-boxes inside
    assert (stamped[:, 20:] == 255).all()  # nothing wrapped to the right edge (or the bottom)
    assert (
        np.abs(stamped.astype(int) - paths).max(axis=2).astype(bool).sum()
        <= 0.2 * (paths[..., 1] < 250).sum()
    )
