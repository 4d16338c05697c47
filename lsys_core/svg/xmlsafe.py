"""Safety checks on the raw bytes and the XML tree of an SVG file.

Size limits, gzip bombs, binary junk and XML attacks (entities, external references, internal DTD
subsets) are refused here, before any SVG interpretation sees the content.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
import zlib

from lsys_core.errors import LimitError, SvgError

__all__ = [
    "DEFAULT_MAX_BYTES",
    "DEFAULT_MAX_DEPTH",
    "DEFAULT_MAX_ELEMENTS",
    "SVG_NS",
    "XLINK_HREF",
    "check_bytes",
    "local_name",
    "maybe_gunzip",
    "parse_xml",
    "snippet",
]

DEFAULT_MAX_BYTES = 50_000_000
DEFAULT_MAX_ELEMENTS = 200_000
DEFAULT_MAX_DEPTH = 500

SVG_NS = "{http://www.w3.org/2000/svg}"
XLINK_HREF = "{http://www.w3.org/1999/xlink}href"

INTERNAL_SUBSET = re.compile(rb"<!DOCTYPE[^\[>]*\[")


def maybe_gunzip(data: bytes, max_bytes: int, name: str) -> bytes:
    """Decompress SVGZ content, refusing to inflate beyond ``max_bytes``."""
    if not data.startswith(b"\x1f\x8b"):
        return data
    d = zlib.decompressobj(16 + zlib.MAX_WBITS)
    try:
        out = d.decompress(data, max_bytes + 1)
    except zlib.error as exc:
        raise SvgError(f"not an SVG: {name}: corrupt gzip data ({exc})") from exc
    if len(out) > max_bytes or d.unconsumed_tail:
        raise LimitError(f"{name} decompresses to more than {max_bytes:,} bytes")
    if not d.eof:
        raise SvgError(f"not an SVG: {name}: truncated gzip data")
    return out


def check_bytes(data: bytes, name: str) -> None:
    """Reject empty input and binary junk before XML parsing."""
    if not data.strip():
        raise SvgError(f"not an SVG: {name} is empty")
    head = data[:4096]
    utf16 = head.startswith((b"\xff\xfe", b"\xfe\xff"))
    if not utf16 and b"\x00" in head:
        raise SvgError(f"not an SVG: {name} holds binary data")


def parse_xml(source: str | bytes, name: str):
    """Parse with defusedxml: no entities, no external references."""
    import defusedxml
    import defusedxml.ElementTree as DET

    try:
        return DET.fromstring(source, forbid_dtd=False, forbid_entities=True, forbid_external=True)
    except defusedxml.EntitiesForbidden as exc:
        raise SvgError(f"entities are not allowed in SVG input (possible XML attack): {name}") from exc
    except defusedxml.ExternalReferenceForbidden as exc:
        raise SvgError(f"external references are not allowed in SVG input: {name}") from exc
    except defusedxml.DefusedXmlException as exc:
        raise SvgError(f"unsafe XML in {name}: {type(exc).__name__}") from exc
    except ET.ParseError as exc:
        raise SvgError(f"not an SVG: {name}: {exc}") from exc
    except (ValueError, LookupError) as exc:  # unknown or inconsistent encoding declaration
        raise SvgError(f"not an SVG: {name}: {exc}") from exc


def local_name(tag) -> str | None:
    """Return the SVG local name of a tag, or None for comments and foreign namespaces."""
    if not isinstance(tag, str):
        return None
    if tag.startswith(SVG_NS):
        return tag[len(SVG_NS) :]
    if tag.startswith("{"):
        return None
    return tag


def snippet(text: str, n: int = 40) -> str:
    """Return ``text`` quoted for a message, shortened to about ``n`` characters."""
    text = " ".join(text.split())
    return repr(text if len(text) <= n else text[: n - 3] + "...")
