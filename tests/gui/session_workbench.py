# Body of the GUI session of test_workbench.py: runs inside `freecad` (see harness.py; it
# provides RESULTS, FreeCAD, FreeCADGui, QtGui, QtCore). Every command runs through
# FreeCAD's command mechanism (Gui.runCommand) on the bundled example; dialogs are
# replaced by recorders (surfcomp.gui.dialogs is the one place commands ask the user).
import time

import numpy as np

Gui = FreeCADGui
ROOT = os.environ["SURFCOMP_ROOT"]
TMP = os.environ["SURFCOMP_TMP"]
NOMINAL = os.path.join(ROOT, "examples", "nominal.step")
MEAS = os.path.join(ROOT, "examples", "measurements.csv")

import surfcomp
from surfcomp.core import colormap
from surfcomp.gui import commands, dialogs, mapscene, panels, prefs

RESULTS["surfcomp_file"] = surfcomp.__file__
RESULTS["workbenches"] = sorted(Gui.listWorkbenches())
Gui.activateWorkbench("SurfCompWorkbench")
RESULTS["active_workbench"] = Gui.activeWorkbench().name()
RESULTS["commands"] = sorted(c for c in Gui.listCommands() if c.startswith("SurfComp_"))
mw = Gui.getMainWindow()
RESULTS["toolbars"] = [t.objectName() for t in mw.findChildren(QtGui.QToolBar)]
tb = [t for t in mw.findChildren(QtGui.QToolBar) if t.objectName() == "SurfComp"]
RESULTS["toolbar_actions"] = [a.text() for a in tb[0].actions()] if tb else []
RESULTS["toolbar_icons_null"] = [a.text() for a in tb[0].actions()
                                 if not a.isSeparator() and a.icon().isNull()] if tb else []
RESULTS["resources"] = {c.ID: c().GetResources() for c in commands.COMMANDS}

# -- dialog recorders --------------------------------------------------------------------
ERRORS, PREVIEWS, DIALOGS = [], [], []
FILES = []
dialogs.show_error = lambda title, message: ERRORS.append([title, message])
dialogs.ask_open_file = lambda title, filters: FILES.pop(0)
dialogs.ask_float = lambda *a, **k: 0.1
dialogs.ask_save_file = lambda title, filters, default="": os.path.join(TMP, "report.html")
def _run_dialog(dlg):
    DIALOGS.append(dlg)
    if isinstance(dlg, panels.PreviewDialog):
        PREVIEWS.append(dlg.text.toPlainText())
    return True
dialogs.run_dialog = _run_dialog

def active(cls):
    return bool(cls().IsActive())

doc = FreeCAD.newDocument("Session")
RESULTS["active_empty_doc"] = {c.ID: active(c) for c in commands.COMMANDS}

# -- load nominal and measurements through the commands ----------------------------------
FILES.append(NOMINAL)
Gui.runCommand("SurfComp_LoadNominal")
nominal = doc.getObject("Nominal")
RESULTS["nominal_faces"] = len(nominal.Shape.Faces) if nominal else 0
FILES.append(MEAS)
Gui.runCommand("SurfComp_ImportMeasurements")
meas = [o for o in doc.Objects if o.Name.startswith("Measurement")]
RESULTS["measurement_points"] = meas[0].PointCount if meas else 0
RESULTS["measurement_vp"] = type(meas[0].ViewObject.Proxy).__name__ if meas else None
RESULTS["preview"] = PREVIEWS[:]
meas = meas[0]

# with a face selected, Load nominal checks it and adds nothing
Gui.Selection.addSelection(doc.Name, nominal.Name, "Face1")
n_before = len(doc.Objects)
Gui.runCommand("SurfComp_LoadNominal")
Gui.updateGui()
RESULTS["load_selected_face"] = [len(doc.Objects) - n_before, report_view_text()]
Gui.Selection.clearSelection()

