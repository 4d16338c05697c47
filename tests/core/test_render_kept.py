"""The own renderer draws content kept as is (text, images) at its place in the paint order."""

from __future__ import annotations

import base64
import shutil
import subprocess
from dataclasses import replace

import numpy as np
import pytest

from lsys_core.derive.derivation import derive
from lsys_core.grammar.model import Terminal, Verbatim
from lsys_core.pipeline import infer
from lsys_core.render.kept import Kept
from lsys_core.render.raster import render
from lsys_core.render.svg import drawing_to_svg
from lsys_core.svg.parse import parse_svg

from .scenes import make_drawing

SQUARE = "M0 0 L10 0 L10 10 L0 10 Z"
TEXT = '<text x="100" y="70" style="font-family:sans-serif;font-size:40px;fill:#000">Hi</text>'


def ink(img: np.ndarray) -> np.ndarray:
    return img[..., 3] >= 128


def with_kept(xml: str, order: int = 1, terminals=None, n: int = 1, defs: str = ""):
    """A 200×100 drawing of ``n`` red squares (x 10..30, 40..60, ...) and one kept item."""
    terminals = terminals or [Terminal("S", SQUARE, "fill:#ff0000")]
    b = [10 + 30 * k + 40j for k in range(n)]
    drawing = make_drawing(terminals, [0] * n, [2] * n, b, (0.0, 0.0, 200.0, 100.0))
    return replace(drawing, verbatim=(Verbatim(order, xml, "<text>"),), defs=defs)


def test_derived_text_is_drawn_where_its_box_is_and_not_without_it():
    svg = (
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 200 100" width="200" height="100">'
        '<rect x="10" y="10" width="20" height="20" fill="red"/>'
        '<rect x="40" y="10" width="20" height="20" fill="red"/>'
        '<rect x="70" y="10" width="20" height="20" fill="red"/>' + TEXT + "</svg>"
    )
    drawing = derive(infer(parse_svg(svg.encode())).grammar)
    assert len(drawing.verbatim) == 1
    img = render(drawing, 200, 100)
    # "Hi" at 40 px: baseline y 70, cap height ~29 px, about 35 px wide from x 100.
    box = ink(img)[38:71, 98:140]
    assert box.mean() > 0.2
    text_only = ink(img).copy()
    text_only[:, :95] = False
    ys, xs = np.nonzero(text_only)
    assert ys.min() >= 38 and ys.max() <= 71 and xs.min() >= 100 and xs.max() <= 140
    bare = render(replace(drawing, verbatim=()), 200, 100)
    assert not ink(bare)[:, 95:].any()
    assert (ink(bare)[:, :95] == ink(img)[:, :95]).all()  # the instances are unchanged


@pytest.mark.skipif(shutil.which("rsvg-convert") is None, reason="needs rsvg-convert (librsvg2-bin)")
def test_text_inks_the_pixels_rsvg_inks():
    import skia

    drawing = with_kept(
        '<g transform="matrix(1 0 0 1 20 0)"><text x="80" y="60" style="font-family:sans-serif;'
        'font-size:30px;font-weight:bold;text-anchor:middle;fill:#000">Ab'
        '<tspan dy="10" style="font-style:italic">cd</tspan></text></g>'
    )
    png = subprocess.run(
        ["rsvg-convert", "-w", "400", "-h", "200"],
        input=drawing_to_svg(drawing).encode(),
        capture_output=True,
        check=True,
        timeout=60,
    ).stdout
    theirs = ink(skia.Image.MakeFromEncoded(skia.Data.MakeWithCopy(png)).toarray())
    ours = ink(render(drawing, 400, 200))
    assert theirs[:, 70:].sum() > 500  # the text is there
    differ = (theirs != ours).sum() / (theirs | ours).sum()
    assert differ < 0.03  # same face, size, anchor and shifts (measured 0.6 %: edge pixels)


