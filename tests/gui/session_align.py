# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_align_gui.py: the Align measurements command on a document opened from
# disk whose measurement was taken after re-clamping; its task panel driven by real key and
# mouse events: a transform file, a best fit with chosen degrees of freedom, a bad 3-2-1 set
# refused in the panel, OK as one undo step, Cancel leaving nothing.
import json  # noqa: E402

import Part  # noqa: E402

from surfcomp.app import features  # noqa: E402
from surfcomp.core.measurement import align  # noqa: E402
from surfcomp.gui import align_panel  # noqa: E402
from surfcomp.io.readers import read_any  # noqa: E402

# the example's measured points, and the same after re-clamping: 0.3 deg about Z, 50 um
ms = read_any(MEAS)
points = ms.nominal + ms.normal * ms.deviation[:, None]
SETUP = align.work_offset([0.04, -0.03, 0.05], 0.3)
for name, P in (("still.xyz", points), ("moved.xyz", align.apply(SETUP, points))):
    np.savetxt(os.path.join(TMP, name), P, fmt="%.10f", header="x y z", comments="")
with open(os.path.join(TMP, "t.json"), "w") as f:
    json.dump({"matrix": np.linalg.inv(SETUP).tolist()}, f)
with open(os.path.join(TMP, "rps.json"), "w") as f:
    json.dump({"primary": [1, 40, 2000], "secondary": [5, 30], "tertiary": [1000]}, f)

made = FreeCAD.newDocument("Aligned")
nom = made.addObject("Part::Feature", "Nominal")
nom.Shape = Part.read(NOMINAL)
ref = features.make_compensation(made, nom, "Face1",
                                 features.make_measurement(made, os.path.join(TMP, "still.xyz"),
                                                           name="Still"))
ref.Label = "Reference"
meas = features.make_measurement(made, os.path.join(TMP, "moved.xyz"), name="Reclamped")
comp = features.make_compensation(made, nom, "Face1", meas)
made.recompute()
names = comp.Name, meas.Name, ref.Name
path = os.path.join(TMP, "align.FCStd")
made.saveAs(path)
FreeCAD.closeDocument(made.Name)
Gui.updateGui()

# -- the user opens the document and selects the compensation -----------------------------
doc = FreeCAD.openDocument(path)
for _ in range(20):
    Gui.updateGui()
    time.sleep(0.02)
comp, meas, ref = (doc.getObject(n) for n in names)
unmoved = list(ref.Deviation)
ref.ViewObject.Visibility = False      # its map lies on the same face
RESULTS["before"] = [list(comp.State), comp.AlignMatrix, max(abs(a - b) for a, b in
                                                             zip(comp.Deviation, unmoved))]
Gui.Selection.clearSelection()
RESULTS["active_two_compensations"] = active(align_panel.AlignMeasurements)
Gui.Selection.addSelection(doc.Name, comp.Name)
RESULTS["active_selected"] = active(align_panel.AlignMeasurements)
Gui.runCommand("SurfComp_AlignMeasurements")
Gui.updateGui()
panel = align_panel.AlignPanel.instance
RESULTS["opened"] = [panel is not None, panel.method.currentText(), panel.transform.text(),
                     panel.result.toPlainText(), panel.rps.isEnabled(),
                     panel.dof["z"].isEnabled()]


def type_text(widget, text):
    """Select the field's text (Ctrl+A) and type ``text`` key by key."""
    widget.setFocus()
    key(widget, QtCore.Qt.Key_A, "a", QtCore.Qt.ControlModifier)
    names = {",": "Key_Comma", ";": "Key_Semicolon"}
    for ch in text:
        key(widget, getattr(QtCore.Qt, names.get(ch, "Key_" + ch.upper())), ch)


