"""core/ and io/ must import without FreeCAD, Part or Qt on the path."""

import subprocess
import sys

from tests.conftest import ROOT

CODE = r"""
import importlib, pkgutil, sys
sys.path = [p for p in sys.path if 'freecad' not in p.lower()]
class Block:
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in ('FreeCAD', 'FreeCADGui', 'Part', 'Path', 'PathScripts',
                                  'PySide', 'PySide2', 'pivy'):
            raise ImportError('blocked for the layering test: ' + name)
sys.meta_path.insert(0, Block())
import surfcomp.core, surfcomp.io
names = []
for pkg in (surfcomp.core, surfcomp.io):
    for m in pkgutil.iter_modules(pkg.__path__):
        importlib.import_module(pkg.__name__ + '.' + m.name)
        names.append(m.name)
print(len(names))
"""


def test_core_and_io_import_without_freecad():
    out = subprocess.run([sys.executable, "-c", CODE], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert int(out.stdout.strip()) >= 2
