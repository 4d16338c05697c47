"""What the SVG reader kept, read back for the tests: an element's style, its clip path's outline."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from lsys_core.geometry import cubics_from_d


def style_of(element) -> dict[str, str]:
    """The element's style declarations as a dictionary."""
    return dict(p.split(":", 1) for p in element.style.split(";") if p)


def clip_box(scene, element) -> tuple[float, float, float, float]:
    """``(xmin, xmax, ymin, ymax)`` of the control points of the one-path clip path of ``element``."""
    ref = style_of(element)["clip-path"]
    defs = ET.fromstring(f'<defs xmlns="http://www.w3.org/2000/svg">{scene.defs}</defs>')
    (clip,) = [c for c in defs if "url(#" + c.get("id") + ")" == ref]
    c, _, _ = cubics_from_d(clip[0].get("d"))
    return c.real.min(), c.real.max(), c.imag.min(), c.imag.max()
