# SPDX-License-Identifier: LGPL-2.1-or-later
"""Regenerate the README's screenshots (docs/screenshots/*.png) in the real FreeCAD GUI.

    xvfb-run -a -s "-screen 0 1600x1200x24" /usr/bin/python3 tests/gui/make_screenshots.py

Not a test: it runs the bundled example through the workbench's commands and saves
the deviation map (in µm, with a flagged point), the tolerance-band map (warning band,
percentages), each with its legend from the legend panel beside it, and the whole window
with the filter task panel, the legend panel and the histogram panel open.
"""

import os
import pathlib
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, ROOT)

from tests.gui.harness import run_gui, with_common  # noqa: E402

BODY = r'''
outdir = os.path.join(ROOT, "docs", "screenshots")
os.makedirs(outdir, exist_ok=True)
mw.resize(1400, 900)
doc = FreeCAD.newDocument("Example")
comp = make_map(doc, *load_example(doc))
view = Gui.ActiveDocument.ActiveView
view.viewIsometric()
view.fitAll()
Gui.updateGui()
vobj = comp.ViewObject


def save_with_legend(name):
    """The 3D view's image with the map's legend (the legend panel's entry) on its right."""
    path = os.path.join(outdir, name)
    view.saveImage(path, 1000, 650, "White")
    entry = legend_entries()[comp.Label]
    leg = entry.grab().toImage()
    img = QtGui.QImage(path)
    out = QtGui.QImage(img.width() + leg.width(), img.height(), QtGui.QImage.Format_RGB32)
    out.fill(QtGui.QColor(255, 255, 255))
    painter = QtGui.QPainter(out)
    painter.drawImage(0, 0, img)
    painter.drawImage(img.width(), 20, leg)
    painter.end()
    out.save(path)


# flag a point, as a click on the map does
dev = np.array(comp.Deviation)
vobj.Flags = [int(np.nanargmin(np.abs(dev - 0.03)))]
save_with_legend("deviation_map.png")
vobj.Flags = []
vobj.TolBand = True
vobj.TolLow = -0.01
vobj.TolHigh = 0.01
vobj.WarnBand = 0.8
save_with_legend("tolerance_band.png")
vobj.TolBand = False
vobj.WarnBand = 0.0
Gui.Selection.addSelection(doc.Name, comp.Name)
Gui.runCommand("SurfComp_Filter")
panels.FilterPanel.instance.show.setCurrentIndex(1)
vobj.Histogram = True
Gui.updateGui()
view.fitAll()
for _ in range(5):
    Gui.updateGui()
# a widget grab leaves the OpenGL view empty: paint the view's own render into it
shot = mw.grab()
gl = [w for w in mw.findChildren(QtGui.QWidget)
      if w.metaObject().className() == "QOpenGLWidget" and w.isVisible()]
if gl:
    w = gl[0]
    tmp_png = os.path.join(os.environ["SURFCOMP_TMP"], "view.png")
    view.saveImage(tmp_png, w.width(), w.height(), "Current")
    painter = QtGui.QPainter(shot)
    painter.drawImage(w.mapTo(mw, QtCore.QPoint(0, 0)), QtGui.QImage(tmp_png))
    painter.end()
RESULTS["gl_widgets"] = len(gl)
shot.save(os.path.join(outdir, "workbench_filter_panel.png"))
panels.FilterPanel.instance.reject()
RESULTS["written"] = sorted(os.listdir(outdir))
'''


def main():
    with tempfile.TemporaryDirectory() as tmp:
        res, _out = run_gui(with_common(BODY), pathlib.Path(tmp))
    if res["errors"]:
        print("\n".join(res["errors"]))
        raise SystemExit(1)
    print("docs/screenshots:", ", ".join(res["written"]))


if __name__ == "__main__":
    main()
