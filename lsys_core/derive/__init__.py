"""Stage 4, derivation: rewrite a grammar and interpret it with a turtle into a :class:`Drawing`."""

from __future__ import annotations

from lsys_core.derive.derivation import DEFAULT_LIMIT, Randomize, derive
from lsys_core.derive.model import Drawing

__all__ = ["DEFAULT_LIMIT", "Drawing", "Randomize", "derive"]
