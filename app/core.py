"""The editor's door to ``lsys_core``: every computation the widgets ask for goes through here.

The functions forward to the library (imported on first use, so the window appears before
scipy and svgelements are loaded) and convert plain values (settings dicts, file reads) at
the boundary.  The only arithmetic here is display bookkeeping: a bounding disc per terminal
(from ``lsys_core.render.svg.terminal_points``) to pick the element under a click.  Nothing
imports Qt (the inference worker process uses this module too).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from typing import Any

__all__ = [
    "axiom_count",
    "default_settings",
    "describe",
    "describe_iter",
    "drawing_bounds",
    "export_png",
    "export_svg",
    "find_handles",
    "format_grammar",
    "freeze_heap",
    "handle_values",
    "infer",
    "instance_centers",
    "instance_radius",
    "list_params",
    "load_svg",
    "make_renderer",
    "parse_grammar",
    "read_text",
    "replace_terminal",
    "replace_with_terminal",
    "restyle_terminal",
    "rule_closures",
    "rules_under",
    "set_param",
    "set_params",
    "settings_from_dict",
    "shape_from_svg",
    "snap",
    "snap_params",
    "symmetrize",
    "terminal_image",
    "write_atomic",
]


def load_svg(path: str) -> Any:
    """Load an SVG file into a Scene (``lsys_core.svg.parse.load_svg``)."""
    from lsys_core.svg.parse import load_svg as _load

    return _load(path)


def infer(scene: Any, settings: Any, *, cancel=None, progress=None) -> Any:
    """Infer a grammar for ``scene`` (``lsys_core.pipeline.infer``)."""
    from lsys_core.pipeline import infer as _infer

    return _infer(scene, settings, cancel=cancel, progress=progress)


def analyse(scene: Any, settings: Any, *, previous=None, cancel=None, progress=None) -> Any:
    """Analyse ``scene`` once for any weights (``lsys_core.pipeline.analyse``)."""
    from lsys_core.pipeline import analyse as _analyse

    return _analyse(scene, settings, previous=previous, cancel=cancel, progress=progress)


def rules_from_analysis(analysis: Any, *, cancel=None, progress=None) -> Any:
    """Rules for the analysis' settings, as ``infer`` would end (``lsys_core.pipeline.rules_from_analysis``
    then ``tighter_if_better``)."""
    from lsys_core.pipeline import rules_from_analysis as _rules
    from lsys_core.pipeline import tighter_if_better

    result = _rules(analysis, cancel=cancel, progress=progress)
    return tighter_if_better(analysis, result, cancel=cancel, progress=progress)


def symmetrize(scene: Any, settings: Any, *, cancel=None, progress=None) -> Any:
    """Infer with relaxed clustering tolerance (``lsys_core.pipeline.symmetrize``)."""
    from lsys_core.pipeline import symmetrize as _sym

    return _sym(scene, settings, cancel=cancel, progress=progress)


def _settings_type() -> type:
    from lsys_core.pipeline import InferenceSettings

    return InferenceSettings


def default_settings() -> Any:
    """Return the default ``InferenceSettings`` (None while the pipeline is unavailable)."""
    try:
        return _settings_type()()
    except ImportError:
        return None


def settings_from_dict(values: dict[str, Any]) -> Any:
    """Build ``InferenceSettings`` from a dict, ignoring unknown keys (recovery files)."""
    cls = _settings_type()
    names = {f.name for f in dataclasses.fields(cls)}
    return cls(**{k: v for k, v in values.items() if k in names})


def parse_grammar(text: str) -> Any:
    """Parse ``.lsys`` text, terminal path data included (raises ``GrammarSyntaxError`` with line and column)."""
    from lsys_core.grammar import parse_grammar as _parse

    return _parse(text, check_paths=True)


def format_grammar(grammar: Any) -> str:
    """Format a grammar as ``.lsys`` text."""
    from lsys_core.grammar import format_grammar as _format

    return _format(grammar)


def list_params(grammar: Any) -> list:
    """List the numeric parameters of a grammar (``Param(key, label, value, kind)``)."""
    from lsys_core.grammar import list_params as _list

    return _list(grammar)


def set_param(grammar: Any, key: str, value: float) -> Any:
    """Return ``grammar`` with one parameter changed."""
    from lsys_core.grammar import set_param as _set

    return _set(grammar, key, value)


def set_params(grammar: Any, values: dict[str, float]) -> Any:
    """Return ``grammar`` with several parameters changed."""
    from lsys_core.grammar import set_params as _set

    return _set(grammar, values)


def describe(grammar: Any) -> tuple:
    """Return the rules as designer's cards (``lsys_core.grammar.semantics.describe``)."""
    from lsys_core.grammar.semantics import describe as _describe

    return _describe(grammar)


