# SPDX-License-Identifier: LGPL-2.1-or-later
"""How fast the filter task panel's live map follows a key, on the example's 45 x 45 grid
(issue 24: on screen within 0.3 s of the last key press), beside a reference version of
surfcomp measured in the same run.

    xvfb-run -a -s "-screen 0 1600x1200x24" /usr/bin/python3 bench/bench_filter_panel.py \\
        [--reference REV | --reference-tree DIR] [--presses 12]

Each version runs in its own fresh FreeCAD GUI (tests/gui/harness.py): the example's map,
the Filter panel open, then real key presses at the X server (XTest, as a keyboard sends
them; tests/gui/latency.py): Up and Down on the mask size, one at a time with the GUI quiet
in between, and custom weights typed 80 ms a key. Each is timed from the (last) press to
the first render of the 3D view that shows the map's new colours; FreeCAD's CPU seconds
over that time (all its threads, the rendering's included) are printed too, as they move
less with other jobs on the machine. ``--reference`` is a git revision of this repository
(default: the code before the preview was made faster), exported into a temporary folder;
``--reference-tree`` takes such a folder instead (a copy without git, e.g. in a chroot).
"""

import argparse
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from tests.gui.harness import run_gui, with_common  # noqa: E402

#: the code before the live preview was made faster (issue 24)
REFERENCE = "d5598b0"

BODY = r'''
sys.path.insert(0, ROOT)
from tests.gui import latency

doc = FreeCAD.newDocument("Bench")
comp = make_map(doc, *load_example(doc))
view = view_top()
Gui.Selection.addSelection(doc.Name, comp.Name)
Gui.runCommand("SurfComp_Filter")
panel = panels.FilterPanel.instance
app = QtGui.QApplication.instance()
keys = latency.PanelKeys(app, mw, panel, view, comp.ViewObject.Proxy.scene)
RESULTS["presses"] = keys.presses(["Up", "Down"] * (PRESSES // 2))
RESULTS["typing"] = keys.typing("1 2 1; 2 4 2; 1 2 1")
RESULTS["debounce"] = panels.FilterPanel.DEBOUNCE
RESULTS["load"] = os.getloadavg()[0]
RESULTS["version"] = ".".join(FreeCAD.Version()[:3])
keys.close()
panel.reject()
'''


def measure(tree, presses, tmp):
    """Run the measurement with surfcomp from ``tree`` (a checkout); its results."""
    home = tmp / "fchome"
    (home / "Mod").mkdir(parents=True)
    os.symlink(tree, home / "Mod" / "surfcomp")
    body = with_common("PRESSES = %d\n" % presses + BODY)
    res, _out = run_gui(body, tmp, home=home, timeout=600)
    if res["errors"]:
        raise SystemExit("\n".join(res["errors"]))
    return res


def export(rev, where):
    """The files of revision ``rev`` of this repository, in ``where``."""
    archive = subprocess.run(["git", "-C", ROOT, "archive", rev], check=True,
                             capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(where)], input=archive, check=True)
    return str(where)


def line(name, res):
    changed = [r for r in res["presses"] if r["changed"]]
    if len(changed) < len(res["presses"]) or not res["typing"]["changed"]:
        raise SystemExit("%s: %d of %d key presses (typing: %s) changed nothing on the map: "
                         "the keys did not reach the panel" % (
                             name, len(res["presses"]) - len(changed), len(res["presses"]),
                             res["typing"]["changed"]))
    secs = [r["seconds"] for r in changed if r["seconds"] is not None]
    cpus = [r["cpu"] for r in changed if r["cpu"] is not None]
    missed = len(changed) - len(secs)
    t = res["typing"]
    return ("  %-22s debounce %3d ms  key press: median %.3f s, max %.3f s (CPU median %.3f s)"
            "%s; typed weights, last key: %s (CPU %s); load %.1f"
            % (name, res["debounce"], statistics.median(secs), max(secs),
               statistics.median(cpus), "; %d not repainted" % missed if missed else "",
               "%.3f s" % t["seconds"] if t["seconds"] is not None else "not repainted",
               "%.3f s" % t["cpu"] if t["cpu"] is not None else "-", res["load"]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--reference", default=REFERENCE, help="git revision to compare with")
    ap.add_argument("--reference-tree", help="a folder holding the reference's files")
    ap.add_argument("--presses", type=int, default=12)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        (tmp / "ref").mkdir()
        (tmp / "now").mkdir()
        (tmp / "ref-run").mkdir()
        tree = args.reference_tree or export(args.reference, tmp / "ref")
        ref = measure(os.path.abspath(tree), args.presses, tmp / "ref-run")
        now = measure(ROOT, args.presses, tmp / "now")
    print("filter panel, key press to repaint of the live map (45 x 45 example grid, "
          "FreeCAD %s, %d presses)" % (now["version"], args.presses))
    print(line("this checkout", now))
    print(line("reference " + (args.reference_tree or args.reference), ref))


if __name__ == "__main__":
    main()
