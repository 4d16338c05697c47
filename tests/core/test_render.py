"""Tests of raster rendering with skia."""

from __future__ import annotations

import struct
import zlib

import numpy as np
import pytest

from lsys_core.derive.model import Drawing
from lsys_core.errors import LsysError
from lsys_core.grammar.model import Terminal
from lsys_core.render.raster import HIGHLIGHT, Renderer, render, render_png

from .scenes import make_drawing

SQUARE = "M0 0 L10 0 L10 10 L0 10 Z"


def drawing_of(terminals, symbol, a, b, viewbox=(0.0, 0.0, 100.0, 100.0), size=None) -> Drawing:
    return make_drawing(terminals, symbol, a, b, viewbox, size, rule=0)


def test_filled_square_pixels():
    dr = drawing_of([Terminal("S", SQUARE, "fill:#ff0000")], [0], [2], [20 + 40j])
    img = render(dr, 100, 100)
    assert img.shape == (100, 100, 4) and img.dtype == np.uint8
    # The square covers x 20..40, y 40..60 (1 drawing unit = 1 pixel).
    inside = img[45:55, 25:35]
    assert (inside == [255, 0, 0, 255]).all()
    outside = np.ones((100, 100), bool)
    outside[39:61, 19:41] = False
    assert (img[outside][:, 3] == 0).all()
    assert (img[..., 3] > 0).sum() == pytest.approx(400, abs=45)


def test_background_and_view_fit():
    dr = drawing_of([Terminal("S", SQUARE, "fill:#0000ff")], [0], [1], [0])
    # View of the square only, into a wide image: scaled to 50 px tall and centred horizontally.
    img = render(dr, 200, 50, view=(0, 0, 10, 10), background=(255, 255, 255, 255))
    blue = (img[..., 2] == 255) & (img[..., 0] == 0)
    ys, xs = np.nonzero(blue)
    assert ys.min() == 0 and ys.max() == 49
    assert xs.min() == 75 and xs.max() == 124
    assert (img[:, :70] == 255).all()  # white opaque background


def test_stroke_only_outline():
    ring = Terminal("R", SQUARE, "fill:none;stroke:#000000;stroke-width:1")
    img = render(drawing_of([ring], [0], [5], [25 + 25j]), 100, 100)
    alpha = img[..., 3]
    assert alpha[50, 50] == 0  # interior empty
    assert alpha[25, 50] > 0 and alpha[75, 50] > 0 and alpha[50, 25] > 0  # edges drawn
    assert alpha[10, 10] == 0


def test_opacity_and_evenodd():
    half = Terminal("H", SQUARE, "fill:#000000;opacity:0.5")
    img = render(drawing_of([half], [0], [10], [0]), 100, 100)
    assert abs(int(img[50, 50, 3]) - 128) <= 1
    donut = "M0 0 L10 0 L10 10 L0 10 Z M3 3 L7 3 L7 7 L3 7 Z"  # same winding: nonzero fills the hole
    filled = render(drawing_of([Terminal("D", donut, "fill:#000")], [0], [10], [0]), 100, 100)
    holed = render(
        drawing_of([Terminal("D", donut, "fill:#000;fill-rule:evenodd")], [0], [10], [0]), 100, 100
    )
    assert filled[50, 50, 3] == 255
    assert holed[50, 50, 3] == 0 and holed[15, 15, 3] == 255


def test_draft_mode_matches_full_mode_roughly():
    leaf = Terminal(
        "A", "M0 0 C6 -6 16 -5 22 0 C15 3 6 6 0 0 Z", "fill:#2e7d32;stroke:#1b5e20;stroke-width:0.5"
    )
    rng = np.random.default_rng(1)
    n = 300
    dr = drawing_of(
        [leaf],
        np.zeros(n),
        rng.uniform(0.5, 2, n) * np.exp(1j * rng.uniform(0, 6.3, n)),
        rng.uniform(0, 400, n) + 1j * rng.uniform(0, 300, n),
        (0, 0, 400, 300),
    )
    r = Renderer(400, 300)
    full = r.draw(dr).copy()
    draft = r.draw(dr, draft=True)
    a, b = full[..., 3] > 127, draft[..., 3] > 127
    iou = (a & b).sum() / (a | b).sum()
    assert iou > 0.9


def test_renderer_returns_its_own_pixels_without_copy():
    dr = drawing_of([Terminal("S", SQUARE, "fill:#00ff00")], [0], [1], [0])
    r = Renderer(64, 48)
    first = r.draw(dr)
    second = r.draw(dr, view=(0, 0, 10, 10))
    assert first is second is r.pixels
    assert first.shape == (48, 64, 4)
    assert first[24, 32, 1] == 255  # the second draw is visible through the first array
    r.resize(32, 32)
    assert r.size == (32, 32) and r.draw(dr).shape == (32, 32, 4)


