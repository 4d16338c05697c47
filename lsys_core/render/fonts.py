"""Typefaces for kept text: a CSS ``font-family`` list resolved by fontconfig, as librsvg's pango does.

skia's own font manager on Linux is built on fontconfig too, but it refuses fontconfig's
substitutes for families that are not installed: "Times New Roman" or "Helvetica" give it no
face, where fontconfig (and so pango and librsvg) binds them to the installed serif or sans
face its configuration names (metric aliases, generic families).  So the family list, weight
and slant go to fontconfig itself through its C library (``libfontconfig.so.1``, which skia
needs on Linux anyway), and the file it matches is opened by skia.  Where that library is
missing (other systems), skia's font manager is asked for each family in turn, then its
default face.

Found faces are cached per (families, weight, italic).  skia is imported inside the functions.
"""

from __future__ import annotations

import ctypes
import ctypes.util
from functools import lru_cache
from typing import Any

__all__ = ["families", "typeface"]

_FC_MATCH_PATTERN = 0
_FC_RESULT_MATCH = 0
_FC_SLANT_ROMAN, _FC_SLANT_ITALIC = 0, 100


def families(text: str) -> list[str]:
    """Split a ``font-family`` value into family names (quotes removed)."""
    out = []
    for part in text.split(","):
        name = part.strip().strip("'\"").strip()
        if name:
            out.append(name)
    return out


@lru_cache(maxsize=1)
def _fontconfig() -> Any:
    """The fontconfig C library with the functions used here declared, or None."""
    name = ctypes.util.find_library("fontconfig")
    if name is None:
        return None
    try:
        lib = ctypes.CDLL(name)
        p, s, i = ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int
        for fn, args, res in (
            ("FcPatternCreate", [], p),
            ("FcPatternDestroy", [p], None),
            ("FcPatternAddString", [p, s, s], i),
            ("FcPatternAddInteger", [p, s, i], i),
            ("FcConfigSubstitute", [p, p, i], i),
            ("FcDefaultSubstitute", [p], None),
            ("FcFontMatch", [p, p, ctypes.POINTER(i)], p),
            ("FcPatternGetString", [p, s, i, ctypes.POINTER(s)], i),
            ("FcPatternGetInteger", [p, s, i, ctypes.POINTER(i)], i),
            ("FcPatternGetBool", [p, s, i, ctypes.POINTER(i)], i),
            ("FcWeightFromOpenType", [i], i),
        ):
            f = getattr(lib, fn)
            f.argtypes, f.restype = args, res
    except (OSError, AttributeError):
        return None
    return lib


def _fontconfig_match(names: list[str], weight: int, italic: bool) -> tuple[str, int, bool] | None:
    """The font file, face index and synthetic-bold flag fontconfig matches, or None."""
    fc = _fontconfig()
    if fc is None:
        return None
    pattern = fc.FcPatternCreate()
    if not pattern:
        return None
    matched = None
    try:
        for name in names:
            fc.FcPatternAddString(pattern, b"family", name.encode("utf-8", "replace"))
        fc.FcPatternAddInteger(pattern, b"weight", fc.FcWeightFromOpenType(weight))
        fc.FcPatternAddInteger(pattern, b"slant", _FC_SLANT_ITALIC if italic else _FC_SLANT_ROMAN)
        fc.FcConfigSubstitute(None, pattern, _FC_MATCH_PATTERN)
        fc.FcDefaultSubstitute(pattern)
        result = ctypes.c_int(0)
        matched = fc.FcFontMatch(None, pattern, ctypes.byref(result))
        if not matched:
            return None
        file, index, embolden = ctypes.c_char_p(), ctypes.c_int(0), ctypes.c_int(0)
        if (
            fc.FcPatternGetString(matched, b"file", 0, ctypes.byref(file)) != _FC_RESULT_MATCH
            or not file.value
        ):
            return None
        fc.FcPatternGetInteger(matched, b"index", 0, ctypes.byref(index))
        fc.FcPatternGetBool(matched, b"embolden", 0, ctypes.byref(embolden))
        return file.value.decode("utf-8", "surrogateescape"), index.value & 0xFFFF, bool(embolden.value)
    finally:
        if matched:
            fc.FcPatternDestroy(matched)
        fc.FcPatternDestroy(pattern)


@lru_cache(maxsize=256)
def typeface(family: str, weight: int, italic: bool) -> tuple[Any, bool]:
    """The skia typeface for a ``font-family`` list, a CSS weight and slant; and whether to embolden it."""
    import skia

    names = families(family)
    found = _fontconfig_match(names, weight, italic)
    if found is not None:
        face = skia.Typeface.MakeFromFile(found[0], found[1])
        if face is not None:
            return face, found[2]
    manager = skia.FontMgr.RefDefault()
    slant = skia.FontStyle.kItalic_Slant if italic else skia.FontStyle.kUpright_Slant
    style = skia.FontStyle(weight, skia.FontStyle.kNormal_Width, slant)
    for name in names:
        face = manager.matchFamilyStyle(name, style)
        if face is not None:
            return face, False
    return manager.legacyMakeTypeface("", style) or skia.Typeface.MakeDefault(), False
