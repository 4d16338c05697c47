"""Rounding a rule's numbers moves exact copies no farther than rounding may (hierarchy.select).

Four copies of a pair of long strokes (reaching 60 from their centres, like an axis line and
its row of ticks), the second 100 along and 1 across from the first, all upright.
The step is a fraction of a degree off its axis: the plain step along the axis would move every
second shape by 1 (within the tolerance of 3, but three times what rounding may spend).
"""

from __future__ import annotations

import numpy as np

from lsys_core.hierarchy.candidates import PairCandidate
from lsys_core.hierarchy.gain import Ledger, placement_error
from lsys_core.hierarchy.mdl import Precision
from lsys_core.hierarchy.nodes import Nodes
from lsys_core.hierarchy.select import worthwhile
from lsys_core.hierarchy.snap import SHARE
from lsys_core.hierarchy.symbols import SymbolTable

EPS = 3.0
FIRSTS = np.array([0, 300 + 40j, 80 + 400j, 500 + 350j])
OFFSET = 100 + 1.0j


def _pairs() -> tuple[Nodes, SymbolTable, PairCandidate]:
    a = np.ones(8, complex)
    b = np.concatenate([FIRSTS, FIRSTS + OFFSET])
    nodes = Nodes.of_elements(np.repeat([0, 1], 4), a, b, b, np.full(8, 60.0), EPS)
    table = SymbolTable(["A", "B"], np.array([60.0, 60.0]), np.eye(2))
    groups = tuple(np.array([i, i + 4]) for i in range(4))
    c = PairCandidate(space=(0, 1), groups=groups, h=1.0, phi=0.3, l=1.0, A=1 + 0j, B=OFFSET)
    return nodes, table, c


def test_a_step_just_off_its_axis_keeps_its_small_offset_between_exact_copies() -> None:
    nodes, table, c = _pairs()
    prec = Precision.of_box(complex(-10, -10), complex(620, 420), EPS)
    got = worthwhile(c, Ledger(prec, nodes, table), nodes, table.sizes, np.zeros(2), SHARE, limit=EPS)
    assert got is not None
    assert abs(got.B.imag - 1.0) < SHARE * EPS  # not the plain step (100, 0): 1 off for every pair
    _, err, _, _ = placement_error(got, nodes, table.sizes, np.zeros(2))
    assert err.max() <= SHARE * EPS