def test_highlight_colours_selected_instances():
    sq = Terminal("S", SQUARE, "fill:#000000")
    dr = drawing_of([sq], [0, 0], [2, 2], [10 + 10j, 60 + 10j])
    img = render(dr, 100, 100, highlight=np.array([1]))
    assert tuple(img[20, 20, :3]) == (0, 0, 0)
    r, _, b = img[20, 70, :3].astype(int)
    assert r > 100 and r > b  # orange tint
    mask_img = render(dr, 100, 100, highlight=np.array([True, False]))
    assert mask_img[20, 20, 0] > 100 and tuple(mask_img[20, 70, :3]) == (0, 0, 0)
    assert HIGHLIGHT[0] == 255
    draft = render(dr, 100, 100, highlight=np.array([1]), draft=True)  # batched outlines, hairline
    assert tuple(draft[20, 20, :3]) == (0, 0, 0)
    r, _, b = draft[20, 70, :3].astype(int)
    assert r > 100 and r > b


def test_culling_and_empty_drawing():
    sq = Terminal("S", SQUARE, "fill:#000")
    far = drawing_of([sq], [0, 0], [1, 1], [1e6, 5 + 5j])
    img = render(far, 50, 50, view=(0, 0, 50, 50))
    assert img[..., 3].sum() > 0
    empty = drawing_of([sq], [], [], [])
    assert (render(empty, 10, 10, background=(1, 2, 3, 255)) == [1, 2, 3, 255]).all()
    broken = drawing_of([Terminal("X", "M0 0 L", "fill:#000"), Terminal("Y", "", "")], [0, 1], [1, 1], [0, 0])
    assert render(broken, 10, 10)[..., 3].max() == 0


def test_default_view_from_bounds():
    sq = Terminal("S", SQUARE, "fill:#000")
    dr = drawing_of([sq], [0], [1], [1000 + 1000j], viewbox=None)
    img = render(dr, 50, 50)
    covered = (img[..., 3] > 0).mean()
    assert 0.8 < covered < 1.0  # fitted with a small margin


def test_invalid_size():
    with pytest.raises(LsysError):
        Renderer(0, 10)


def _png_info(data: bytes) -> tuple[int, int]:
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    length, kind = struct.unpack(">I4s", data[8:16])
    assert kind == b"IHDR"
    ihdr = data[16 : 16 + length]
    assert zlib.crc32(b"IHDR" + ihdr) == struct.unpack(">I", data[16 + length : 20 + length])[0]
    return struct.unpack(">II", ihdr[:8])


def test_render_png(tmp_path):
    dr = drawing_of([Terminal("S", SQUARE, "fill:#f00")], [0], [3], [10 + 10j], (0, 0, 40, 20), ("40", "20"))
    out = tmp_path / "out.png"
    render_png(dr, out)
    assert _png_info(out.read_bytes()) == (40, 20)
    render_png(dr, out, width=200)
    assert _png_info(out.read_bytes()) == (200, 100)
    with pytest.raises(LsysError, match="cannot write"):
        render_png(dr, tmp_path / "missing" / "x.png", 10, 10)
    assert [p.name for p in tmp_path.iterdir()] == ["out.png"]


def test_draft_highlight_blends_in_one_pass() -> None:
    """A highlighted draft instance shows its fill under the translucent highlight and the outline;
    a stroke wider than a hairline stays under the outline."""
    from lsys_core.render.passes import HIGHLIGHT_FILL, over

    sq = Terminal("S", SQUARE, "fill:#0000ff")
    dr = drawing_of([sq], [0, 0], [2, 2], [10 + 10j, 60 + 10j])
    full = render(dr, 100, 100, highlight=np.array([1]), antialias=False)
    draft = render(dr, 100, 100, highlight=np.array([1]), draft=True)
    assert tuple(draft[20, 20]) == (0, 0, 255, 255)  # not highlighted
    blend = over(HIGHLIGHT_FILL, (0, 0, 255, 255))
    assert np.abs(draft[20, 70].astype(int) - blend).max() <= 1
    assert np.abs(full[20, 70].astype(int) - draft[20, 70].astype(int)).max() <= 2
    assert tuple(draft[10, 70, :3]) == HIGHLIGHT[:3]  # the outline on the square's top edge
    thick = Terminal("S", SQUARE, "fill:#0000ff;stroke:#00ff00;stroke-width:4")
    dr = drawing_of([thick], [0], [2], [50 + 50j])
    draft = render(dr, 100, 100, highlight=np.array([0]), draft=True)
    assert tuple(draft[48, 60, :3]) == (0, 255, 0)  # inside the stroke (y 48..52), off the outline
    assert over((9, 9, 9, 255), (200, 0, 0, 255)) == (9, 9, 9, 255)
    assert over((9, 9, 9, 0), (200, 0, 0, 128)) == (200, 0, 0, 128)
