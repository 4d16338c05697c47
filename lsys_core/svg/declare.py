"""The declarations a shape draws with: paints, stroke geometry, opacity, paint order, clip, mask.

A shape's computed style becomes the few declarations the scene keeps, in document units: paint
server references are rewritten for the element (:meth:`.resources.Resources.paint_server`),
stroke lengths are scaled by its transform, and clip paths and masks are rewritten in document
coordinates (:class:`.masking.Definitions`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable

from lsys_core.geometry.paths import ArrayPath
from lsys_core.memo import IdentityMemo
from lsys_core.svg.masking import EMPTY, Definitions
from lsys_core.svg.paint import paint_declarations, parse_paint, scale_of, stroke_declarations, unit_value
from lsys_core.svg.records import Ctx, box_of, paint_order
from lsys_core.svg.resources import Box

__all__ = ["DeclarationMemo", "shape_declarations"]

#: Distinct styles a :class:`DeclarationMemo` keeps (it starts again when full).
MEMO_SIZE = 4096


def shape_declarations(
    defs: Definitions, style: dict[str, str], ctx: Ctx, box: Callable[[], Box | None]
) -> dict[str, str] | None:
    """The declarations a shape draws with (None: clipped out or masked out entirely).

    ``box()`` is the shape's bounding box in its own coordinates (for ``objectBoundingBox``
    units), asked for only by a paint server, clip path or mask: the tight box of a curve costs
    more than everything else here (7.6 of 14 s reading 20,000 leaves when every shape had it).
    """
    ctm, vp = ctx.ctm, ctx.vp

    def server(ref: str):
        return defs.paint_server(ref, ctm, box(), vp)

    fill = parse_paint(style.get("fill", "black"), style, server, ctx.context)
    stroke = parse_paint(style.get("stroke", "none"), style, server, ctx.context)
    geometry_decls = None
    if stroke is not None:
        vector_effect = style.get("vector-effect", "none").strip().lower()
        scale = 1.0 if vector_effect == "non-scaling-stroke" else scale_of(ctm)
        geometry_decls = stroke_declarations(style, vp, scale)
        if geometry_decls is None:
            stroke = None
    decls = paint_declarations("fill", fill, unit_value(style.get("fill-opacity"), 1.0))
    if fill is not None and style.get("fill-rule", "nonzero").strip().lower() == "evenodd":
        decls["fill-rule"] = "evenodd"
    decls.update(paint_declarations("stroke", stroke, unit_value(style.get("stroke-opacity"), 1.0)))
    if geometry_decls:
        decls.update(geometry_decls)
    opacity = unit_value(style.get("opacity"), 1.0)
    if opacity < 1.0:
        decls["opacity"] = f"{opacity:.6g}"
    order = paint_order(style.get("paint-order"))
    if order.index("stroke") < order.index("fill"):
        decls["paint-order"] = "stroke"
    clip = defs.clip(style.get("clip-path"), ctm, box(), vp) if "clip-path" in style else None
    if clip == EMPTY:
        return None
    if clip:
        decls["clip-path"] = f"url(#{clip})"
    mask = defs.mask(style.get("mask"), ctm, box(), vp) if "mask" in style else None
    if mask == EMPTY:
        return None
    if mask:
        decls["mask"] = f"url(#{mask})"
    return decls


class DeclarationMemo:
    """:func:`shape_declarations` of shapes whose declarations depend only on their style.

    Charts, maps and patterns draw thousands of shapes with a few styles: reading 20,000 leaves
    spent 1.5 of 6.7 profiled seconds here.  A shape's declarations are reused when it has no
    paint server, clip path, mask or context paint (those depend on its box or its place) and
    its style, stroke scale and viewport equal an earlier shape's.  Such shapes share one
    dictionary: nothing changes it (group effects give a record its own copy before they add
    to it, :mod:`.group_effects`), and the scene writes each one as text once (copying it for
    every shape cost 10 ms of reading a 50,052-leaf grid, writing it 50 ms).

    Styles come shared from the cascade (:meth:`.style.Cascade.computed`), so what a style
    object contributes to the key is remembered by its identity, as is the stroke scale of the
    last matrix (siblings share theirs): building the key from the style's items cost 0.19 of
    5.3 profiled seconds reading 20,000 leaves.
    """

    def __init__(self) -> None:
        self._memo: dict[tuple, dict[str, str]] = {}
        self._styles: IdentityMemo[dict[str, str], tuple | None] = IdentityMemo(MEMO_SIZE)
        self._scale: tuple[tuple, float] | None = None

    def get(
        self, defs: Definitions, style: dict[str, str], ctx: Ctx, path: ArrayPath
    ) -> dict[str, str] | None:
        """Return :func:`shape_declarations` for a shape drawing ``path``, from memory when it can."""
        key = self._key(style, ctx)
        if key is None:
            return shape_declarations(defs, style, ctx, _box(path))
        decls = self._memo.get(key)
        if decls is None:
            decls = shape_declarations(defs, style, ctx, _box(path))
            if decls is None:  # cannot happen without clips or masks; never remembered
                return None
            if len(self._memo) >= MEMO_SIZE:
                self._memo.clear()
            self._memo[key] = decls
        return decls

    def shared(self, style: dict[str, str], ctx: Ctx) -> bool:
        """Whether the declarations of shapes drawn with ``style`` in ``ctx`` depend on nothing else."""
        return self._key(style, ctx) is not None

    def _key(self, style: dict[str, str], ctx: Ctx) -> tuple | None:
        if ctx.context is not None:
            return None
        items = self._styles.get(style, self._style_key)
        if items is None:
            return None
        scale = self._scale
        if scale is None or scale[0] is not ctx.ctm:
            self._scale = scale = (ctx.ctm, scale_of(ctx.ctm))
        return items, scale[1], ctx.vp

    @staticmethod
    def _style_key(style: dict[str, str]) -> tuple | None:
        """What a style contributes to the key; None when its declarations depend on more than it."""
        if "clip-path" in style or "mask" in style:
            return None
        items = tuple(style.items())
        if any("url(" in v or "context-" in v for _k, v in items):
            return None
        return items


def _box(path: ArrayPath) -> Callable[[], Box | None]:
    """The tight box of ``path`` in its own coordinates, computed when first asked for."""
    return functools.cache(lambda: box_of(path))