# a file that does not parse: the CLI's message in a dialog, nothing added
bad = os.path.join(TMP, "bad.csv")
with open(bad, "w") as f:
    f.write("id,x_nom,y_nom,z_nom,i,j,k,dev\nP1,1,2,3,0,0,1,0.01\nP2,1,2,x,0,0,1,0.02\n")
from surfcomp.errors import SurfcompError
from surfcomp.io.readers import read_any

try:
    read_any(bad)
    RESULTS["cli_message"] = None
except SurfcompError as exc:
    RESULTS["cli_message"] = str(exc)
n_before = len(doc.Objects)
FILES.append(bad)
Gui.runCommand("SurfComp_ImportMeasurements")
RESULTS["bad_import_errors"] = ERRORS[:]
RESULTS["bad_import_objects_added"] = len(doc.Objects) - n_before
del ERRORS[:]

# -- deviation map of the selected face + measurement -------------------------------------
Gui.Selection.clearSelection()
RESULTS["map_active_without_selection"] = active(commands.DeviationMap)
Gui.Selection.addSelection(doc.Name, nominal.Name, "Face1")
Gui.Selection.addSelection(doc.Name, meas.Name)
RESULTS["map_active_with_selection"] = active(commands.DeviationMap)
t0 = time.perf_counter()
Gui.runCommand("SurfComp_DeviationMap")
Gui.updateGui()
RESULTS["map_seconds"] = time.perf_counter() - t0
comps = [o for o in doc.Objects if o.Name.startswith("Compensation")]
RESULTS["errors_after_map"] = ERRORS[:]
comp = comps[0]
vobj = comp.ViewObject
RESULTS["comp_state"] = list(comp.State)
RESULTS["display_mode"] = vobj.DisplayMode
RESULTS["undo_names"] = doc.UndoNames
scene = vobj.Proxy.scene
RESULTS["range_auto"] = list(scene.range)
RESULTS["view_range_props"] = [vobj.RangeMin.Value, vobj.RangeMax.Value]
dev = np.array(comp.Deviation)
RESULTS["dev_minmax"] = [float(np.nanmin(dev)), float(np.nanmax(dev))]
RESULTS["mesh_vertices"] = scene.surface_coords.point.getNum()
RESULTS["markers"] = scene.marker_coords.point.getNum()
RESULTS["labels"] = [scene.labels.getChild(i).getChild(3).string.getValues()[0]
                     for i in range(scene.labels.getNumChildren())]

# -- screenshots -------------------------------------------------------------------------
RESULTS["hidden_by_map"] = [nominal.Visibility, meas.ViewObject.Visibility]
Gui.Selection.clearSelection()
view = Gui.ActiveDocument.ActiveView
view.viewTop()
view.fitAll()
Gui.updateGui()
W, H = view.getSize()
RESULTS["image_size"] = [W, H]
nodes = np.array(comp.NominalPoints).reshape(-1, 3)

def project(points):
    out = []
    for p in points:
        x, y = view.getPointOnScreen(FreeCAD.Vector(*map(float, p)))
        out.append([int(x), int(y)])
    return out

def shot(name):
    Gui.updateGui()
    path = os.path.join(TMP, name + ".png")
    view.saveImage(path, W, H, "White")
    return path

i_max, i_min = colormap.extremes(dev)
RESULTS["extreme_nodes"] = [i_max, i_min]
RESULTS["extreme_pixels"] = project(nodes[[i_max, i_min]])
RESULTS["shot_deviation"] = shot("map_deviation")

# manual range: the largest deviation is no longer at the end of the scale
vobj.AutoRange = False
vobj.RangeMin = -0.1
vobj.RangeMax = 0.1
RESULTS["range_manual"] = list(scene.range)
RESULTS["shot_manual"] = shot("map_manual")
vobj.AutoRange = True

