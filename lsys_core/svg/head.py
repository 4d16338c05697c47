"""The head of an SVG document: root attributes, ``<title>`` and ``<desc>``, kept for the export.

The scene holds what is drawn; this holds what describes the document, so that a structured
export of an inferred drawing keeps the input's identity: its ``id``, ``lang``,
``preserveAspectRatio``, ``data-*``/``aria-*`` and editor attributes (``inkscape:…`` with
their namespace declarations), and its title and description.  Presentation attributes of
the root (``style``, ``fill``, ``opacity``, ``transform``, ``class`` …) are not kept: the
importer has already applied them to every element.  ``width``, ``height`` and ``viewBox``
travel with the scene itself.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

__all__ = ["Head", "read_head"]

_SVG_NS = "http://www.w3.org/2000/svg"
_XML_NS = "http://www.w3.org/XML/1998/namespace"
#: Root attributes without a namespace that describe the document (kept as they are).
_KEEP = frozenset({"id", "version", "baseProfile", "preserveAspectRatio", "lang", "role", "zoomAndPan"})
_KEEP_PREFIXES = ("data-", "aria-")
#: Namespaces whose root attributes are presentation or linking, not description.
_DROP_NS = frozenset({_SVG_NS, "http://www.w3.org/1999/xlink", "http://www.w3.org/2000/xmlns/"})
#: Longest title or description kept, in characters.
MAX_TEXT = 10_000
_NAME = re.compile(r"^[A-Za-z_][\w.-]*$")


@dataclass(frozen=True)
class Head:
    """Root attributes (``(qualified name, value)``, namespace declarations first), title and description."""

    attributes: tuple[tuple[str, str], ...] = ()
    title: str = ""
    desc: str = ""


def read_head(data: bytes) -> Head:
    """Return the head of an SVG document that :func:`~lsys_core.svg.parse_svg` has accepted.

    Only the root's start tag and its first children are read (the parse stops at the first
    child that is not ``<title>``, ``<desc>`` or ``<metadata>``).  Returns an empty head when
    the bytes cannot be read (the caller has its scene anyway).
    """
    import defusedxml.ElementTree as DET

    from lsys_core.svg.xmlsafe import DEFAULT_MAX_BYTES, ChunkReader, maybe_gunzip

    prefixes: dict[str, str] = {}
    attrs: list[tuple[str, str]] = []
    texts = {"title": "", "desc": ""}
    depth = 0
    try:
        data = maybe_gunzip(data, DEFAULT_MAX_BYTES, "")
        events = DET.iterparse(ChunkReader(data), events=("start-ns", "start", "end"), forbid_dtd=False)
        for event, item in events:
            if event == "start-ns":
                prefix, uri = item
                prefixes.setdefault(uri, prefix)
                continue
            tag = item.tag.rpartition("}")[2] if isinstance(item.tag, str) else ""
            if event == "start":
                depth += 1
                if depth == 1:
                    attrs = _root_attributes(item.attrib, prefixes)
                elif depth == 2 and tag not in ("title", "desc", "metadata"):
                    break
            else:
                if depth == 2 and tag in texts and not texts[tag]:
                    texts[tag] = " ".join("".join(item.itertext()).split())[:MAX_TEXT]
                depth -= 1
    except Exception:  # any parse problem: no head (the drawing itself was read already)
        return Head()
    return Head(tuple(attrs), texts["title"], texts["desc"])


def _root_attributes(attrib: dict[str, str], prefixes: dict[str, str]) -> list[tuple[str, str]]:
    kept: list[tuple[str, str]] = []
    used: dict[str, str] = {}
    for key, value in attrib.items():
        if key.startswith("{"):
            uri, _, local = key[1:].partition("}")
            if uri == _XML_NS:
                if local in ("lang", "space"):
                    kept.append((f"xml:{local}", value))
                continue
            prefix = prefixes.get(uri)
            if uri in _DROP_NS or not prefix or not _NAME.match(prefix):
                continue
            used[prefix] = uri
            kept.append((f"{prefix}:{local}", value))
        elif key in _KEEP or key.startswith(_KEEP_PREFIXES):
            kept.append((key, value))
    return [(f"xmlns:{p}", uri) for p, uri in used.items()] + kept
