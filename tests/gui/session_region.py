# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_region_gui.py: the two G1 top faces of a block picked in the 3D view
# (a click, then Ctrl+click), Compensate region, its figures, a screenshot, undo; a region
# covered too little refused with a message and nothing added; the next round: the region
# object and a new measurement picked in the tree, Compensate region again.
sys.path.insert(0, ROOT)
from surfcomp.app import features, region_doc
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


def click_view(xy, modifiers):
    """A real left click on the 3D view at ``xy`` (view pixels, origin bottom left)."""
    w = gl_widget()
    W, H = view.getSize()
    ratio = float(W) / w.width()
    click(w, QtCore.QPointF((xy[0] + 0.5) / ratio, (H - 1 - xy[1] + 0.5) / ratio), modifiers)


centres = [solid.Faces[k].Surface.value(5.0 + 10.0 * i, 5.0) for i, k in enumerate(tops)]
px = project(view, [tuple(c) for c in centres])
Gui.Selection.clearSelection()
RESULTS["active_nothing"] = active(region_cmd.CompensateRegion)
click_view(px[0], QtCore.Qt.NoModifier)
RESULTS["one_face"] = [selection(), active(region_cmd.CompensateRegion)]
click_view(px[1], QtCore.Qt.ControlModifier)
RESULTS["two_faces"] = [selection(), active(region_cmd.CompensateRegion)]
n0 = len(doc.Objects)
del ERRORS[:]
Gui.runCommand("SurfComp_CompensateRegion")
Gui.updateGui()
made = [o for o in doc.Objects if o.TypeId == "Part::FeaturePython"
        and getattr(getattr(o, "Proxy", None), "Type", "") == "SurfComp_RegionCompensation"]
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
px = project(view, [tuple(c) for c in centres])    # where the faces are drawn now
Gui.Selection.clearSelection()
click_view(px[0], QtCore.Qt.NoModifier)
click_view(px[1], QtCore.Qt.ControlModifier)
RESULTS["bad_faces"] = selection()
Gui.Selection.addSelection(doc.Name, bad.Name)
del ERRORS[:]
Gui.runCommand("SurfComp_CompensateRegion")
Gui.updateGui()
RESULTS["bad"] = [ERRORS[:], len(doc.Objects) - n1, block.ViewObject.Visibility]

# -- the next round: round 1 (made by the first part above, undone; here made as a script
# would), a second measurement (the part machined from its result: 30 % of the error
# left), the region object and that measurement picked in the tree
first = region_doc.make_region(doc, block, "Face1,Face2", meas)
doc.recompute()
second_csv = os.path.join(TMP, "g1_round2.csv")
rp.write_csv(second_csv, pts, nrm, 0.3 * dev)
meas2 = features.make_measurement(doc, second_csv, name="Round2")
doc.recompute()
del ERRORS[:]
Gui.Selection.clearSelection()
RESULTS["round_pick_region"] = [click_tree(first.Label), active(region_cmd.CompensateRegion)]
n2 = len(doc.Objects)
Gui.runCommand("SurfComp_CompensateRegion")     # two unused measurements: which one?
Gui.updateGui()
RESULTS["round_ambiguous"] = [ERRORS[:], len(doc.Objects) - n2]
del ERRORS[:]
click_tree(first.Label)
RESULTS["round_used"] = click_tree(meas.Label, QtCore.Qt.ControlModifier)
Gui.runCommand("SurfComp_CompensateRegion")     # round 1's own measurement
Gui.updateGui()
RESULTS["round_used_refused"] = [ERRORS[:], len(doc.Objects) - n2]
del ERRORS[:]
click_tree(first.Label)
RESULTS["round_pick"] = click_tree(meas2.Label, QtCore.Qt.ControlModifier)
undo0 = doc.UndoCount
Gui.runCommand("SurfComp_CompensateRegion")
Gui.updateGui()
rounds = [o for o in doc.Objects if getattr(getattr(o, "Proxy", None), "Type", "") ==
          "SurfComp_RegionCompensation" and o.Base is not None]
RESULTS["round_errors"] = ERRORS[:]
if rounds:
    r2 = rounds[0]
    RESULTS["round2"] = {
        "base": r2.Base.Name, "first": first.Name, "round": r2.Round, "label": r2.Label,
        "faces": list(r2.RegionFaces), "measurement": r2.Measurement.Name,
        "options": [[first.Method, first.MaskSize, first.MinCoverage],
                    [r2.Method, r2.MaskSize, r2.MinCoverage]],
        "vol_first": first.VolChange, "vol": r2.VolChange, "max_gap": r2.MaxGap,
        "valid": r2.Shape.isValid(), "visible": [first.ViewObject.Visibility,
                                                 r2.ViewObject.Visibility],
        "undo": doc.UndoCount - undo0, "status": mw.statusBar().currentMessage()}
    view.viewIsometric()
    view.fitAll()
    settle(view)
    RESULTS["round_shot"] = shot(view, "region_round2")
