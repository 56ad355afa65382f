# SPDX-License-Identifier: LGPL-2.1-or-later
# Run by tests/app/test_toolpath_report.py in a fresh `freecadcmd` whose user home links this
# checkout: FreeCAD opens the 0.20 shop document itself (as File > Open does; surfcomp's
# Init.py has run, nothing else of surfcomp), then Restore and Replace of Round2 with what
# each did to the tool paths. SURFCOMP_BLOCK=ocl: OpenCamLib is unimportable while the
# document opens (a machine without it); SURFCOMP_BLOCK=cam: so are the CAM modules the
# document names (a FreeCAD that cannot resolve 0.20's names).
import importlib.abc
import json
import os
import sys

import FreeCAD

out = {"loaded_before_open": sorted(m for m in sys.modules
                                    if m.split(".")[0] in ("PathScripts", "ocl", "opencamlib")
                                    or m.startswith(("Path.", "surfcomp.gui")))}


BLOCKED = {"ocl": ("ocl", "opencamlib"),
           "cam": ("PathScripts.PathJob", "PathScripts.PathStock", "PathScripts.PathSetupSheet",
                   "PathScripts.PathToolController", "PathScripts.PathToolBit",
                   "PathScripts.PathSurface")}.get(os.environ.get("SURFCOMP_BLOCK"), ())


class Blocker(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path=None, target=None):
        if fullname in BLOCKED or fullname.split(".")[0] in BLOCKED:
            raise ImportError("%s is not importable here (test)" % fullname)
        return None


blocker = Blocker() if BLOCKED else None
if blocker:
    sys.meta_path.insert(0, blocker)
doc = FreeCAD.openDocument(os.environ["SURFCOMP_DOC"])
if blocker:
    sys.meta_path.remove(blocker)

from surfcomp.app import cam, replace, toolpaths  # noqa: E402
from surfcomp.errors import InputError  # noqa: E402
from tests.toolpath_checks import feed_moves, shop_surfaces  # noqa: E402

op = doc.getObject("Surface")
r2 = doc.getObject("Round2")


out.update({
    "modules": cam.branches()["modules"],
    "proxies": {o.Name: type(o.Proxy).__name__ for o in doc.Objects
                if "Proxy" in o.PropertiesList},
    "job_module": sys.modules["PathScripts.PathJob"].__name__
    if "PathScripts.PathJob" in sys.modules else None,
    "saved": feed_moves(op), "saved_commands": len(op.Path.Commands)})
snap = toolpaths.snapshot(doc)
replace.restore(doc, r2)
doc.recompute()
out["restore"] = toolpaths.as_dicts(toolpaths.compare(doc, snap))
out["restore_lines"] = toolpaths.describe(toolpaths.compare(doc, snap))
out["restored"] = feed_moves(op)
snap = toolpaths.snapshot(doc)
try:
    replace.replace(doc, r2)
except InputError as exc:
    out["replace_error"] = str(exc)
    out["replace_record"] = r2.ReplacedLinks
else:
    doc.recompute()
    out["replace"] = toolpaths.as_dicts(toolpaths.compare(doc, snap))
    out["replace_lines"] = toolpaths.describe(toolpaths.compare(doc, snap))
out["replaced"] = feed_moves(op)
out["surfaces"] = shop_surfaces(doc)
out["invalid"] = [o.Name for o in doc.Objects if "Invalid" in o.State or "Error" in o.State]
print("RESULT " + json.dumps(out))
sys.stdout.flush()
os._exit(0)
