# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_workbench.py: workbench, toolbar, preferences, Load nominal, the
# import preview and its plausibility checks, errors as dialogs, property names.
RESULTS["surfcomp_file"] = surfcomp.__file__
RESULTS["workbenches"] = sorted(Gui.listWorkbenches())
RESULTS["active_workbench"] = Gui.activeWorkbench().name()
# what loading the workbench (and the GUI modules the prologue imports) did not import
RESULTS["not_loaded"] = sorted(m for m in ("scipy.optimize",) if m not in sys.modules)
RESULTS["commands"] = sorted(c for c in Gui.listCommands() if c.startswith("SurfComp_"))
RESULTS["toolbars"] = [t.objectName() for t in mw.findChildren(QtGui.QToolBar)]
tb = [t for t in mw.findChildren(QtGui.QToolBar) if t.objectName() == "SurfComp"]
RESULTS["toolbar_actions"] = [a.text() for a in tb[0].actions()] if tb else []
RESULTS["toolbar_icons_null"] = [a.text() for a in tb[0].actions()
                                 if not a.isSeparator() and a.icon().isNull()] if tb else []
# the map drop-down: a tool button with a menu of the four maps
menus = [b.menu() for b in tb[0].findChildren(QtGui.QToolButton) if b.menu() is not None]
RESULTS["dropdown"] = [[a.text() for a in m.actions()] for m in menus]
RESULTS["resources"] = {c.ID: c().GetResources() for c in commands.COMMANDS + commands.GROUPS}

doc = FreeCAD.newDocument("Basics")
RESULTS["active_empty_doc"] = {c.ID: active(c) for c in commands.COMMANDS}

# -- load nominal: the view is fitted ------------------------------------------------------
view = Gui.ActiveDocument.ActiveView
view.viewTop()
FILES.append(NOMINAL)
Gui.runCommand("SurfComp_LoadNominal")
Gui.updateGui()
nominal = doc.getObject("Nominal")
RESULTS["nominal_faces"] = len(nominal.Shape.Faces) if nominal else 0
bb = nominal.Shape.BoundBox
corners = [(bb.XMin, bb.YMin, bb.ZMin), (bb.XMax, bb.YMax, bb.ZMax)]
W, H = view.getSize()
RESULTS["nominal_on_screen"] = [project(view, corners), [W, H]]

# a selected face: Load nominal says what it found, in a dialog and the status bar
Gui.Selection.addSelection(doc.Name, nominal.Name, "Face1")
n_before = len(doc.Objects)
Gui.runCommand("SurfComp_LoadNominal")
Gui.updateGui()
RESULTS["load_selected_face"] = [len(doc.Objects) - n_before, INFOS[-1] if INFOS else None,
                                 fcgui.status_text()]
Gui.Selection.clearSelection()

# -- import preview ----------------------------------------------------------------------
FILES.append(MEAS)
Gui.runCommand("SurfComp_ImportMeasurements")
meas = [o for o in doc.Objects if o.Name.startswith("Measurement")]
RESULTS["measurement_points"] = meas[0].PointCount if meas else 0
RESULTS["measurement_vp"] = type(meas[0].ViewObject.Proxy).__name__ if meas else None
RESULTS["preview"] = PREVIEWS[:]

# the um file read as mm (issue 13): deviations in um, no unit in the column name
um = os.path.join(TMP, "deviations_in_um.csv")
rows = deviations_in_um(um)
n_before = len(doc.Objects)
del PREVIEWS[:]
state = {}


def look(dlg):
    state["mm"] = [dlg.text.toPlainText(), dlg.status.toPlainText(), dlg.accepted_ok(),
                   dlg.units()]
    dlg.unit.setCurrentIndex(preview.UNIT_CHOICES.index("um"))   # the unit selector
    state["um"] = [dlg.text.toPlainText(), dlg.status.toPlainText(), dlg.accepted_ok(), dlg.units()]
    dlg.unit.setCurrentIndex(0)
    return True     # "OK" pressed while the errors are shown


ON_DIALOG.append(look)
FILES.append(um)
Gui.runCommand("SurfComp_ImportMeasurements")
RESULTS["um_file"] = state
RESULTS["um_file_objects_added"] = len(doc.Objects) - n_before


def accept_um(dlg):
    dlg.unit.setCurrentIndex(preview.UNIT_CHOICES.index("um"))
    return True


ON_DIALOG.append(accept_um)
FILES.append(um)
Gui.runCommand("SurfComp_ImportMeasurements")
m_um = doc.Objects[-1]
RESULTS["um_file_as_um"] = [m_um.Name, m_um.Units, float(max(map(abs, m_um.Deviation)))]