@pytest.mark.parametrize("text_on_top", [True, False])
def test_paint_order_of_text_and_shapes(text_on_top):
    big = Terminal("B", "M0 0 L100 0 L100 50 L0 50 Z", "fill:#ff0000")
    xml = '<text x="100" y="70" style="font-family:sans-serif;font-size:40px;fill:#0000ff">Hi</text>'
    drawing = make_drawing([big], [0], [1], [90 + 25j], (0.0, 0.0, 200.0, 100.0))
    drawing = replace(drawing, verbatim=(Verbatim(1 if text_on_top else 0, xml),))
    img = render(drawing, 200, 100)
    glyphs = ink(render(replace(drawing, symbol=np.array([5], np.int32)), 200, 100))  # text alone
    assert glyphs.sum() > 100
    over = img[glyphs & (np.arange(200)[None, :] > 92) & (np.arange(100)[:, None] < 73)]
    blue = (over[:, 2] > 200) & (over[:, 0] < 60)
    red = (over[:, 0] > 200) & (over[:, 2] < 60)
    if text_on_top:
        assert blue.mean() > 0.6 and red.mean() < 0.3
    else:
        assert red.mean() > 0.95 and not blue.any()


def test_steps_put_kept_items_between_the_instances():
    drawing = with_kept(TEXT, order=2, n=4)
    kept = Kept(drawing)
    idx = np.arange(4)
    assert list(kept.steps(idx, [])) == [("each", 0, 2, []), ("kept", 2, 2, [0]), ("each", 2, 4, [])]
    # A batchable run crossing the kept item is split around it.
    assert list(kept.steps(idx, [(1, 4)])) == [
        ("each", 0, 1, []),
        ("run", 1, 2, []),
        ("kept", 2, 2, [0]),
        ("run", 2, 4, []),
    ]
    # After every instance: drawn once, last.
    assert list(Kept(with_kept(TEXT, order=4, n=4)).steps(idx, [])) == [
        ("each", 0, 4, []),
        ("kept", 4, 4, [0]),
    ]
    # Instances culled before the item: it goes after the visible ones drawn before it.
    assert list(kept.steps(np.array([0, 3]), [])) == [
        ("each", 0, 1, []),
        ("kept", 1, 1, [0]),
        ("each", 1, 2, []),
    ]


def test_anchor_hidden_text_and_transparent_groups():
    def xs(xml):
        img = ink(render(with_kept(xml, order=0, n=0), 200, 100))
        cols = np.flatnonzero(img.any(axis=0))
        return (int(cols.min()), int(cols.max())) if cols.size else None

    start = xs('<text x="100" y="60" style="font-size:20px">Hello</text>')
    middle = xs('<text x="100" y="60" style="font-size:20px;text-anchor:middle">Hello</text>')
    end = xs('<text x="100" y="60" style="font-size:20px;text-anchor:end">Hello</text>')
    assert start is not None and middle is not None and end is not None
    assert start[0] >= 99 and end[1] <= 101
    assert abs((middle[0] + middle[1]) / 2 - 100) <= 2
    assert xs('<text x="100" y="60" style="font-size:20px;opacity:0">Hello</text>') is None
    assert xs('<g style="display:none"><text x="100" y="60">Hello</text></g>') is None
    assert xs('<text x="100" y="60" style="visibility:hidden">Hello</text>') is None
    # Per-character x positions: each letter where its x says.
    spread = xs('<text x="10 150" y="60" style="font-size:20px">AB</text>')
    assert spread is not None and spread[0] <= 12 and spread[1] >= 150


def png_of(rgba: np.ndarray) -> bytes:
    import skia

    image = skia.Image.fromarray(np.ascontiguousarray(rgba))
    return bytes(image.encodeToData(skia.EncodedImageFormat.kPNG, 100))


def test_data_uri_images_with_aspect_ratio_and_no_fetching(tmp_path):
    pixels = np.zeros((10, 20, 4), np.uint8)
    pixels[..., 1] = pixels[..., 3] = 255  # green, 2:1
    uri = "data:image/png;base64," + base64.b64encode(png_of(pixels)).decode()
    img = render(with_kept(f'<image x="100" y="0" width="100" height="100" href="{uri}"/>', n=0), 200, 100)
    green = (img[..., 1] > 200) & (img[..., 3] > 200)
    ys, xs = np.nonzero(green)
    # xMidYMid meet: 100×50 in the middle of the box.
    assert xs.min() == 100 and xs.max() == 199 and ys.min() in (25, 26) and ys.max() in (73, 74)
    stretched = render(
        with_kept(
            f'<image x="100" y="0" width="100" height="100" preserveAspectRatio="none" href="{uri}"/>', n=0
        ),
        200,
        100,
    )
    assert (stretched[5:95, 105:195, 1] > 200).all()
    # A file the href names is never read, whatever it holds.
    local = tmp_path / "green.png"
    local.write_bytes(png_of(pixels))
    for href in (str(local), local.as_uri(), "http://127.0.0.1:9/x.png"):
        out = render(with_kept(f'<image x="0" y="0" width="100" height="100" href="{href}"/>', n=0), 200, 100)
        assert not ink(out).any()


