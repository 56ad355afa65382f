# SPDX-License-Identifier: LGPL-2.1-or-later
"""How fast a colour map appears in the FreeCAD GUI for a 200 x 200 measurement grid.

    xvfb-run -a -s "-screen 0 1600x1200x24" /usr/bin/python3 bench/bench_colormap.py

Runs inside the real FreeCAD GUI (tests/gui/harness.py). A 200 x 200 grid of points on
the example face (nominal + normal + deviation, the example's deviation field plus
noise) is turned into a compensation; then the map is switched on from an empty cache
(mesh of the face, field of the node values, colours, coin nodes, first redraw) and
restyled (range change: recolour only). Prints seconds; the issue's goal is < 1 s.
"""

import os
import pathlib
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from tests.gui.harness import run_gui  # noqa: E402

BODY = r'''
import time
import numpy as np
sys.path.insert(0, os.environ["SURFCOMP_ROOT"])
from examples.make_example import deviation_field
from surfcomp.app import features
from surfcomp.app.nominal import load_nominal
from surfcomp.core.surface import bspline
from surfcomp.io.measurements import MeasurementSet
from surfcomp.gui import viewproviders
import Part

N = int(os.environ.get("BENCH_GRID", "200"))
root = os.environ["SURFCOMP_ROOT"]
nom = load_nominal(os.path.join(root, "examples", "nominal.step"))
t = np.linspace(0.01, 0.99, N)
P, Su, Sv = bspline.evaluate_grid(nom.surface, t, t, order=1)
nrm = np.cross(Su, Sv)
nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
P, nrm = P.reshape(-1, 3), nrm.reshape(-1, 3)
rng = np.random.default_rng(1)
d = deviation_field(P[:, 0], P[:, 1]) + rng.normal(0, 0.0015, len(P))
ms = MeasurementSet(nominal=P, normal=nrm, deviation=d, source="bench",
                    columns={"x_nom": "x", "y_nom": "y", "z_nom": "z", "i": "i", "j": "j",
                             "k": "k", "dev": "dev"})
doc = FreeCAD.newDocument("Bench")
part = doc.addObject("Part::Feature", "Nominal")
part.Shape = Part.read(os.path.join(root, "examples", "nominal.step"))
meas = features.make_measurement_from_set(doc, ms)
comp = features.make_compensation(doc, part, "Face1", meas)
viewproviders.attach(comp)
comp.ViewObject.DisplayMode = "Shaded"
t0 = time.perf_counter()
doc.recompute()
RESULTS["recompute_s"] = time.perf_counter() - t0
RESULTS["grid"] = [comp.GridRows, comp.GridCols]
view = FreeCADGui.ActiveDocument.ActiveView
view.viewTop()
view.fitAll()
FreeCADGui.updateGui()
vp = comp.ViewObject.Proxy
for rep in range(3):
    vp._data = {}
    comp.ViewObject.DisplayMode = "Shaded"
    FreeCADGui.updateGui()
    t0 = time.perf_counter()
    t_data = time.perf_counter()
    d = viewproviders.map_data(comp, "deviation")
    t_data = time.perf_counter() - t_data
    vp._data["deviation"] = d
    t_scene = time.perf_counter()
    comp.ViewObject.DisplayMode = "Map"
    t_scene = time.perf_counter() - t_scene
    view.redraw()
    FreeCADGui.updateGui()
    RESULTS.setdefault("map_total_s", []).append(time.perf_counter() - t0)
    RESULTS.setdefault("map_data_s", []).append(t_data)
    RESULTS.setdefault("scene_s", []).append(t_scene)
RESULTS["mesh_vertices"] = vp.scene.surface_coords.point.getNum()
RESULTS["markers"] = vp.scene.marker_coords.point.getNum()
t0 = time.perf_counter()
comp.ViewObject.AutoRange = False
comp.ViewObject.RangeMin = -0.02
comp.ViewObject.RangeMax = 0.02
view.redraw()
FreeCADGui.updateGui()
RESULTS["restyle_s"] = time.perf_counter() - t0
for name, prop in (("no_points", "Points"),):
    setattr(comp.ViewObject, prop, False)
    t0 = time.perf_counter()
    view.redraw()
    FreeCADGui.updateGui()
    RESULTS[name + "_s"] = time.perf_counter() - t0
for k in range(2):
    t0 = time.perf_counter()
    view.redraw()
    FreeCADGui.updateGui()
    RESULTS.setdefault("redraw_only_s", []).append(time.perf_counter() - t0)
view.saveImage(os.path.join(os.environ["SURFCOMP_TMP"], "bench_map.png"), 1200, 800, "White")
'''


def main():
    with tempfile.TemporaryDirectory() as tmp:
        res, out = run_gui(BODY, pathlib.Path(tmp), timeout=600)
    if res["errors"]:
        print("\n".join(res["errors"]))
        raise SystemExit(1)
    print("grid %d x %d, mesh %d vertices, %d markers" % (
        res["grid"][0], res["grid"][1], res["mesh_vertices"], res["markers"]))
    print("compensation recompute (pipeline, not the map): %.2f s" % res["recompute_s"])
    for k in range(len(res["map_total_s"])):
        print("map appears: %.3f s  (mesh + field + values %.3f s, coin nodes %.3f s, "
              "redraw %.3f s)" % (res["map_total_s"][k], res["map_data_s"][k], res["scene_s"][k],
                                  res["map_total_s"][k] - res["map_data_s"][k] - res["scene_s"][k]))
    print("range change (recolour only): %.3f s" % res["restyle_s"])
    print("without point markers: %.3f s; plain redraws: %s" % (
        res["no_points_s"], ", ".join("%.3f s" % t for t in res["redraw_only_s"])))


if __name__ == "__main__":
    main()