# deviations all far beyond the face's size tolerance (a 100 x 100 mm face: +-0.15 mm)
big = os.path.join(TMP, "big.csv")
with open(big, "w") as f:
    f.write("id,x_nom,y_nom,z_nom,i,j,k,dev\n")
    for k in range(9):
        f.write("P%d,%d,%d,0,0,0,1,%g\n" % (k, 10 * (k % 3), 50 * (k // 3), 20.0 + k))
from surfcomp.io.readers import read_any

RESULTS["big_preview"] = preview.preview_text(read_any(big), max_offset=50.0)

# a file that does not parse: the CLI's message in a dialog, nothing added
bad = os.path.join(TMP, "bad.csv")
with open(bad, "w") as f:
    f.write("id,x_nom,y_nom,z_nom,i,j,k,dev\nP1,1,2,3,0,0,1,0.01\nP2,1,2,x,0,0,1,0.02\n")
from surfcomp.errors import SurfcompError

try:
    read_any(bad)
    RESULTS["cli_message"] = None
except SurfcompError as exc:
    RESULTS["cli_message"] = str(exc)
n_before = len(doc.Objects)
del ERRORS[:]
FILES.append(bad)
Gui.runCommand("SurfComp_ImportMeasurements")
RESULTS["bad_import_errors"] = ERRORS[:]
RESULTS["bad_import_objects_added"] = len(doc.Objects) - n_before
del ERRORS[:]

# -- a measurement that does not fit the face: dialog, document unchanged ----------------------
far = os.path.join(TMP, "far.csv")
with open(far, "w") as f:
    for line in rows:
        parts = line.split(",")
        if parts[0].startswith("P"):
            parts[3] = "%.6f" % (float(parts[3]) + 5.0)
        f.write(",".join(parts) + "\n")
# the preview locates the points on the nominal face: refused there, nothing added
n_before = len(doc.Objects)
FILES.append(far)
Gui.runCommand("SurfComp_ImportMeasurements")
RESULTS["far_preview"] = [PREVIEWS[-1], len(doc.Objects) - n_before]
# made by script, the map refuses it before any object is made
from surfcomp.app import features

far_meas = features.make_measurement(doc, far)
names_before = sorted(o.Name for o in doc.Objects)
del ERRORS[:]
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, nominal.Name, "Face1")
Gui.Selection.addSelection(doc.Name, far_meas.Name)
Gui.runCommand("SurfComp_DeviationMap")
RESULTS["far_errors"] = ERRORS[:]
RESULTS["far_objects_unchanged"] = sorted(o.Name for o in doc.Objects) == names_before
del ERRORS[:]

# -- property names fit the default property view ---------------------------------------------
comp = make_map(doc, nominal, meas[0])
Gui.Selection.addSelection(doc.Name, comp.Name)
for _ in range(5):
    Gui.updateGui()
    time.sleep(0.05)
trees = [t for t in mw.findChildren(QtGui.QTreeView)
         if t.metaObject().className() == "Gui::PropertyEditor::PropertyEditor"]


def name_widths(tree):
    """[group, name, pixels the name needs, pixels the name column has] of every property
    (depth 2: under a group row, indented once; 8 px of cell padding)."""
    model, fm, out = tree.model(), tree.fontMetrics(), []
    for g in range(model.rowCount(QtCore.QModelIndex())):
        group = model.index(g, 0, QtCore.QModelIndex())
        for r in range(model.rowCount(group)):
            text = str(model.data(model.index(r, 0, group)))
            adv = fm.horizontalAdvance(text) if hasattr(fm, "horizontalAdvance") \
                else fm.width(text)
            out.append([str(model.data(group)), text, adv + tree.indentation() + 8,
                        tree.columnWidth(0)])
    return out


widths = []
for tree in trees:
    widths += name_widths(tree)
RESULTS["property_widths"] = widths
Gui.Selection.clearSelection()

# -- preferences page ---------------------------------------------------------------------------
ui = Gui.PySideUic.loadUi(os.path.join(ROOT, "resources", "ui", "preferences.ui"))
combos = {w.objectName(): [w.itemText(i) for i in range(w.count())]
          for w in ui.findChildren(QtGui.QComboBox)}
RESULTS["pref_combos"] = combos
RESULTS["pref_choices"] = {"method": list(prefs.METHOD_CHOICES), "edge": list(prefs.EDGE_CHOICES),
                           "fileUnits": list(prefs.FILE_UNIT_CHOICES),
                           "scheme": list(prefs.SCHEME_CHOICES),
                           "displayUnit": list(prefs.DISPLAY_UNIT_CHOICES)}
RESULTS["pref_defaults"] = [prefs.mask_size(), prefs.method(), prefs.edge(), prefs.scheme(),
                            prefs.tolerance_band(), list(prefs.tolerance()), prefs.display_unit()]
prefs.set_value(prefs.SCHEME, "blue-white-red")
RESULTS["pref_ui_display_unit"] = ui.findChild(QtGui.QComboBox, "displayUnit").currentText()
prefs.set_value(prefs.DISPLAY_UNIT, "mm")
prefs.set_value(prefs.TOLERANCE_BAND, True)
prefs.set_value(prefs.METHOD, "raw")
c2 = make_map(doc, nominal, meas[0])
RESULTS["pref_new_map"] = [c2.Name, c2.Method, c2.ViewObject.Scheme, c2.ViewObject.Unit,
                           c2.ViewObject.TolBand]
RESULTS["errors_at_end"] = ERRORS[:]
