"""scipy's k-d tree, :class:`cKDTree`, loaded without the rest of ``scipy.spatial``.

``from lsys_core.geometry.kdtree import cKDTree`` runs the package's ``__init__``, which imports all of it
(Delaunay and Voronoi, distances, rotations, ...): 27-37 ms of every ``lsys infer`` (whose
whole run takes 0.68 s for 1,200 elements) for the one class this package uses.  The class
is defined by the compiled module ``scipy.spatial._ckdtree``, which needs only numpy and
``scipy.sparse`` (imported anyway); it is loaded from its file under its own name, in about
1 ms, and a later ``import scipy.spatial`` finds it there and uses the same class.  Where that
does not work (the package already imported, another layout, a bundle without the file), the
package is imported as usual.
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import os
import sys
from types import ModuleType
from typing import TYPE_CHECKING

__all__ = ["cKDTree"]

_NAME = "scipy.spatial._ckdtree"


def _load_alone() -> ModuleType | None:
    """Load ``scipy.spatial._ckdtree`` from its file, without its package (None where it cannot)."""
    import scipy

    folder = os.path.join(os.path.dirname(scipy.__file__ or ""), "spatial")
    spec = importlib.machinery.PathFinder.find_spec(_NAME, [folder])
    if (
        spec is None
        or spec.loader is None
        or not isinstance(spec.loader, importlib.machinery.ExtensionFileLoader)
    ):
        return None
    module = importlib.util.module_from_spec(spec)
    sys.modules[_NAME] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        sys.modules.pop(_NAME, None)
        raise
    return module


def _tree_class() -> type:
    if "scipy.spatial" not in sys.modules and _NAME not in sys.modules:
        try:
            module = _load_alone()
        except Exception:  # (the package, below, says what is wrong, if anything)
            module = None
        if module is not None and isinstance(getattr(module, "cKDTree", None), type):
            return module.cKDTree
    from scipy.spatial import cKDTree as tree

    return tree


if TYPE_CHECKING:
    from scipy.spatial import cKDTree
else:
    cKDTree = _tree_class()
