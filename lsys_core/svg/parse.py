"""Read an SVG file into a :class:`~lsys_core.svg.model.Scene`, safely.

The bytes are checked before any SVG library sees them: size, binary junk, XML
attacks (entities, internal DTD subsets), nesting depth, ``<use>`` cycles and
``<use>`` fan-out.  The checked tree is re-serialised (without DTD, with the
content of ``<symbol>``, ``<mask>`` and ``<marker>`` moved out of the drawing
flow) and handed to svgelements, which resolves CSS, inheritance, ``<use>`` and
transforms.  Each drawable shape becomes an :class:`~lsys_core.svg.model.Element`
with cubic Bézier arrays in viewBox user units and a resolved style string.
"""

from __future__ import annotations

import gc
import os
from pathlib import Path

from lsys_core.errors import LimitError, SvgError
from lsys_core.svg.extract import extract
from lsys_core.svg.model import Scene
from lsys_core.svg.prepare import prepare
from lsys_core.svg.xmlsafe import (
    DEFAULT_MAX_BYTES,
    DEFAULT_MAX_DEPTH,
    DEFAULT_MAX_ELEMENTS,
    maybe_gunzip,
)

__all__ = ["DEFAULT_MAX_BYTES", "DEFAULT_MAX_DEPTH", "DEFAULT_MAX_ELEMENTS", "load_svg", "parse_svg"]


def load_svg(
    path: str | os.PathLike,
    *,
    max_bytes: int = DEFAULT_MAX_BYTES,
    max_elements: int = DEFAULT_MAX_ELEMENTS,
    max_depth: int = DEFAULT_MAX_DEPTH,
) -> Scene:
    """Read an SVG (or gzip-compressed SVGZ) file into a scene.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    max_bytes : int
        Largest accepted file size (also for the decompressed content of SVGZ).
    max_elements : int
        Largest accepted number of elements once ``<use>`` references are expanded.
    max_depth : int
        Deepest accepted element nesting (``<use>`` references count as nesting).

    Returns
    -------
    Scene

    Raises
    ------
    SvgError
        The file cannot be read, is not a safe SVG, or has nothing drawable.
    LimitError
        The file exceeds one of the limits.
    """
    p = Path(path)
    try:
        size = p.stat().st_size
        if size > max_bytes:
            raise LimitError(f"{p} is too large ({size:,} bytes; the limit is {max_bytes:,})")
        with open(p, "rb") as fh:
            data = fh.read(max_bytes + 1)
    except OSError as exc:
        raise SvgError(f"cannot read {p}: {exc.strerror or exc}") from exc
    return parse_svg(data, max_bytes=max_bytes, max_elements=max_elements, max_depth=max_depth, name=str(p))


def parse_svg(
    source: str | bytes,
    *,
    max_bytes: int = DEFAULT_MAX_BYTES,
    max_elements: int = DEFAULT_MAX_ELEMENTS,
    max_depth: int = DEFAULT_MAX_DEPTH,
    name: str = "<string>",
) -> Scene:
    """Parse SVG text or bytes into a scene (see :func:`load_svg`).

    ``name`` is used in messages.
    """
    data = source.encode("utf-8") if isinstance(source, str) else bytes(source)
    if len(data) > max_bytes:
        raise LimitError(f"{name} is too large ({len(data):,} bytes; the limit is {max_bytes:,})")
    data = maybe_gunzip(data, max_bytes, name)
    source_bytes = len(data)
    prepared = prepare(source if isinstance(source, str) else data, max_elements, max_depth, name)
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        elements, skips = extract(prepared, name)
    finally:
        if was_enabled:
            gc.enable()
    if not elements:
        detail = f" ({'; '.join(skips.messages())})" if skips.counts else ""
        raise SvgError(f"no drawable elements in {name}{detail}")
    return Scene(
        elements=tuple(elements),
        viewbox=prepared.viewbox,
        size=prepared.size,
        warnings=(*prepared.notes, *skips.messages()),
        source_bytes=source_bytes,
    )