def describe_iter(grammar: Any) -> Iterator[Any]:
    """Yield the cards of :func:`describe` one by one."""
    from lsys_core.grammar.semantics import describe_iter as _describe_iter

    return _describe_iter(grammar)


def rules_under(grammar: Any, name: str) -> set[str]:
    """Return ``name`` and the rules it uses (``lsys_core.grammar.semantics.rules_under``)."""
    from lsys_core.grammar.semantics import rules_under as _under

    return _under(grammar, name)


def freeze_heap(*, collect: bool = False) -> None:
    """Move every object now alive into the garbage collector's permanent generation.

    The editor's modules, classes and widgets live as long as the process, and a full
    collection traverses every tracked object: with them in the collected generations, each
    full collection on the UI thread took 16–42 ms (50,000–87,000 objects) while rules with 833
    parameters were applied.  Objects freed later by reference counting are still freed; only
    reference cycles among frozen objects would stay, so this is called when the window is
    built (after a collection) and once after the first drawing (modules imported on first use).
    """
    import gc

    if collect:
        gc.collect()
    gc.freeze()


def rule_closures(grammar: Any) -> dict[str, frozenset[str]]:
    """Return :func:`rules_under` of ``axiom`` and every rule, read in one pass."""
    from lsys_core.grammar.semantics import rule_closures as _closures

    return _closures(grammar)


def find_handles(grammar: Any, drawing: Any, index: int, knob: float) -> Any:
    """Return the handles of the repetition of instance ``index`` (``lsys_core.derive.handles``)."""
    from lsys_core.derive.handles import find_handles as _find

    return _find(grammar, drawing, index, knob)


def handle_values(handles: Any, which: str, point: complex, pixel: float = 0.0) -> dict[str, float]:
    """Return control values for handle ``which`` dragged to ``point`` (``drag_values``)."""
    from lsys_core.derive.handles import drag_values

    return drag_values(handles, which, point, pixel)


def snap(value: float, tolerance: float, kind: str, *, ring: int | None = None) -> float:
    """Return the simplest value within ``tolerance`` (``lsys_core.grammar.snap.snap``)."""
    from lsys_core.grammar.snap import snap as _snap

    return _snap(value, tolerance, kind, ring=ring)


def snap_params(grammar: Any) -> Any:
    """Return ``grammar`` with clean numbers (``lsys_core.grammar.snap.snap_params``)."""
    from lsys_core.grammar.snap import snap_params as _snap_params

    return _snap_params(grammar)


_THUMBNAILS: dict[tuple[str, str, int], Any] = {}


def terminal_image(terminal: Any, size: int) -> Any:
    """Return a ``size`` × ``size`` straight-RGBA array of one terminal's shape, fitted (cached)."""
    key = (terminal.path, terminal.style, size)
    image = _THUMBNAILS.get(key)
    if image is None:
        import dataclasses as _dc

        import numpy as np

        from lsys_core.derive.model import Drawing
        from lsys_core.render.raster import default_view, render

        one = Drawing(
            (_dc.replace(terminal, name="T"),),
            np.zeros(1, np.int32),
            np.ones(1, complex),
            np.zeros(1, complex),
            np.zeros(1, np.int32),
        )
        x, y, w, h = default_view(one)
        side = max(w, h)
        view = (x - (side - w) / 2, y - (side - h) / 2, side, side)
        image = render(one, size, size, view=view)
        if len(_THUMBNAILS) > 512:
            _THUMBNAILS.clear()
        _THUMBNAILS[key] = image
    return image


def restyle_terminal(grammar: Any, name: str, changes: dict[str, str | None]) -> Any:
    """Return ``grammar`` with CSS declarations of terminal ``name`` set (None removes one)."""
    import dataclasses as _dc

    from lsys_core.errors import GrammarError
    from lsys_core.render.paths import parse_style

    term = grammar.terminal(name)
    if term is None:
        raise GrammarError(f"no terminal named {name}")
    decls = parse_style(term.style)
    for key, value in changes.items():
        if value is None:
            decls.pop(key, None)
        else:
            decls[key] = value
    style = ";".join(f"{k}:{v}" for k, v in decls.items())
    terminals = tuple(_dc.replace(t, style=style) if t.name == name else t for t in grammar.terminals)
    return _dc.replace(grammar, terminals=terminals)


def replace_terminal(grammar: Any, name: str, path_d: str, style: str) -> Any:
    """Return ``grammar`` with terminal ``name`` drawing another shape."""
    from lsys_core.grammar.edit import replace_terminal as _replace

    return _replace(grammar, name, path_d, style)


