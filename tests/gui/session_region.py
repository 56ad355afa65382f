# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_region_gui.py: the two G1 top faces of a block picked in the 3D view
# (a click, then Ctrl+click), Compensate region, its figures, a screenshot, undo; a region
# covered too little refused with a message and nothing added.
sys.path.insert(0, ROOT)
from surfcomp.app import features
from surfcomp.gui import region_cmd
from tests.app import region_parts as rp

doc = FreeCAD.newDocument("Region")
solid, tops = rp.g1_top_solid()
block = doc.addObject("Part::Feature", "Block")
block.Shape = solid
pts, nrm, dev = rp.sample_faces([solid.Faces[k] for k in tops], 3000, rp.ridge_field, seed=1)
good = os.path.join(TMP, "g1.csv")
rp.write_csv(good, pts, nrm, dev)
meas = features.make_measurement(doc, good)
doc.recompute()
meas.ViewObject.Visibility = False
view = view_top()


def click(xy, modifiers):
    """A real left click on the 3D view at ``xy`` (view pixels, origin bottom left) with
    keyboard ``modifiers`` (Ctrl adds to the selection)."""
    w = gl_widget()
    W, H = view.getSize()
    ratio = float(W) / w.width()
    pos = QtCore.QPointF((xy[0] + 0.5) / ratio, (H - 1 - xy[1] + 0.5) / ratio)
    glob = QtCore.QPointF(w.mapToGlobal(pos.toPoint()))
    for kind, buttons in ((QtCore.QEvent.MouseButtonPress, QtCore.Qt.LeftButton),
                          (QtCore.QEvent.MouseButtonRelease, QtCore.Qt.NoButton)):
        Gui.updateGui()
        ev = QtGui.QMouseEvent(kind, pos, glob, QtCore.Qt.LeftButton, buttons, modifiers)
        QtGui.QApplication.sendEvent(w, ev)
        Gui.updateGui()


centres = [solid.Faces[k].Surface.value(5.0 + 10.0 * i, 5.0) for i, k in enumerate(tops)]
px = project(view, [tuple(c) for c in centres])
Gui.Selection.clearSelection()
RESULTS["active_nothing"] = active(region_cmd.CompensateRegion)
click(px[0], QtCore.Qt.NoModifier)
RESULTS["one_face"] = [selection(), active(region_cmd.CompensateRegion)]
click(px[1], QtCore.Qt.ControlModifier)
RESULTS["two_faces"] = [selection(), active(region_cmd.CompensateRegion)]
n0 = len(doc.Objects)
del ERRORS[:]
Gui.runCommand("SurfComp_CompensateRegion")
Gui.updateGui()
made = [o for o in doc.Objects if o.TypeId == "Part::FeaturePython"
        and getattr(o.Proxy, "Type", "") == "SurfComp_RegionCompensation"]
reg = made[0] if made else None
RESULTS["errors_run"] = ERRORS[:]
RESULTS["made"] = [len(made), len(doc.Objects) - n0]
if reg is not None:
    RESULTS["region"] = {"faces": reg.Faces, "region_faces": list(reg.RegionFaces),
                         "points": list(reg.PointsPerFace), "max_gap": reg.MaxGap,
                         "max_angle_change": reg.MaxAngleChange, "vol_change": reg.VolChange,
                         "integral": reg.CorrIntegral, "volume": reg.Shape.Volume,
                         "nominal_volume": block.Shape.Volume, "n_faces": len(reg.Shape.Faces),
                         "valid": reg.Shape.isValid(), "state": list(reg.State),
                         "block_visible": block.ViewObject.Visibility,
                         "visible": reg.ViewObject.Visibility}
RESULTS["display_mode"] = reg.ViewObject.DisplayMode if reg is not None else None
view.viewIsometric()
view.fitAll()
settle(view)
RESULTS["shot"] = shot(view, "region")
RESULTS["status"] = mw.statusBar().currentMessage()
doc.undo()
Gui.updateGui()
RESULTS["after_undo"] = [len(doc.Objects) - n0, block.ViewObject.Visibility]

# Face2 measured on its y < 3 strip only: refused, naming the face, nothing added
keep = ~((pts[:, 0] > 10) & (pts[:, 1] > 3))
part = os.path.join(TMP, "part.csv")
rp.write_csv(part, pts[keep], nrm[keep], dev[keep])
bad = features.make_measurement(doc, part, name="Partial")
doc.recompute()
bad.ViewObject.Visibility = False
n1 = len(doc.Objects)
view_top()
Gui.Selection.clearSelection()
click(px[0], QtCore.Qt.NoModifier)
click(px[1], QtCore.Qt.ControlModifier)
Gui.Selection.addSelection(doc.Name, bad.Name)
del ERRORS[:]
Gui.runCommand("SurfComp_CompensateRegion")
Gui.updateGui()
RESULTS["bad"] = [ERRORS[:], len(doc.Objects) - n1, block.ViewObject.Visibility]
