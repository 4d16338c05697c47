"""The symbols of a hierarchy under construction: terminals and the non-terminals of new rules.

Every live node is an instance of a symbol.  A terminal is an input shape; a non-terminal is
a rule with (for sequences and branchings) the counter it is called with, so ``P1(3)`` and
``P1(4)`` are two symbols of one *family* ``P1``.  The table gives rules fresh names, writes
the modules that draw a symbol, and knows how alike two symbols are (φ of §5.4).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lsys_core.grammar.model import Count, Linear, Module, Pop, Push, Symbol, Turtle

__all__ = ["SymbolInfo", "SymbolTable"]


@dataclass(frozen=True)
class SymbolInfo:
    """One symbol: its name, counter (None: not parametric), whether terminal, and its family."""

    name: str
    m: int | None
    terminal: bool
    family: str


class SymbolTable:
    """Symbols, their sizes (radius in their own frame) and the shape similarity of terminals.

    Parameters
    ----------
    terminal_names : list of str
        Names of the terminals (symbols ``0 … k-1``).
    terminal_sizes : ndarray
        Radius of every terminal's shape in its local frame.
    similarity : ndarray, shape (k, k)
        Shape similarity φ of every pair of terminals, in [0, 1].
    """

    def __init__(self, terminal_names: list[str], terminal_sizes: np.ndarray, similarity: np.ndarray):
        self.infos: list[SymbolInfo] = [SymbolInfo(nm, None, True, nm) for nm in terminal_names]
        self._sizes: list[float] = [float(s) for s in terminal_sizes]
        self._index: dict[tuple, int] = {("t", nm): i for i, nm in enumerate(terminal_names)}
        self._names: set[str] = set(terminal_names)
        self._counters = {"P": 0, "R": 0, "X": 0, "Z": 0}
        self.similarity = similarity
        self.n_terminals = len(terminal_names)
        #: Per terminal, the terminal it is a stretched copy of (itself if none), and the stretch.
        self.stretch_base = np.arange(self.n_terminals)
        self.stretch = np.zeros(self.n_terminals)

    def set_stretch(self, base: np.ndarray, amount: np.ndarray) -> None:
        """Record which terminals are stretched copies of which (``base`` -1: none), and by how much."""
        base = np.asarray(base, np.int64)
        self.stretch_base = np.where(base >= 0, base, np.arange(self.n_terminals))
        self.stretch = np.where(base >= 0, np.asarray(amount, float), 0.0)

    def stretch_family(self, sids: np.ndarray) -> np.ndarray:
        """The symbol every symbol of ``sids`` is drawn from: a stretched copy's base, else itself."""
        sids = np.asarray(sids, np.int64)
        inside = sids < self.n_terminals
        return np.where(inside, self.stretch_base[np.where(inside, sids, 0)], sids)

    def stretch_of(self, sids: np.ndarray) -> np.ndarray:
        """The stretch every symbol of ``sids`` is drawn with (0 but for stretched copies)."""
        sids = np.asarray(sids, np.int64)
        inside = sids < self.n_terminals
        return np.where(inside, self.stretch[np.where(inside, sids, 0)], 0.0)

    def __len__(self) -> int:
        return len(self.infos)

    @property
    def sizes(self) -> np.ndarray:
        """Radius of every symbol's geometry in its own frame (0 until a node of it exists)."""
        return np.asarray(self._sizes, float)

    def families(self) -> np.ndarray:
        """Family index of every symbol (one per terminal, one per rule)."""
        ids: dict[str, int] = {}
        return np.array([ids.setdefault(s.family, len(ids)) for s in self.infos], dtype=np.int64)

    def new_name(self, prefix: str) -> str:
        """Return a fresh rule name ``P1``, ``P2`` … (prefix ``P``, ``R``, ``X`` or ``Z``)."""
        if prefix == "Z" and "Z" not in self._names:
            self._names.add("Z")
            return "Z"
        while True:
            self._counters[prefix] += 1
            name = f"{prefix}{self._counters[prefix]}"
            if name not in self._names:
                self._names.add(name)
                return name

    def symbol(self, name: str, m: int | None) -> int:
        """Return the index of non-terminal ``name`` called with counter ``m`` (added if new)."""
        key = ("r", name, m)
        if key not in self._index:
            self._index[key] = len(self.infos)
            self.infos.append(SymbolInfo(name, m, False, name))
            self._sizes.append(0.0)
        return self._index[key]

    def set_size(self, sid: int, size: float) -> None:
        """Record the radius of a non-terminal's geometry in its own frame (first node wins)."""
        if self._sizes[sid] == 0.0:
            self._sizes[sid] = float(size)

    def ref(self, sid: int) -> Symbol:
        """The module naming symbol ``sid`` (with its counter)."""
        s = self.infos[sid]
        return Symbol(s.name, Count(s.m) if s.m is not None else None)

    def draw(self, sid: int, last: bool = False) -> tuple[Module, ...]:
        """Modules that draw symbol ``sid`` without moving the turtle (brackets for non-terminals)."""
        mod = self.ref(sid)
        if sid < self.n_terminals and self.stretch_base[sid] != sid:
            t = float(self.stretch[sid])
            drawn = (Turtle("~", Linear(t)), self.ref(int(self.stretch_base[sid])))
            return drawn if last else (Push(), *drawn, Pop())
        return (mod,) if last or self.infos[sid].terminal else (Push(), mod, Pop())

    def phi(self, si: int, sj: int) -> float:
        """Similarity of two symbols (§5.4): the shapes' φ for terminals, else by family."""
        if si == sj:
            return 1.0
        a, b = self.infos[si], self.infos[sj]
        if a.terminal and b.terminal:
            return float(self.similarity[si, sj])
        if a.family == b.family:
            return 0.8
        return 0.3
