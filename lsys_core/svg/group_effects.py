"""Group effects -- opacity, clip path, mask -- applied to what a group drew.

A group's content has become records by the time its effects are known, so they are applied to
the records it produced: a clip path is intersected with each record's own (clipping distributes
over what is painted), a mask is given to each record, and opacity multiplies into each record's
opacity.  The last is exact where the group's children do not overlap one another and close
otherwise (a group drawn at half opacity shows no overlap between its children); the scene keeps
no groups, so this is the one approximation of the reader.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import TYPE_CHECKING

from lsys_core.geometry.bezier import transform_cubics
from lsys_core.svg.masking import EMPTY
from lsys_core.svg.paint import unit_value
from lsys_core.svg.shapes import tight_bbox
from lsys_core.svg.tree import describe
from lsys_core.svg.values import IDENTITY, invert, multiply
from lsys_core.svg.verbatim import wrap

if TYPE_CHECKING:
    from lsys_core.svg.walk import Ctx, Reader

__all__ = ["apply"]


def _group_box(reader: Reader, ctx: Ctx, start: int) -> tuple[float, float, float, float] | None:
    """The bounding box of the shapes a group drew, in the group's own coordinates."""
    from lsys_core.svg.walk import ShapeRecord

    inv = invert(ctx.ctm)
    if inv is None:
        return None
    lo_x = lo_y = float("inf")
    hi_x = hi_y = float("-inf")
    for rec in reader.records[start:]:
        if not isinstance(rec, ShapeRecord) or rec.path.cubics.shape[0] == 0:
            continue
        b = tight_bbox(transform_cubics(rec.path.cubics, multiply(inv, rec.ctm)))
        if b is None:
            continue
        lo_x, lo_y, hi_x, hi_y = min(lo_x, b[0]), min(lo_y, b[1]), max(hi_x, b[2]), max(hi_y, b[3])
    if lo_x > hi_x:
        return None
    return (lo_x, lo_y, hi_x - lo_x, hi_y - lo_y)


def apply(
    reader: Reader, el: ET.Element, style: dict[str, str], ctx: Ctx, start: int, clip: str | None = None
) -> None:
    """Apply the opacity, clip path and mask of group ``el`` (and a viewport ``clip``) to its records."""
    from lsys_core.svg.walk import ShapeRecord

    opacity = unit_value(style.get("opacity"), 1.0)
    clip_value = style.get("clip-path")
    mask_value = style.get("mask")
    has_clip = clip_value is not None and clip_value.strip().lower() != "none"
    has_mask = mask_value is not None and mask_value.strip().lower() != "none"
    if opacity >= 1.0 and not has_clip and not has_mask and clip is None:
        return
    res = reader.resources
    box = _group_box(reader, ctx, start) if has_clip or has_mask else None
    own = res.clip(clip_value, ctx.ctm, box, ctx.vp) if has_clip else None
    mask = res.mask(mask_value, ctx.ctm, box, ctx.vp) if has_mask else None
    if EMPTY in (own, mask):
        del reader.records[start:]
        return
    clip = res.intersect(own, clip)
    for rec in reader.records[start:]:
        if isinstance(rec, ShapeRecord):
            if rec.hidden:
                continue
            st = rec.style = dict(rec.style)  # (records may share one: :class:`.declare.DeclarationMemo`)
            if opacity < 1.0:
                st["opacity"] = f"{unit_value(st.get('opacity'), 1.0) * opacity:.6g}"
            if clip is not None:
                mine = st.get("clip-path")
                mine_id = mine[5:-1] if mine else None
                both = res.intersect(mine_id, clip)
                if both == EMPTY:
                    st["opacity"] = "0"
                elif both:
                    st["clip-path"] = f"url(#{both})"
            if mask is not None:
                if "mask" in st:
                    reader.notes.append(
                        f"ignored the mask of {describe(el)} on content that has its own mask"
                    )
                else:
                    st["mask"] = f"url(#{mask})"
        else:
            extra = {}
            if opacity < 1.0:
                extra["opacity"] = f"{opacity:.6g}"
            if clip is not None:
                extra["clip-path"] = f"url(#{clip})"
            if mask is not None:
                extra["mask"] = f"url(#{mask})"
            rec.xml = wrap(rec.xml, IDENTITY, {}, extra)
