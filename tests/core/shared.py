"""Access to ../shared (corpus, tools) next to the checkout; tests skip when it is absent."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared"
CORPUS = SHARED / "corpus"
REALWORLD = SHARED / "realworld"


def need(path: Path) -> Path:
    """Return ``path`` or skip the test when it does not exist."""
    if not path.exists():
        pytest.skip(f"{path} not available")
    return path


def compare_svg():
    """Return the shared tool's ``compare(a, b)`` function."""
    spec = importlib.util.spec_from_file_location("compare_svg", need(SHARED / "tools" / "compare_svg.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.compare
