# SPDX-License-Identifier: LGPL-2.1-or-later
"""How fast the filter task panel redraws the live map after a change, on the example's
45 x 45 grid (issue 13: within 0.3 s).

    xvfb-run -a -s "-screen 0 1600x1200x24" /usr/bin/python3 bench/bench_filter_panel.py

Runs inside the real FreeCAD GUI (tests/gui/harness.py). Opens the Filter panel on the
example's deviation map and, for changes of mask size, weights, mask kind and edge handling,
times ``FilterPanel.update`` (check, preview recompute of the compensation, map redraw, RMS
figures) and, inside it, the recompute and the redraw alone. The panel waits its debounce
(``FilterPanel.DEBOUNCE``) after the last key press before it starts; that is printed too.
Prints seconds.
"""

import os
import pathlib
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from tests.gui.harness import run_gui, with_common  # noqa: E402

BODY = r'''
doc = FreeCAD.newDocument("Bench")
comp = make_map(doc, *load_example(doc))
Gui.Selection.addSelection(doc.Name, comp.Name)
Gui.runCommand("SurfComp_Filter")
panel = panels.FilterPanel.instance
proxy = comp.ViewObject.Proxy
parts = {"recompute": [], "redraw": []}
real_recompute, real_redraw = doc.recompute, proxy.redraw


def timed(name, fn):
    def run(*a, **k):
        t0 = time.perf_counter()
        out = fn(*a, **k)
        parts[name].append(time.perf_counter() - t0)
        return out
    return run


proxy.redraw = timed("redraw", real_redraw)
changes = [("mask", v) for v in (7, 9, 11, 13, 5, 3)] + \
    [("weights", "1 2 1; 2 4 2; 1 2 1"), ("weights", "")] + \
    [("kind", 1), ("kind", 0), ("edge", 1), ("edge", 0)]
rows = []
for what, value in changes:
    if what == "mask":
        panel.mask.setValue(value)
    elif what == "weights":
        panel.weights.setText(value)
    elif what == "kind":
        panel.kind.setCurrentIndex(value)
    else:
        panel.edge.setCurrentIndex(value)
    panel.timer.stop()
    t0, c0 = time.perf_counter(), time.process_time()
    ok = panel.update()
    total, cpu = time.perf_counter() - t0, time.process_time() - c0
    Gui.updateGui()
    rows.append([what, str(value), total, ok, cpu])
RESULTS["rows"] = rows
RESULTS["redraw"] = parts["redraw"]
RESULTS["debounce"] = panels.FilterPanel.DEBOUNCE
# the recompute alone, for the same changes of the mask size
rec = []
for v in (7, 9, 11, 5):
    comp.MaskSize = v
    t0 = time.perf_counter()
    doc.recompute()
    rec.append(time.perf_counter() - t0)
RESULTS["recompute"] = rec
panel.reject()
'''


def main():
    with tempfile.TemporaryDirectory() as tmp:
        res, _out = run_gui(with_common(BODY), pathlib.Path(tmp))
    if res["errors"]:
        print("\n".join(res["errors"]))
        raise SystemExit(1)
    print("filter panel on the 45 x 45 example grid (seconds, after the %d ms debounce)"
          % res["debounce"])
    for what, value, total, ok, cpu in res["rows"]:
        print("  %-8s %-22s update %.3f (CPU %.3f)%s" % (what, value or "(none)", total, cpu,
                                                         "" if ok else "  (refused)"))
    totals = sorted(r[2] for r in res["rows"])
    cpus = sorted(r[4] for r in res["rows"])
    print("update: median %.3f, max %.3f; CPU time median %.3f, max %.3f (the machine's load "
          "average: %.1f)" % (totals[len(totals) // 2], totals[-1], cpus[len(cpus) // 2],
                              cpus[-1], os.getloadavg()[0]))
    red = sorted(res["redraw"])
    print("of which redraw (mesh field, colours, coin): median %.3f, max %.3f"
          % (red[len(red) // 2], red[-1]))
    rec = sorted(res["recompute"])
    print("of which preview recompute: median %.3f, max %.3f" % (rec[len(rec) // 2], rec[-1]))


if __name__ == "__main__":
    main()
