"""The rendering walk: every element of the document, in paint order, into scene records.

:class:`Reader` visits the tree as a renderer would: the cascade gives each element its style,
transforms and viewports (nested ``<svg>``, ``<symbol>`` through ``<use>``, markers) compose into
one matrix per element, and each drawable shape becomes a :class:`ShapeRecord` (geometry in its
own coordinates, the matrix, and what it draws with), numbered in paint order.  Content that is
not geometry -- text, images, foreign objects, unknown elements, anything under a filter -- becomes
a :class:`VerbatimRecord`, a self-contained copy in document coordinates at its place in the
order.  Group effects (opacity, clip path, mask) are applied to the records a group produced once
its content is known.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections import Counter
from dataclasses import dataclass, field, replace

from lsys_core.errors import LimitError
from lsys_core.geometry.paths import ArrayPath
from lsys_core.svg import group_effects, markers
from lsys_core.svg.css import StyleSheet
from lsys_core.svg.declare import DeclarationMemo
from lsys_core.svg.facts import StyleFacts, StyleFactsMemo
from lsys_core.svg.masking import Definitions
from lsys_core.svg.paint import anisotropy
from lsys_core.svg.pathcache import DEFAULT_MAX_SEGMENTS, PathCache
from lsys_core.svg.records import (
    SHAPES,
    Ctx,
    ShapeRecord,
    VerbatimRecord,
    length_or,
    only_part,
    source_names,
    switch_child,
)
from lsys_core.svg.shapes import Geometry, KeepAsIs, draws_cap_dots, shape_geometry
from lsys_core.svg.siblings import Run, same_run
from lsys_core.svg.style import DEFAULT_FONT_SIZE, Cascade
from lsys_core.svg.tree import Tree, describe, href_of, local_name, shown
from lsys_core.svg.values import (
    IDENTITY,
    Matrix,
    Viewport,
    multiply,
    parse_transform,
    parse_viewbox,
    viewbox_transform,
)
from lsys_core.svg.verbatim import inherited_declarations, wrap

__all__ = ["Ctx", "Reader", "ShapeRecord", "VerbatimRecord"]

_MARKABLE = frozenset({"path", "line", "polyline", "polygon"})
_CONTAINERS = frozenset({"g", "a", "switch", "svg"})
#: Elements that draw nothing where they stand.
_NOT_DRAWN = frozenset(
    {
        "defs", "clipPath", "mask", "marker", "pattern", "symbol", "linearGradient", "radialGradient",
        "filter", "style", "script", "title", "desc", "metadata", "font", "font-face", "cursor", "view",
        "stop", "color-profile",
    }
)  # fmt: skip
_ANIMATION = frozenset({"animate", "animateMotion", "animateTransform", "animateColor", "set"})
#: Content kept as is (not geometry to infer rules from).
_VERBATIM = frozenset({"text", "image", "foreignObject"})


@dataclass
class Reader:
    """Walks a parsed document into records (see the module docstring)."""

    tree: Tree
    name: str
    max_elements: int
    max_depth: int
    records: list[ShapeRecord | VerbatimRecord] = field(default_factory=list)
    skips: Counter = field(default_factory=Counter)
    kept: Counter = field(default_factory=Counter)
    notes: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        sheet = StyleSheet()
        for el in self.tree.of_kind("style"):  # whatever its type says, as renderers read it
            sheet.add("".join(el.itertext()))
        self.notes.extend(sheet.notes)
        self.cascade = Cascade(self.tree, sheet)
        self.paths = PathCache(self.tree, self.name)
        self.segments = 0
        self.resources = Definitions(
            self.tree, self.style_at, self.cascade.specified, self._clip_geometry, self.notes
        )
        self._style_cache: dict[int, dict[str, str]] = {}
        self._declarations = DeclarationMemo()
        self._names = source_names(self.tree)
        self.order = 0
        self.root_font = DEFAULT_FONT_SIZE
        self._last_anisotropy: tuple[Matrix, float] | None = None
        self._facts = StyleFactsMemo()
        self._run: Run | None = None
        self._runs = not self.cascade.sheet.rules  # (see :mod:`.siblings`)

    # -- styles ---------------------------------------------------------------------------------

    def style_at(self, el: ET.Element) -> dict[str, str]:
        """The computed style of an element where it stands in the document (cached)."""
        key = id(el)
        got = self._style_cache.get(key)
        if got is None:
            chain = [el, *self.tree.ancestors(el)]
            style: dict[str, str] = {}
            for node in reversed(chain):
                cached = self._style_cache.get(id(node))
                style = cached if cached is not None else self.cascade.computed(node, style, self.root_font)
                self._style_cache[id(node)] = style
            got = style
        return got

    def _clip_geometry(self, el: ET.Element, vp: Viewport) -> ArrayPath | None:
        try:
            geom, _ = shape_geometry(el, local_name(el.tag) or "", vp, self.paths.get, rows=False)
        except KeepAsIs:
            return None
        return None if geom is None else geom.path

    # -- records --------------------------------------------------------------------------------

    def _next_order(self) -> int:
        if len(self.records) >= self.max_elements:
            raise LimitError(f"{self.name} draws more than {self.max_elements:,} elements")
        self.order += 1
        return self.order - 1

    def keep_as_is(self, el: ET.Element, ctx: Ctx, why: str | None = None) -> None:
        """Record an element (and its content) as markup in document coordinates."""
        tag = local_name(el.tag) or "?"
        inner = self.resources.content_markup(el)
        xml = wrap(inner, ctx.ctm, inherited_declarations(ctx.style))
        what = describe(el, tag)
        if tag == "text":
            text = " ".join("".join(el.itertext()).split())
            what = f"<text> {shown(text, 30)}" if text else what
        self.records.append(VerbatimRecord(xml, what + (f" ({why})" if why else ""), self._next_order()))
        self.kept[f"<{tag}>" + (f" ({why})" if why else "")] += 1

    # -- the walk -------------------------------------------------------------------------------

    def walk(self, el: ET.Element, ctx: Ctx) -> None:
        """Draw one element (and its content) in context."""
        tag = local_name(el.tag)
        if tag is None or tag in _NOT_DRAWN:
            return
        if tag in _ANIMATION:
            self.skips["animation (not kept: the drawing is static)"] += 1
            return
        if ctx.depth > self.max_depth:
            raise LimitError(f"{self.name}: elements are nested more than {self.max_depth} levels deep")
        style = self.cascade.computed(el, ctx.style, self.root_font)
        facts = self._facts.get(style)
        if not facts.displayed:
            return
        font = facts.font
        vp = ctx.vp if font == ctx.vp.font_size and font else ctx.vp._replace(font_size=font)
        notes = len(self.notes)
        own = self._transform(el, style, vp)
        ctm = multiply(ctx.ctm, own) if own is not None else ctx.ctm
        # (made directly: ``dataclasses.replace`` cost 0.35 of 5.3 profiled seconds for 20,000 leaves)
        inner = Ctx(ctm, style, vp, ctx.depth + 1, ctx.uses, ctx.chain, ctx.context)
        if facts.filtered:
            self.keep_as_is(el, ctx, "filter")
            return
        if (
            own is not None
            and own != IDENTITY
            and (el.get("transform-origin") or style.get("transform-origin"))
        ):
            self.keep_as_is(el, ctx, "transform-origin: renderers differ")
            return
        if tag in SHAPES:
            run = Run(el, tag, inner, facts) if self._runs and len(self.notes) == notes else None
            self._run = run
            self.shape(el, tag, inner, ctx, facts, run)
            return
        start = len(self.records)
        clip = None
        if tag in _CONTAINERS:
            body = inner
            if tag == "svg" and el is not self.tree.root:
                entered = self._viewport(el, inner, ctx)
                if entered is None:
                    return
                body, clip = entered
            self._children(switch_child(el) if tag == "switch" else list(el), body)
        elif tag == "use":
            self.use(el, inner)
        elif tag != "symbol":
            self.keep_as_is(el, ctx)
            return
        if len(self.records) > start:
            group_effects.apply(self, el, style, inner, start, clip)

    def _children(self, children: list[ET.Element], body: Ctx) -> None:
        """Draw the children of a container in ``body``; like siblings share a :class:`.siblings.Run`."""
        last: Run | None = None
        path_of, names = self.paths.get, self._names
        for child in children:
            if not isinstance(child.tag, str):
                continue
            if last is not None and same_run(last, child):
                # A plain path run draws each like sibling as its first path (:attr:`.siblings.Run.plain`).
                if last.plain is not None:
                    path = path_of(child.get("d") or "", False)[0]
                    if path.cubics.shape[0]:  # else the full way says why it is skipped
                        chain = last.inner.chain
                        self._add_shape(
                            path, last.inner.ctm, last.plain, chain + names.get(id(child), "path")
                        )
                        continue
                self.shape(child, last.tag, last.inner, body, last.facts, last)
                continue
            self._run = None
            self.walk(child, body)
            last = self._run if self._run is not None and self._run.el is child else None

    def _transform(self, el: ET.Element, style: dict[str, str], vp: Viewport) -> Matrix | None:
        """The element's own transform (CSS ``transform`` wins over the attribute), with its origin."""
        text = style.get("transform")
        if text is None:
            return None
        m = parse_transform(text) or parse_transform(text, css=True)
        if m is None:  # ignored, as renderers do
            self.notes.append(f"ignored the unreadable transform {shown(text)} of {describe(el)}")
        return m

    def _viewport(
        self, el: ET.Element, ctx: Ctx, outer: Ctx, size: tuple[float, float] | None = None
    ) -> tuple[Ctx, str | None] | None:
        """Enter a nested ``<svg>`` (or a ``<symbol>`` through ``<use>``): its viewport and clip."""
        vp = outer.vp._replace(font_size=ctx.vp.font_size)
        x = length_or(el.get("x"), vp, "x", 0.0)
        y = length_or(el.get("y"), vp, "y", 0.0)
        w = size[0] if size else length_or(el.get("width"), vp, "x", vp.width)
        h = size[1] if size else length_or(el.get("height"), vp, "y", vp.height)
        if w <= 0 or h <= 0:
            return None
        vb_text = el.get("viewBox")
        vb = parse_viewbox(vb_text)
        if vb_text is not None and vb is None:
            self.notes.append(
                f"ignored the viewBox {shown(vb_text)} of {describe(el)}: it needs 4 numbers with width, height > 0"
            )
        m = (1.0, 0.0, 0.0, 1.0, x, y)
        if vb is not None:
            m = multiply(m, viewbox_transform(vb, 0.0, 0.0, w, h, el.get("preserveAspectRatio")))
        new_vp = Viewport(vb[2] if vb else w, vb[3] if vb else h, ctx.vp.font_size, self.root_font)
        clip = None
        clips = vb is not None or local_name(el.tag) == "svg"  # a symbol without viewBox does not clip
        if clips and ctx.style.get("overflow", "hidden").strip().lower() in ("hidden", "scroll"):
            corners = [complex(x, y), complex(x + w, y), complex(x + w, y + h), complex(x, y + h)]
            a, b, c, d, e, f = ctx.ctm
            doc = [complex(a * p.real + c * p.imag + e, b * p.real + d * p.imag + f) for p in corners]
            clip = self.resources.clip_rect(doc)
        return replace(ctx, ctm=multiply(ctx.ctm, m), vp=new_vp), clip

    def use(self, el: ET.Element, ctx: Ctx) -> None:
        """Draw the element a ``<use>`` refers to, where the ``<use>`` is."""
        href = href_of(el)
        target = self.tree.target(href)
        if target is None:
            if href and not href.startswith("#"):
                self.skips["<use> of an external file (not read)"] += 1
            return
        if id(target) in ctx.uses or any(a is target for a in self.tree.ancestors(el)) or target is el:
            self.notes.append(f"skipped a <use> that refers to itself (a reference cycle): {describe(el)}")
            return
        x = length_or(el.get("x"), ctx.vp, "x", 0.0)
        y = length_or(el.get("y"), ctx.vp, "y", 0.0)
        inner = replace(
            ctx,
            ctm=multiply(ctx.ctm, (1.0, 0.0, 0.0, 1.0, x, y)),
            uses=(*ctx.uses, id(target)),
            chain=ctx.chain + self._names.get(id(el), "use") + ">",
        )
        tag = local_name(target.tag)
        if tag in ("symbol", "svg"):
            self._use_viewport(el, target, tag, inner)
        else:
            self.walk(target, inner)

    def _use_viewport(self, use: ET.Element, target: ET.Element, tag: str, ctx: Ctx) -> None:
        """A ``<symbol>`` or ``<svg>`` drawn through ``<use>``: the use's size sets the viewport."""
        style = self.cascade.computed(target, ctx.style, self.root_font)
        if style.get("display", "inline").strip().lower() == "none" and tag == "svg":
            return
        w = length_or(use.get("width") or target.get("width"), ctx.vp, "x", ctx.vp.width)
        h = length_or(use.get("height") or target.get("height"), ctx.vp, "y", ctx.vp.height)
        own = self._transform(target, style, ctx.vp) if tag == "svg" else None
        ctm = multiply(ctx.ctm, own) if own is not None else ctx.ctm
        inner = replace(ctx, ctm=ctm, style=style, depth=ctx.depth + 1)
        got = self._viewport(target, inner, ctx, (w, h))
        if got is None:
            return
        entered, clip = got
        if tag == "symbol":
            rx = length_or(target.get("refX"), entered.vp, "x", 0.0)
            ry = length_or(target.get("refY"), entered.vp, "y", 0.0)
            if rx or ry:
                entered = replace(entered, ctm=multiply(entered.ctm, (1.0, 0.0, 0.0, 1.0, -rx, -ry)))
        start = len(self.records)
        self._children(list(target), entered)
        if len(self.records) > start:
            # The symbol's own opacity is not applied (as renderers draw it); its viewport clips.
            effects = {k: v for k, v in style.items() if k != "opacity"} if tag == "symbol" else style
            group_effects.apply(self, target, effects, inner, start, clip)

    # -- shapes ---------------------------------------------------------------------------------

    def shape(
        self, el: ET.Element, tag: str, ctx: Ctx, outer: Ctx, facts: StyleFacts, run: Run | None = None
    ) -> None:
        """Record a drawable shape with what it draws with (``facts`` of its style), then its markers.

        ``run`` holds what its like siblings share (:mod:`.siblings`): declarations that depend
        on the style and context only are worked out once for them.
        """
        style = ctx.style
        wants_markers = tag in _MARKABLE and facts.markers
        try:
            geom, reason = shape_geometry(el, tag, ctx.vp, self.paths.get, rows=wants_markers or facts.capped)
        except KeepAsIs as why:
            self.keep_as_is(el, outer, str(why))
            return
        if geom is None:
            self.skips[reason or "degenerate (zero size)"] += 1
            return
        if not facts.visible:
            if geom.path.cubics.shape[0]:  # draws nothing, yet counts in its groups' boxes
                self.records.append(ShapeRecord(geom.path, ctx.ctm, {}, "", -1, hidden=True))
            return
        if draws_cap_dots(style, geom.table):
            self.keep_as_is(el, outer, "zero-length subpath with caps")
            return
        empty = geom.path.cubics.shape[0] == 0
        marks = wants_markers and geom.table is not None
        if empty and not marks:
            self.skips[reason or "degenerate (zero size)"] += 1
            return
        decls = run.decls if run is not None else None
        if decls is None:
            decls = self._declarations.get(self.resources, style, ctx, geom.path)
            if decls is None:
                return  # clipped out entirely
            if run is not None and self._declarations.shared(style, ctx):
                run.decls = decls
        stroked = decls.get("stroke", "none") != "none"
        if stroked and self._anisotropy(ctx.ctm) > 1.02:
            self.keep_as_is(el, outer, "stroke under a non-uniform scale")
            return
        order = facts.order
        markers_first = order[0] == "markers"
        if marks and markers_first:
            self._markers(el, geom, ctx, decls)
        if not empty:
            source = ctx.chain + self._names.get(id(el), tag)
            if marks and order[1] == "markers":
                # Markers between fill and stroke: the element is drawn in two parts.
                first, second = order[0], next(w for w in ("fill", "stroke") if w != order[0])
                self._add_shape(geom.path, ctx.ctm, only_part(decls, first), source)
                self._markers(el, geom, ctx, decls)
                self._add_shape(geom.path, ctx.ctm, only_part(decls, second), source)
                return
            self._add_shape(geom.path, ctx.ctm, decls, source)
            if run is not None and tag == "path" and not (marks or facts.capped) and run.decls is decls:
                run.plain = decls  # visible, drawn whole, with shared declarations, kept
        if marks and not markers_first:
            self._markers(el, geom, ctx, decls)

    def _add_shape(self, path: ArrayPath, ctm: Matrix, decls: dict[str, str], source: str) -> None:
        self.segments += path.cubics.shape[0]
        if self.segments > DEFAULT_MAX_SEGMENTS:
            raise LimitError(f"{self.name} draws more than {DEFAULT_MAX_SEGMENTS:,} path segments")
        records = self.records
        if len(records) >= self.max_elements:  # (:meth:`_next_order`, inline: called for every shape)
            raise LimitError(f"{self.name} draws more than {self.max_elements:,} elements")
        self.order += 1
        records.append(ShapeRecord(path, ctm, decls, source, self.order - 1))

    def _anisotropy(self, ctm: Matrix) -> float:
        """:func:`~.paint.anisotropy` of ``ctm``, remembered for the last matrix (siblings share theirs)."""
        last = self._last_anisotropy
        if last is None or last[0] is not ctm:
            self._last_anisotropy = last = (ctm, anisotropy(ctm))
        return last[1]

    # -- markers --------------------------------------------------------------------------------

    def _markers(self, el: ET.Element, geom: Geometry, ctx: Ctx, decls: dict[str, str]) -> None:
        """Draw the markers of a shape as ordinary elements (markers are repetition)."""
        if geom.table is not None:
            markers.draw(self, el, geom.table, ctx, decls)
