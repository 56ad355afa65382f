# SPDX-License-Identifier: LGPL-2.1-or-later
"""Print the versions surfcomp runs on: FreeCAD, Python, numpy, scipy, OpenCamLib, Qt and
the branches the version adapter (surfcomp.app.cam) takes. One line, for install.sh, the
version matrix and bug reports.

    /usr/bin/python3 tools/versions.py [--prefix TEXT] [--json | --summary]
"""

import argparse
import json
import os
import platform
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)


def versions():
    import numpy
    import scipy

    out = {"python": platform.python_version(), "numpy": numpy.__version__,
           "scipy": scipy.__version__}
    try:
        from surfcomp.app import cam, fcenv

        FreeCAD = fcenv.import_freecad()
        out["freecad"] = ".".join(FreeCAD.Version()[:3])
        out.update(cam.branches())
        cam.setup_ocl()
        import ocl

        out["opencamlib"] = os.path.dirname(ocl.__file__)
    except ImportError as exc:
        out.setdefault("freecad", "missing (%s)" % exc)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--prefix", default="")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--summary", action="store_true", help="the version matrix's short form")
    args = ap.parse_args(argv)
    v = versions()
    if args.json:
        print(json.dumps(v, sort_keys=True))
        return 0
    if args.summary:
        print("%sFreeCAD %s (Python %s, numpy %s, scipy %s; CAM modules %s, tool bits %s, %s)"
              % (args.prefix, v.get("freecad"), v["python"], v["numpy"], v["scipy"],
                 v.get("modules", "-"), v.get("toolbits", "-"), v.get("qt", "-")))
        return 0
    print("%sFreeCAD %s, Python %s, numpy %s, scipy %s, CAM modules %s, tool bits %s, Qt %s, "
          "OpenCamLib in %s" % (args.prefix, v.get("freecad"), v["python"], v["numpy"],
                                v["scipy"], v.get("modules", "-"), v.get("toolbits", "-"),
                                v.get("qt", "-"), v.get("opencamlib", "-")))
    return 0 if not v["freecad"].startswith("missing") else 1


if __name__ == "__main__":
    sys.exit(main())
