"""Stage 2, similarity and inverse instancing (§4.1–4.2): elements → terminals and poses.

Elements that are the same shape up to translation, rotation, uniform scale and mirror share a
terminal; each element gets a pose ``z -> a*z + b`` of its terminal (:class:`Instancing`).
"""

from __future__ import annotations

from lsys_core.instancing.fidelity import split_unfaithful
from lsys_core.instancing.model import Instancing
from lsys_core.instancing.orientation import unwrap_symmetric
from lsys_core.instancing.similarity import detect_similarity, terminal_similarity

__all__ = ["Instancing", "detect_similarity", "split_unfaithful", "terminal_similarity", "unwrap_symmetric"]
