"""Tests of the k-d tree loaded without the rest of ``scipy.spatial``."""

from __future__ import annotations

import subprocess
import sys

import numpy as np

from lsys_core.geometry.kdtree import cKDTree


def test_the_tree_is_scipys_and_finds_neighbours():
    import scipy.spatial

    assert cKDTree is scipy.spatial.cKDTree  # (the package, imported later, has the same class)
    pts = np.array([[0.0, 0.0], [3.0, 4.0], [1.0, 1.0]])
    dist, idx = cKDTree(pts).query([[2.9, 4.1]])
    assert idx.tolist() == [1] and np.isclose(dist[0], np.hypot(0.1, 0.1))


def test_an_inference_loads_the_tree_alone_and_the_package_still_works():
    code = (
        "import sys\n"
        "from lsys_core.geometry.kdtree import cKDTree\n"
        "assert 'scipy.spatial' not in sys.modules\n"
        "import scipy.spatial\n"
        "from scipy.spatial.distance import cdist\n"
        "assert scipy.spatial.cKDTree is cKDTree and cdist([[0, 0]], [[3, 4]])[0, 0] == 5\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


def test_without_the_file_the_package_gives_the_tree():
    code = (
        "import sys, importlib.machinery\n"
        "find = importlib.machinery.PathFinder.find_spec\n"
        "def hide(name, path=None, target=None):\n"  # the file is not there unless the package asks
        "    alone = name == 'scipy.spatial._ckdtree' and 'scipy.spatial' not in sys.modules\n"
        "    return None if alone else find(name, path, target)\n"
        "importlib.machinery.PathFinder.find_spec = hide\n"
        "from lsys_core.geometry.kdtree import cKDTree\n"
        "assert 'scipy.spatial' in sys.modules\n"
        "import scipy.spatial\n"
        "assert cKDTree is scipy.spatial.cKDTree\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)
