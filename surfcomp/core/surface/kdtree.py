# SPDX-License-Identifier: LGPL-2.1-or-later
"""scipy's ``cKDTree`` without the rest of ``scipy.spatial`` (no FreeCAD).

``from scipy.spatial import cKDTree`` runs the package's ``__init__``, which imports the
distance functions, Delaunay and Voronoi, and the rotations (``scipy.spatial.transform``,
which imports ``scipy.special`` and ``scipy.constants``): a large share of every
command's start (scipy 1.10, Debian 12; docs/benchmarks.md, "Costs behind choices in the
code"), for the one class the compensation routes use.

Here, while ``scipy.spatial`` is not imported yet, only its extension module
``scipy.spatial._ckdtree`` is loaded, under its own name, so that a later ``import
scipy.spatial`` (a route that needs ``Delaunay`` or the rotations) takes the same module
and the same class. Where that extension is not found or does not load (another scipy
layout), the class comes from the package as before. The tree is scipy's own in both
cases: the results are the same bytes.
"""

import importlib.machinery
import importlib.util
import os
import sys

#: the extension module holding the class (scipy 1.6 and later)
EXTENSION = "scipy.spatial._ckdtree"


def _extension():
    """The extension module ``scipy.spatial._ckdtree`` loaded without its package, or None
    where it is not found or does not load."""
    import scipy

    folder = os.path.join(os.path.dirname(os.path.abspath(scipy.__file__)), "spatial")
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        path = os.path.join(folder, "_ckdtree" + suffix)
        if not os.path.isfile(path):
            continue
        spec = importlib.util.spec_from_file_location(EXTENSION, path)
        if spec is None or spec.loader is None:
            return None
        try:
            module = importlib.util.module_from_spec(spec)
            sys.modules[EXTENSION] = module
            spec.loader.exec_module(module)
        except ImportError:
            sys.modules.pop(EXTENSION, None)
            return None
        return module
    return None


def _load():
    """The ``cKDTree`` class: from the loaded module when ``scipy.spatial`` or its extension
    is imported already, else from the extension alone (:func:`_extension`), else from the
    package."""
    module = sys.modules.get(EXTENSION)
    if module is None and "scipy.spatial" not in sys.modules:
        module = _extension()
    tree = getattr(module, "cKDTree", None)
    if tree is None:
        from scipy.spatial import cKDTree as tree
    return tree


cKDTree = _load()
