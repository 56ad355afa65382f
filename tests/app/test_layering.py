# SPDX-License-Identifier: LGPL-2.1-or-later
"""The layers import only downwards (STYLE: gui -> app -> io -> core; cli over io, core, app).

For each layer a subprocess imports every module of the layer (sub-packages included) while
an import hook refuses, to surfcomp's own modules, the layers above it and the libraries it
must not use (FreeCAD's modules may import what they like: 1.x's Path imports PySide);
relative imports go through the same hook, so ``from ..app import x`` in core fails the
check. The
FreeCAD-free layers run with FreeCAD off the path; app and cli run with FreeCAD importable
but the GUI (FreeCADGui, Qt, coin) refused, so every document object recomputes headless.
"""

import json
import subprocess
import sys

import pytest

from tests.conftest import ROOT

FREECAD = ("FreeCAD", "FreeCADGui", "Part", "Path", "PathScripts", "Mesh", "MeshPart",
           "Import", "Draft")
GUI = ("FreeCADGui", "PySide", "PySide2", "PySide6", "pivy", "surfcomp.gui")

#: layer -> (modules it must never import, whether FreeCAD is set up first)
LAYERS = {
    "core": (FREECAD + GUI + ("surfcomp.io", "surfcomp.app", "surfcomp.cli"), False),
    "io": (FREECAD + GUI + ("surfcomp.app", "surfcomp.cli"), False),
    "app": (GUI + ("surfcomp.cli",), True),
    "cli": (GUI, True),
    "gui": (("surfcomp.cli",), True),
}

CODE = r"""
import importlib, json, pkgutil, sys
ROOT, LAYER, BLOCKED, FREECAD = sys.argv[1], sys.argv[2], json.loads(sys.argv[3]), sys.argv[4]
sys.path.insert(0, ROOT)
if FREECAD == "1":
    from surfcomp.app import fcenv
    fcenv.import_freecad()
else:
    sys.path = [p for p in sys.path if 'freecad' not in p.lower()]

def importer():
    # the module whose code asked for this import (importlib's frames skipped)
    f = sys._getframe(2)
    while f is not None and f.f_globals.get('__name__', '').startswith(
            ('importlib', '_frozen_importlib')):
        f = f.f_back
    return f.f_globals.get('__name__', '') if f is not None else ''

class Block:
    def find_spec(self, name, path=None, target=None):
        # surfcomp's own imports only: FreeCAD's modules may use Qt themselves
        # (1.x's Path package imports PySide)
        if not (importer().startswith('surfcomp') or name.startswith('surfcomp')):
            return None
        for b in BLOCKED:
            if name == b or name.startswith(b + '.'):
                raise ImportError('layering: %s must not import %s' % (LAYER, name))
        return None

sys.meta_path.insert(0, Block())
pkg = importlib.import_module('surfcomp.' + LAYER)
names = []
for m in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + '.'):
    if m.name.endswith('__main__'):
        continue
    importlib.import_module(m.name)
    names.append(m.name)
print(json.dumps(names))
"""


def _check(layer, blocked, freecad):
    out = subprocess.run([sys.executable, "-c", CODE, ROOT, layer, json.dumps(list(blocked)),
                          "1" if freecad else "0"], capture_output=True, text=True, timeout=300)
    return out


@pytest.mark.parametrize("layer", sorted(LAYERS))
def test_every_module_of_the_layer_imports_without_the_layers_above(layer):
    blocked, freecad = LAYERS[layer]
    out = _check(layer, blocked, freecad)
    assert out.returncode == 0, out.stderr[-3000:]
    names = json.loads(out.stdout.strip().splitlines()[-1])
    minimum = {"core": 15, "io": 10, "app": 12, "cli": 5, "gui": 5}[layer]
    assert len(names) >= minimum, names


def test_an_upward_import_is_caught(tmp_path):
    """The check itself: a core module that imports the app layer makes it fail."""
    import shutil

    root = tmp_path / "checkout"
    shutil.copytree(ROOT + "/surfcomp", root / "surfcomp",
                    ignore=shutil.ignore_patterns("__pycache__"))
    with open(root / "surfcomp" / "core" / "upward.py", "w") as fh:
        fh.write("from ..app import fcenv  # noqa: F401\n")
    blocked, freecad = LAYERS["core"]
    out = subprocess.run([sys.executable, "-c", CODE, str(root), "core",
                          json.dumps(list(blocked)), "0"],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode != 0
    assert "layering: core must not import surfcomp.app" in out.stderr
