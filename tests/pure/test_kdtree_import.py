# SPDX-License-Identifier: LGPL-2.1-or-later
"""``surfcomp.core.surface.kdtree``: scipy's cKDTree without importing all of
``scipy.spatial`` (its distance functions, rotations, ``scipy.special`` and
``scipy.constants``), the same class as the package's, and the package's class where the
extension cannot be loaded alone. Each case runs in a fresh interpreter (what a process
imported is the thing checked)."""

import json
import subprocess
import sys

import pytest

from tests.conftest import ROOT


def run(code):
    out = subprocess.run([sys.executable, "-c", "import sys\nsys.path.insert(0, %r)\n%s"
                          % (ROOT, code)], capture_output=True, text=True, timeout=120,
                         cwd=ROOT)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


#: what a process imported of scipy.spatial and its dependencies
LOADED = """
heavy = sorted(m for m in ("scipy.spatial", "scipy.spatial.distance", "scipy.spatial.transform",
                           "scipy.special", "scipy.constants") if m in sys.modules)
"""


def test_the_class_comes_without_the_package():
    got = run("from surfcomp.core.surface.kdtree import cKDTree\n" + LOADED + """
import json
print(json.dumps({"heavy": heavy, "module": cKDTree.__module__}))
""")
    assert got == {"heavy": [], "module": "scipy.spatial._ckdtree"}


def test_a_later_package_import_gives_the_same_class_and_results():
    got = run("""
import numpy as np
from surfcomp.core.surface.kdtree import cKDTree
rng = np.random.default_rng(7)
pts, q = rng.random((500, 3)), rng.random((50, 3))
d1, i1 = cKDTree(pts, balanced_tree=False).query(q, k=3, workers=2)
import scipy.spatial
from scipy.spatial import ckdtree  # the deprecated module that imports _ckdtree again
d2, i2 = scipy.spatial.cKDTree(pts, balanced_tree=False).query(q, k=3, workers=2)
import json
print(json.dumps({"same_class": scipy.spatial.cKDTree is cKDTree,
                  "same_module": sys.modules["scipy.spatial._ckdtree"].cKDTree is cKDTree,
                  "distances": bool((d1 == d2).all()), "indices": bool((i1 == i2).all()),
                  "nearest": int(i1[0, 0]), "brute": int(np.argmin(((pts - q[0]) ** 2).sum(1)))}))
""")
    assert got["same_class"] and got["same_module"]
    assert got["distances"] and got["indices"]
    assert got["nearest"] == got["brute"]


def test_the_package_imported_first_gives_its_class():
    got = run("""
import scipy.spatial
from surfcomp.core.surface.kdtree import cKDTree
import json
print(json.dumps({"same": cKDTree is scipy.spatial.cKDTree}))
""")
    assert got == {"same": True}


def test_without_the_extension_file_the_package_is_imported():
    """Another scipy layout (no ``spatial/_ckdtree`` extension file found): the class
    comes from ``scipy.spatial`` as before."""
    got = run("""
import importlib.machinery
importlib.machinery.EXTENSION_SUFFIXES[:] = []
from surfcomp.core.surface.kdtree import cKDTree
import json
print(json.dumps({"package": "scipy.spatial" in sys.modules,
                  "same": cKDTree is sys.modules["scipy.spatial"].cKDTree}))
""")
    assert got == {"package": True, "same": True}


@pytest.mark.parametrize("module", [
    "surfcomp.core.compensation.pipeline",
    "surfcomp.core.compensation.program_offset",
    "surfcomp.io.measurements",
    "surfcomp.io.gcode.offset_stream",
    "surfcomp.app.file_route",      # the routes' modules import FreeCAD only when they run
    "surfcomp.app.program_route",
])
def test_the_compensation_routes_modules_leave_scipy_spatial_out(module):
    got = run("import %s\n" % module + LOADED + """
import json
print(json.dumps({"heavy": heavy}))
""")
    assert got == {"heavy": []}, module
