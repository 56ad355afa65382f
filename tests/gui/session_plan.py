# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_plan_gui.py: the Plan measurement command on the example face, its
# task panel driven by real key and mouse events, OK, undo and Cancel.
from surfcomp.gui import plan_panel

doc = FreeCAD.newDocument("Plan")
FILES.append(NOMINAL)
Gui.runCommand("SurfComp_LoadNominal")
Gui.updateGui()
nominal = doc.getObject("Nominal")
RESULTS["active_no_face"] = active(commands.PlanMeasurement)
Gui.Selection.addSelection(doc.Name, nominal.Name, "Face1")
RESULTS["active_face"] = active(commands.PlanMeasurement)
n0 = len(doc.Objects)
Gui.runCommand("SurfComp_PlanMeasurement")
Gui.updateGui()
panel = plan_panel.PlanPanel.instance
obj = panel.obj
RESULTS["default"] = [panel.result.toPlainText(), obj.Layout, obj.Kept, obj.Placed,
                      len(obj.Shape.Vertexes), panel.points.isEnabled()]
# the face is drawn (its display mesh made) before the panel plans on it
RESULTS["safe_z"] = obj.SafeZ
# on the default grid, a max tilt of 15 degrees drops the steeper points: the panel names
# the option as its field, the Dropped property as the property; the panel as the user
# sees it
type_value(panel.tilt, "15")
click(panel.plan_button)
Gui.updateGui()
RESULTS["tilt"] = [panel.result.toPlainText(), list(obj.Dropped), obj.Kept, obj.Placed, obj.MaxTilt]
RESULTS["tilt_png"] = os.path.join(TMP, "plan_tilt.png")
panel.form.grab().save(RESULTS["tilt_png"])
# every line of the message shows without scrolling
RESULTS["tilt_scroll"] = panel.result.verticalScrollBar().maximum()
type_value(panel.tilt, "60")
click(panel.plan_button)
RESULTS["tilt_back"] = [obj.Kept, obj.MaxTilt]
# the adaptive layout with 60 points, chosen with the keyboard, planned with the button
panel.layout.setFocus()
key(panel.layout, QtCore.Qt.Key_Down)
key(panel.layout, QtCore.Qt.Key_Down)
type_value(panel.points, "60")
click(panel.plan_button)
RESULTS["adaptive"] = [panel.layout.currentText(), panel.result.toPlainText(), obj.Layout, obj.Kept,
                       obj.Placed, panel.points.isEnabled(), panel.count_u.isEnabled(),
                       [tuple(p) for p in obj.PlanPoints[:3]]]
vo = obj.ViewObject
RESULTS["view_object"] = [vo.TypeId, bool(vo.Visibility), vo.DisplayMode, vo.PointSize,
                          len(obj.Shape.Vertexes)]
view = Gui.ActiveDocument.ActiveView
settle(view)
view.viewIsometric()
view.fitAll()
settle(view)       # FreeCAD 1.x animates the camera: a picture taken before it ends is blank
RESULTS["shot"] = shot(view, "plan")
# a tip larger than the face's smallest concave radius: the message stays in the panel and
# OK keeps the panel open
type_value(panel.tip, "60")
click(panel.plan_button)
RESULTS["bad"] = [panel.result.toPlainText(), panel.accept(),
                  plan_panel.PlanPanel.instance is panel]
# the panel as the user sees it: the message below the field it names
Gui.updateGui()
RESULTS["bad_png"] = os.path.join(TMP, "plan_bad.png")
panel.form.grab().save(RESULTS["bad_png"])
RESULTS["bad_labels"] = [panel.form.layout().labelForField(w).text()
                         for w in (panel.layout, panel.points, panel.tip, panel.tilt)]
type_value(panel.tip, "1.5")
RESULTS["ok"] = [panel.accept(), plan_panel.PlanPanel.instance is None, obj.Kept,
                 obj.TipRadius, len(doc.Objects) - n0, list(obj.State)]
doc.undo()
Gui.updateGui()
RESULTS["after_undo"] = len(doc.Objects) - n0
# Cancel removes the object it made
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, nominal.Name, "Face1")
Gui.runCommand("SurfComp_PlanMeasurement")
Gui.updateGui()
second = plan_panel.PlanPanel.instance
name2 = second.obj.Name
RESULTS["cancel"] = [second.reject(), doc.getObject(name2) is None, len(doc.Objects) - n0]
# a plan made by a script (the macro's factory) draws its points too
from surfcomp.app.plan_feature import make_measurement_plan

scripted = make_measurement_plan(doc, nominal, "Face1", Layout="uniform", Points=25)
doc.recompute()
Gui.updateGui()
RESULTS["scripted"] = [scripted.Kept, scripted.ViewObject.DisplayMode,
                       scripted.ViewObject.PointSize]
RESULTS["report_view_end"] = report_view_text()
RESULTS["errors_at_end"] = ERRORS[:]