def replace_with_terminal(grammar: Any, nonterminal: str, terminal: str) -> Any:
    """Return ``grammar`` with every use of a non-terminal replaced by a terminal."""
    from lsys_core.grammar.edit import replace_with_terminal as _replace

    return _replace(grammar, nonterminal, terminal)


def shape_from_svg(path: str) -> tuple[str, str]:
    """Return the path data (all shapes of the file joined) and style (the first shape's) of an SVG.

    Used to replace a terminal by a shape drawn elsewhere; ``replace_terminal`` places it.

    Raises
    ------
    LsysError
        If the file cannot be read or holds no shape.
    """
    import numpy as np

    from lsys_core.errors import SvgError
    from lsys_core.geometry.paths import d_from_cubics

    scene = load_svg(path)
    if not scene.elements:
        raise SvgError(f"{path} holds no shape")
    cubics = np.concatenate([e.cubics for e in scene.elements])
    offsets = np.cumsum([0] + [len(e.closed) for e in scene.elements[:-1]])
    subpaths = np.concatenate([e.subpaths + o for e, o in zip(scene.elements, offsets, strict=True)])
    closed = tuple(c for e in scene.elements for c in e.closed)
    return d_from_cubics(cubics, subpaths, closed), scene.elements[0].style


def export_svg(drawing: Any, path: str) -> None:
    """Write the drawing as an SVG file (atomically)."""
    from lsys_core.render.svg import export_svg as _export

    _export(drawing, path)


def export_png(drawing: Any, path: str, **options: Any) -> None:
    """Render the drawing into a PNG file."""
    from lsys_core.render.raster import render_png

    render_png(drawing, path, **options)


def make_renderer(width: int, height: int) -> Any:
    """Return a ``lsys_core.render.raster.Renderer`` drawing into a ``width`` × ``height`` surface."""
    from lsys_core.render.raster import Renderer

    return Renderer(width, height)


def write_atomic(path: str, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (``lsys_core.io.write_atomic``)."""
    from lsys_core.io import write_atomic as _write

    _write(path, data)


def read_text(path: str) -> str:
    """Read a UTF-8 text file as ``lsys`` does (``lsys_core.io.read_text``), with Unix line ends.

    The size is bounded and the text checked as it is read; failures are one-line ``LsysError`` s
    (too large, binary data, bad UTF-8 with its line and column).
    """
    from lsys_core.io import read_text as _read

    return _read(path).replace("\r\n", "\n").replace("\r", "\n")


# -- display helpers (picking, fitting) ---------------------------------------------------------------
_TERMINAL_DISCS: dict[tuple[str, ...], tuple[Any, Any]] = {}


def _terminal_discs(drawing: Any) -> tuple[Any, Any]:
    """Return the centre (complex) and radius of a disc around every terminal's control points."""
    import numpy as np

    from lsys_core.render.svg import terminal_points

    key = tuple(t.path for t in drawing.terminals)
    cached = _TERMINAL_DISCS.get(key)
    if cached is None:
        points = terminal_points(drawing)
        centers = np.zeros(len(points), complex)
        radii = np.zeros(len(points))
        for i, p in enumerate(points):
            if p.size:
                centers[i] = complex((p.real.min() + p.real.max()) / 2, (p.imag.min() + p.imag.max()) / 2)
                radii[i] = float(np.abs(p - centers[i]).max())
        if len(_TERMINAL_DISCS) > 64:
            _TERMINAL_DISCS.clear()
        cached = _TERMINAL_DISCS[key] = (centers, radii)
    return cached


def instance_centers(drawing: Any) -> Any:
    """Return the centre of every instance's bounding disc in document coordinates (for picking)."""
    centers, _ = _terminal_discs(drawing)
    return drawing.a * centers[drawing.symbol] + drawing.b


def instance_radius(drawing: Any, index: int) -> float:
    """Return the radius of instance ``index``'s bounding disc in document units."""
    _, radii = _terminal_discs(drawing)
    return float(abs(drawing.a[index]) * radii[drawing.symbol[index]])


def drawing_bounds(drawing: Any) -> tuple[float, float, float, float] | None:
    """Return ``(x0, y0, x1, y1)`` of the drawing's instances, strokes included (None if empty)."""
    from lsys_core.render.svg import drawing_bounds as _bounds

    return _bounds(drawing)


def axiom_count(grammar: Any) -> int | None:
    """Return the axiom's counter m (``set_param(g, "m", value)`` changes it), or None if it has none."""
    for p in list_params(grammar):
        if p.kind == "count" and p.key.startswith("axiom."):
            return int(p.value)
    return None
