"""Stage 3, the hierarchy (§4.3–5.7): transformation spaces, clustering, rules, level by level.

Pivots make turning rows linear, pairs of instances become points (α, d, s, β) of
transformation spaces, mean shift clusters them, the most important clusters become
sequence and branching rules, and the elements they explain collapse into one node per
application, until one axiom is left.  Post-processing simplifies the grammar.
"""

from __future__ import annotations

from lsys_core.hierarchy.pivots import estimate_pivots, recenter
from lsys_core.hierarchy.postprocess import simplify
from lsys_core.hierarchy.rules import Hierarchy, Tolerance, Weights, build_hierarchy

__all__ = ["Hierarchy", "Tolerance", "Weights", "build_hierarchy", "estimate_pivots", "recenter", "simplify"]
