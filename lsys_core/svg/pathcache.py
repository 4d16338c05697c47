"""Path data of a whole document, parsed in one pass before the walk.

Parsing each ``d`` on its own costs a fixed overhead per path; reading every distinct ``d`` of the
document at once (:func:`~lsys_core.geometry.pathdata.parse_paths`) costs it once.  The segment
budget of the document is enforced here, before the cubic arrays are allocated.
"""

from __future__ import annotations

import numpy as np

from lsys_core.errors import LimitError
from lsys_core.geometry import pathdata as pd
from lsys_core.geometry.pathdata import PathTable, parse_paths
from lsys_core.geometry.paths import ArrayPath, arrays_from_table
from lsys_core.svg.tree import Tree

__all__ = ["DEFAULT_MAX_PATH_NUMBERS", "DEFAULT_MAX_SEGMENTS", "PathCache"]

#: Path segments (after arcs are cut into cubics) a document may draw, all elements together.
DEFAULT_MAX_SEGMENTS = 2_000_000
#: Numbers in the path data of a document, all paths together.
DEFAULT_MAX_PATH_NUMBERS = 4_000_000


class PathCache:
    """Parsed path data by ``d`` text: cubics, rows (for markers) and the first error."""

    def __init__(self, tree: Tree, name: str = "<string>", max_segments: int | None = None) -> None:
        if max_segments is None:
            max_segments = DEFAULT_MAX_SEGMENTS
        ds = list(dict.fromkeys([el.get("d") or "" for el in tree.of_kind("path")]))
        self._index = {d: i for i, d in enumerate(ds)}
        try:
            self._table = parse_paths(ds, max_numbers=DEFAULT_MAX_PATH_NUMBERS) if ds else None
        except LimitError as exc:
            raise LimitError(f"{name}: {exc}") from exc
        self._paths: list[ArrayPath] = []
        if self._table is not None:
            drawing = int(np.count_nonzero(self._table.op != pd.MOVE))  # rows that draw a segment
            if drawing > max_segments:
                raise LimitError(f"{name} has more than {max_segments:,} path segments")
            self._paths = arrays_from_table(self._table, len(ds), max_segments=max_segments, name=name)
            self._bounds = np.searchsorted(self._table.path, np.arange(len(ds) + 1))
            arc_rows = np.cumsum(self._table.op == pd.ARC)
            self._arc_before = np.concatenate([[0], arc_rows])

    def release(self) -> None:
        """Forget the parsed paths (after the walk; the records keep the ones they drew).

        The table and the converted paths of a path of 10^6 segments are 61 MiB each; the
        reader that holds this cache lives in a reference cycle until the next collection.
        """
        self._index = {}
        self._table = None
        self._paths = []

    def get(self, d: str, rows: bool = True) -> tuple[ArrayPath, PathTable | None, str | None]:
        """Return the cubics, the rows (None unless ``rows``) and the first error of path data ``d``.

        Only markers and caps need the rows: slicing them for every path cost 0.33 of 5.3
        profiled seconds reading 20,000 leaves that have neither.
        """
        i = self._index.get(d)
        if i is None or self._table is None:
            from lsys_core.geometry.pathdata import parse_path
            from lsys_core.geometry.paths import path_from_d

            path, error = path_from_d(d)
            return path, parse_path(d) if rows else None, error
        return self._paths[i], self._rows(i) if rows else None, self._table.errors[i]

    def _rows(self, i: int) -> PathTable:
        t = self._table
        assert t is not None
        a, b = int(self._bounds[i]), int(self._bounds[i + 1])
        arc_a, arc_b = int(self._arc_before[a]), int(self._arc_before[b])
        return PathTable(t.op[a:b], t.pts[a:b], t.arc[arc_a:arc_b], t.path[a:b] - i, (t.errors[i],))