def click_box(box):
    """A real left click on a check box's indicator (its left end, where users click)."""
    Gui.updateGui()
    pos = QtCore.QPointF(8.0, box.height() / 2.0)
    glob = QtCore.QPointF(box.mapToGlobal(pos.toPoint()))
    for kind, buttons in ((QtCore.QEvent.MouseButtonPress, QtCore.Qt.LeftButton),
                          (QtCore.QEvent.MouseButtonRelease, QtCore.Qt.NoButton)):
        QtGui.QApplication.sendEvent(box, QtGui.QMouseEvent(
            kind, pos, glob, QtCore.Qt.LeftButton, buttons, QtCore.Qt.NoModifier))
    Gui.updateGui()


# 1. the transform file (the known re-clamping), method none: the deviations come back
FILES.append(os.path.join(TMP, "t.json"))
click(panel.transform_button)
RESULTS["transform_text"] = panel.transform.text()
click(panel.apply_button)
RESULTS["transform"] = [panel.result.toPlainText(), list(meas.AlignTransform),
                        list(comp.AlignMatrix),
                        max(abs(a - b) for a, b in zip(comp.Deviation, unmoved))]
# 2. a best fit on the face, z rx ry only: the method chosen with the keyboard, the boxes
# unticked with the mouse
panel.method.setFocus()
key(panel.method, QtCore.Qt.Key_Down)
for name in ("x", "y", "rz"):
    click_box(panel.dof[name])
click(panel.apply_button)
RESULTS["bestfit"] = [panel.method.currentText(), panel.result.toPlainText(), meas.AlignMethod,
                      meas.AlignDof, list(comp.Alignment), list(comp.Warnings)]
view = Gui.ActiveDocument.ActiveView
settle(view)
view.viewIsometric()
view.fitAll()
settle(view)
RESULTS["view_shot"] = shot(view, "align_view")
shot_path = os.path.join(TMP, "align_panel.png")
mw.grab().save(shot_path)
RESULTS["shot"] = shot_path
# the panel fits the task view: nothing to scroll sideways to
area = panel.form.parentWidget()
while area is not None and not isinstance(area, QtGui.QScrollArea):
    area = area.parentWidget()
RESULTS["fits"] = [panel.form.width(), area.viewport().width(),
                   area.horizontalScrollBar().isVisible()]
# 3. 3-2-1 on three collinear points: refused in the panel, nothing written
key(panel.method, QtCore.Qt.Key_Down)
type_text(panel.rps, "1,2,3;4,5;6")
click(panel.apply_button)
RESULTS["bad"] = [panel.method.currentText(), panel.result.toPlainText(), meas.AlignMethod,
                  meas.AlignRps, panel.accept(), align_panel.AlignPanel.instance is panel,
                  list(comp.State)]
# the ids from a 3-2-1 file instead
FILES.append(os.path.join(TMP, "rps.json"))
click(panel.rps_button)
RESULTS["rps_file"] = panel.rps.text()
# reference faces from the selection in the 3D view
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, "Nominal", "Face1")
click(panel.faces_button)
RESULTS["faces"] = panel.faces.text()
# 4. back to the best fit; OK keeps it as one undo step
key(panel.method, QtCore.Qt.Key_Up)
RESULTS["ok"] = [panel.method.currentText(), panel.accept(),
                 align_panel.AlignPanel.instance is None, meas.AlignMethod, meas.AlignFaces,
                 meas.AlignDof, len(comp.AlignMatrix), list(comp.State)]
doc.undo()
doc.recompute()
Gui.updateGui()
RESULTS["after_undo"] = [meas.AlignMethod, list(meas.AlignTransform), meas.AlignDof,
                         list(comp.AlignMatrix)]
# 5. Cancel after an Apply puts the document back
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, comp.Name)
Gui.runCommand("SurfComp_AlignMeasurements")
Gui.updateGui()
second = align_panel.AlignPanel.instance
second.method.setFocus()
key(second.method, QtCore.Qt.Key_Down)
click(second.apply_button)
applied = [meas.AlignMethod, len(comp.AlignMatrix)]
RESULTS["cancel"] = applied + [second.reject(), align_panel.AlignPanel.instance is None,
                               meas.AlignMethod, list(comp.AlignMatrix)]
RESULTS["report_view_end"] = report_view_text()
RESULTS["errors_at_end"] = ERRORS[:]