def test_text_on_a_path_follows_it():
    defs = '<defs><path id="p" d="M10 90 L190 10"/></defs>'
    xml = '<text style="font-size:16px"><textPath href="#p">along the diagonal line</textPath></text>'
    img = ink(render(with_kept(xml, n=0, defs=defs), 200, 100))
    ys, xs = np.nonzero(img)
    assert xs.size > 100
    # Every inked pixel lies within a glyph's height of the line y = 90 - 80 (x - 10) / 180.
    line = 90 - 80 * (xs - 10) / 180
    assert (np.abs(ys - line) < 18).all()
    assert xs.max() - xs.min() > 100 and ys.max() - ys.min() > 40  # it runs along, not across


@pytest.mark.skipif(shutil.which("fc-match") is None, reason="needs fc-match (fontconfig)")
@pytest.mark.parametrize("family", ["Times New Roman", "No Such Family, serif", "sans-serif", "monospace"])
def test_families_resolve_as_fontconfig_does(family):
    from lsys_core.render.fonts import typeface

    expected = subprocess.run(
        ["fc-match", "-f", "%{family[0]}", family], capture_output=True, text=True, check=True, timeout=60
    ).stdout
    face, _ = typeface(family, 400, False)
    assert face.getFamilyName() == expected
    bold, embolden = typeface(family, 700, False)
    assert bold.fontStyle().weight() >= 600 or embolden


GRADIENTS = (
    '<defs><linearGradient id="base"><stop offset="0" stop-color="#ff0000"/>'
    '<stop offset="1" stop-color="#0000ff"/></linearGradient>'
    '<linearGradient id="lg" href="#base"/>'
    '<radialGradient id="rg" gradientUnits="userSpaceOnUse" cx="100" cy="50" r="60">'
    '<stop offset="0" stop-color="#00ff00"/><stop offset="100%" stop-color="#000000"/></radialGradient>'
    '<linearGradient id="empty"/><pattern id="pat" width="4" height="4"/></defs>'
)
BLOCK = (
    '<text x="10" y="70" style="font-family:sans-serif;font-size:50px;font-weight:bold;fill:{}">MMMM</text>'
)


def test_gradients_on_text_follow_its_box_and_href_chains():
    img = render(with_kept(BLOCK.format("url(#lg)"), n=0, defs=GRADIENTS), 200, 100)
    solid = img[..., 3] == 255
    cols = np.flatnonzero(solid.any(axis=0))
    left, right = (
        img[solid & (np.arange(200) < cols.min() + 6)],
        img[solid & (np.arange(200) > cols.max() - 6)],
    )
    assert left[:, 0].mean() > 200 and left[:, 2].mean() < 60  # red where the box starts
    assert right[:, 2].mean() > 200 and right[:, 0].mean() < 60  # blue where it ends
    radial = render(with_kept(BLOCK.format("url(#rg)"), n=0, defs=GRADIENTS), 200, 100)
    inked = radial[..., 3] == 255
    near = radial[
        inked & (np.abs(np.arange(200) - 100) < 8)[None, :] & (np.abs(np.arange(100) - 50) < 8)[:, None]
    ]
    far = radial[inked & (np.arange(200) < 25)[None, :]]
    assert near[:, 1].mean() > 180 and far[:, 1].mean() < near[:, 1].mean() - 60
    # No stops: nothing drawn.  A pattern (not drawn here): the fallback colour, else nothing.
    assert not ink(render(with_kept(BLOCK.format("url(#empty)"), n=0, defs=GRADIENTS), 200, 100)).any()
    assert not ink(render(with_kept(BLOCK.format("url(#pat)"), n=0, defs=GRADIENTS), 200, 100)).any()
    fallback = render(with_kept(BLOCK.format("url(#pat) #00ff00"), n=0, defs=GRADIENTS), 200, 100)
    assert (fallback[fallback[..., 3] == 255][:, 1] == 255).all()