# tolerance band mode
vobj.ToleranceBand = True
vobj.ToleranceLower = -0.01
vobj.ToleranceUpper = 0.01
rng = np.random.default_rng(3)
fin = np.isfinite(dev)
# nodes well inside each class (the surface between nodes is interpolated)
pick = {}
for name, mask in (("inside", np.abs(dev) < 0.006), ("above", dev > 0.016),
                   ("below", dev < -0.016)):
    idx = np.flatnonzero(mask & fin)
    pick[name] = [int(i) for i in rng.choice(idx, size=min(5, idx.size), replace=False)]
RESULTS["tolerance_nodes"] = pick
RESULTS["tolerance_pixels"] = {k: project(nodes[v]) for k, v in pick.items()}
RESULTS["shot_tolerance"] = shot("map_tolerance")
vobj.ToleranceBand = False

# the other maps: drawn with their own ranges, no recompute
recomputes = comp.Document.RecomputesFrozen if hasattr(comp.Document, "RecomputesFrozen") else None
maps = {}
for q in ("determined", "random", "correction", "residual"):
    vobj.Map = q
    vals = np.array(comp.Random if q == "random" else
                    comp.Determined if q == "determined" else
                    comp.Correction if q == "correction" else
                    np.array(comp.Deviation) - np.array(comp.Increment))
    maps[q] = {"range": list(scene.range), "title": vobj.Proxy._data and q,
               "nodes_absmax": float(np.nanmax(np.abs(vals)))}
RESULTS["maps"] = maps
vobj.Map = "random"
RESULTS["shot_random"] = shot("map_random")
vobj.Map = "deviation"
RESULTS["comp_touched_after_restyle"] = "Touched" in comp.State

# -- filter task panel ---------------------------------------------------------------------
Gui.Selection.addSelection(doc.Name, comp.Name)
RESULTS["filter_active"] = active(commands.Filter)
det_before = list(comp.Determined)
Gui.runCommand("SurfComp_Filter")
Gui.updateGui()
dlg = Gui.Control.activeDialog()
RESULTS["filter_dialog_open"] = bool(dlg)
panel = panels.FilterPanel.instance
panel.mask.setValue(9)
panel.update()
RESULTS["filter_live_mask"] = comp.MaskSize
RESULTS["filter_live_changed"] = bool(np.nanmax(np.abs(np.array(comp.Determined) - det_before))
                                      > 1e-6)
panel.mask.setValue(4)          # even: not a valid mask
panel.update()
RESULTS["filter_invalid"] = [panel.status.text(), panel.accept()]
panel.reject()
RESULTS["filter_after_reject"] = [comp.MaskSize,
                                  float(np.nanmax(np.abs(np.array(comp.Determined) - det_before)))]
Gui.runCommand("SurfComp_Filter")
panel = panels.FilterPanel.instance
panel.mask.setValue(3)
panel.show.setCurrentIndex(1)
panel.accept()
RESULTS["filter_after_accept"] = [comp.MaskSize, vobj.Map, Gui.Control.activeDialog()]
RESULTS["undo_after_filter"] = doc.UndoNames

# -- report ---------------------------------------------------------------------------------
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, comp.Name)
del DIALOGS[:]
Gui.runCommand("SurfComp_Report")
rep = DIALOGS[0] if DIALOGS else None
if rep is not None:
    rep.copy()
    RESULTS["report"] = {"rows": rep.table.rowCount(), "cols": rep.table.columnCount(),
                         "headers": [rep.table.horizontalHeaderItem(j).text()
                                     for j in range(rep.table.columnCount())],
                         "max_neg": rep.table.item(1, 0).text(),
                         "clipboard": QtGui.QApplication.clipboard().text()}
    saved = rep.save_html()
    RESULTS["report_html"] = {"path": saved, "errors": list(ERRORS),
                              "text": open(saved, encoding="utf-8").read() if saved else ""}
RESULTS["statistics"] = comp.Statistics

# -- mirror (stock) ------------------------------------------------------------------------
Gui.runCommand("SurfComp_Mirror")
RESULTS["mirror"] = [comp.Method, comp.Stock.Value, vobj.Map, list(comp.State)]
doc.undo()
doc.recompute()
RESULTS["after_mirror_undo"] = [comp.Method, comp.Stock.Value]

# -- build corrected face --------------------------------------------------------------------
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, comp.Name)
Gui.runCommand("SurfComp_BuildFace")
cf = [o for o in doc.Objects if o.Name.startswith("CorrectedFace")]
RESULTS["corrected_face"] = [len(cf), cf[0].Shape.Area if cf else 0, comp.Shape.Area]

# -- replace in document / restore -------------------------------------------------------------
user = doc.addObject("Part::Mirroring", "UserOfNominal")
user.Source = nominal
doc.recompute()
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, comp.Name)
RESULTS["replace_active"] = [active(commands.ReplaceInDocument), active(commands.RestoreNominal)]
Gui.runCommand("SurfComp_ReplaceInDocument")
RESULTS["after_replace"] = [user.Source.Name, active(commands.ReplaceInDocument),
                            active(commands.RestoreNominal)]
Gui.runCommand("SurfComp_RestoreNominal")
RESULTS["after_restore"] = [user.Source.Name]

# -- a measurement that does not fit the face: dialog, document unchanged ----------------------
RESULTS["report_view_before_far"] = report_view_text()
far = os.path.join(TMP, "far.csv")
with open(MEAS) as f:
    rows = f.read().splitlines()
with open(far, "w") as f:
    for line in rows:
        parts = line.split(",")
        if parts[0].startswith("P"):
            parts[3] = "%.6f" % (float(parts[3]) + 5.0)
        f.write(",".join(parts) + "\n")
FILES.append(far)
Gui.runCommand("SurfComp_ImportMeasurements")
far_meas = doc.Objects[-1]
names_before = sorted(o.Name for o in doc.Objects)
del ERRORS[:]
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, nominal.Name, "Face1")
Gui.Selection.addSelection(doc.Name, far_meas.Name)
Gui.runCommand("SurfComp_DeviationMap")
RESULTS["far_errors"] = ERRORS[:]
RESULTS["far_objects_unchanged"] = sorted(o.Name for o in doc.Objects) == names_before

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
prefs.set_value(prefs.DISPLAY_UNIT, "um")
prefs.set_value(prefs.TOLERANCE_BAND, True)
prefs.set_value(prefs.METHOD, "raw")
# a new map takes its style from the preferences
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, nominal.Name, "Face1")
Gui.Selection.addSelection(doc.Name, meas.Name)
Gui.runCommand("SurfComp_DeviationMap")
c2 = [o for o in doc.Objects if o.Name.startswith("Compensation")][-1]
RESULTS["pref_new_map"] = [c2.Name, c2.Method, c2.ViewObject.Scheme, c2.ViewObject.LegendUnit,
                           c2.ViewObject.ToleranceBand]
RESULTS["errors_at_end"] = ERRORS[:]

# -- save and reopen: view providers come back ------------------------------------------------
path = os.path.join(TMP, "session.FCStd")
comp_name = comp.Name
doc.saveAs(path)
FreeCAD.closeDocument(doc.Name)
doc = FreeCAD.openDocument(path)
Gui.updateGui()
c = doc.getObject(comp_name)
RESULTS["reopened"] = [type(c.ViewObject.Proxy).__name__, c.ViewObject.DisplayMode,
                       c.ViewObject.Proxy.scene.surface_coords.point.getNum()]
# -- a document made headless (no view providers saved) gets its maps when opened ----------
hdoc = FreeCAD.openDocument(os.path.join(TMP, "headless.FCStd"))
Gui.updateGui()
hc = [o for o in hdoc.Objects if o.Name.startswith("Compensation")][0]
RESULTS["headless_opened"] = [type(hc.ViewObject.Proxy).__name__, hc.ViewObject.DisplayMode,
                              hc.ViewObject.Proxy.scene.surface_coords.point.getNum()]
RESULTS["legend_layout"] = {"bar_x": list(mapscene.BAR_X), "bar_y": list(mapscene.BAR_Y),
                            "label_x": mapscene.LABEL_X}
