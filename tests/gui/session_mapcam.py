# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_mapcam.py: maps in a CAM document (the shop document saved by FreeCAD
# 0.20: a Job with a stock box around the block, its model copy of the replacing round),
# a click on the map, the map in front of the model copy and the nominal (after Replace and
# after Restore), the point markers whole; a trimmed face with a hole (not painted, the
# points inside it listed in the legend panel); a disc-trimmed face refused; labels of built
# faces; the unit of documents from disk; the Filter task panel beside the legend panel.
import shutil

import Part

from surfcomp.app import features
from surfcomp.gui import cover, legend


def node_pixels(view, comp, nodes_idx, lift=0.0):
    """Projected pixels of the compensation's nodes (document coordinates)."""
    nodes = np.array(comp.Nodes).reshape(-1, 3)
    pl = np.array(comp.Placement.toMatrix().A).reshape(4, 4)
    pts = nodes[nodes_idx] @ pl[:3, :3].T + pl[:3, 3]
    return project(view, pts)


def interior_nodes(comp, count=40, seed=1):
    """Nodes away from the face's border, with finite values (the grid's middle)."""
    n, m = int(comp.GridRows), int(comp.GridCols)
    ii, jj = np.meshgrid(np.arange(2, n - 2), np.arange(2, m - 2), indexing="ij")
    idx = (ii * m + jj).ravel()
    idx = idx[np.isfinite(np.array(comp.Deviation)[idx])]
    return [int(k) for k in np.random.default_rng(seed).choice(idx, count, replace=False)]


def map_state(view, comp, name, idx):
    """Screenshot and the expected colours (the map's) at the nodes ``idx``."""
    scene = comp.ViewObject.Proxy.scene
    vals = np.array(comp.Deviation)[idx]
    want = colormap.map_colors(vals, *scene.range)
    return {"shot": shot(view, name), "pixels": node_pixels(view, comp, idx),
            "want": want.tolist()}


def iso(view):
    settle(view)
    view.viewIsometric()
    view.fitAll()
    settle(view)
    return view


# -- the shop document, opened from disk ---------------------------------------------------------
src = os.path.join(ROOT, "tests", "data", "documents", "shop-0.20.FCStd")
path = os.path.join(TMP, "shop.FCStd")
shutil.copyfile(src, path)
doc = FreeCAD.openDocument(path)
Gui.updateGui()
r1, r2 = doc.getObject("Round1"), doc.getObject("Round2")
stock, clone, block = doc.getObject("Stock"), doc.getObject("Clone"), doc.getObject("Block")
# saved by the command line: no unit stored, so the preference's default (um)
RESULTS["units_from_disk"] = [r1.ViewObject.Unit, r2.ViewObject.Unit]
RESULTS["clone_base"] = [o.Name for o in getattr(clone, "Objects", [])]
# with its CAM objects restored, the CAM GUI hides the Job's base model (Round2) as the
# document opens: the user shows the map (Space), which hides the stock around it
RESULTS["opened_visible"] = [r2.Visibility, r2.ViewObject.Visibility]
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, r2.Name)
Gui.runCommand("Std_ToggleVisibility")
Gui.Selection.clearSelection()
Gui.updateGui()
RESULTS["stock_hidden"] = [cover.hidden(doc), stock.Visibility,
                           stock.ViewObject.SwitchNode.whichChild.getValue()]
r1.ViewObject.Visibility = False
Gui.updateGui()
view = view_top()

# a real click on the map: it holds the selection alone (not the stock, not a mesh element)
idx = interior_nodes(r2)
px = node_pixels(view, r2, [idx[0]])[0]
Gui.Selection.clearSelection()
mouse("move", px)
mouse("press", px)
mouse("release", px)
for _ in range(4):
    Gui.updateGui()
    time.sleep(0.05)
RESULTS["click_selection"] = selection()
RESULTS["click_flags"] = list(r2.ViewObject.Flags)
# once the click is done the map lets go: a selection right after it (in the tree) stays
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, "BallEnd")
for _ in range(4):
    Gui.updateGui()
    time.sleep(0.05)
RESULTS["click_elsewhere"] = [name for name, _subs in selection()]
r2.ViewObject.Flags = []

# after Replace (the model copy is the round's corrected solid) and with the nominal shown
view = iso(view)
RESULTS["after_replace"] = map_state(view, r2, "cam_after_replace", idx)
block.ViewObject.Visibility = True
Gui.updateGui()
RESULTS["with_nominal"] = map_state(view, r2, "cam_with_nominal", idx)
# after Restore: the model copy is the nominal block again (exactly on the map's face)
clone.Objects = [block]
doc.recompute()
Gui.updateGui()
RESULTS["clone_after_restore"] = [o.Name for o in clone.Objects]
RESULTS["after_restore"] = map_state(view, r2, "cam_after_restore", idx)
# the markers whole: drawn black for the check, each 7 px square must show entirely (the
# tool paths, drawn over them, hidden)
for o in doc.Objects:
    if o.TypeId.startswith("Path::"):
        o.ViewObject.Visibility = False
scene = r2.ViewObject.Proxy.scene
k = scene.marker_colors.rgb.getNum()
scene.marker_colors.rgb.setValues(0, k, [[0.0, 0.0, 0.0]] * k)
markers = np.array([list(scene.marker_coords.point[i]) for i in range(k)])
pl = np.array(r2.Placement.toMatrix().A).reshape(4, 4)
pick = np.random.default_rng(2).choice(k, 30, replace=False)
RESULTS["markers"] = {"shot": shot(view, "cam_markers"),
                      "pixels": project(view, markers[pick] @ pl[:3, :3].T + pl[:3, 3]),
                      "size": int(scene.marker_style.pointSize.getValue())}
r2.ViewObject.Proxy.restyle()
# hiding the map draws the stock again; showing it hides it again
r2.ViewObject.Visibility = False
Gui.updateGui()
RESULTS["stock_after_map_hidden"] = [cover.hidden(doc),
                                     stock.ViewObject.SwitchNode.whichChild.getValue()]
r2.ViewObject.Visibility = True
Gui.updateGui()
RESULTS["stock_after_map_shown"] = cover.hidden(doc)
RESULTS["shop_modified"] = [o.Name for o in doc.Objects if "Touched" in o.State]
FreeCAD.closeDocument(doc.Name)

# -- a face with a hole: the hole not painted, its points listed --------------------------------
doc = FreeCAD.newDocument("Holed")
bs = Part.read(NOMINAL).Faces[0].Surface
face = Part.Face(bs)
hole = Part.Geom2d.Circle2d(FreeCAD.Base.Vector2d(0.5, 0.55), 0.1)
face.cutHoles([Part.Wire([hole.toShape(bs)])])
face.fix(1e-7, 1e-7, 1e-7)
holed = doc.addObject("Part::Feature", "Holed")
holed.Shape = face
doc.recompute()
FILES.append(MEAS)
Gui.runCommand("SurfComp_ImportMeasurements")
meas = [o for o in doc.Objects if o.Name.startswith("Measurement")][-1]
comp = make_map(doc, holed, meas)
comp.ViewObject.Points = False          # the hole's own measured points are no paint
view = view_top()
ring = {"hole": [], "face": []}
for r, key in ((0.06, "hole"), (0.17, "face")):
    for a in np.linspace(0.0, 2 * np.pi, 12, endpoint=False):
        p = bs.value(0.5 + r * np.cos(a), 0.55 + r * np.sin(a))
        ring[key].append([p.x, p.y, p.z])
RESULTS["hole"] = {"shot": shot(view, "hole"), "hole": project(view, ring["hole"]),
                   "face": project(view, ring["face"]),
                   "triangles": comp.ViewObject.Proxy.scene.faces.coordIndex.getNum() // 4,
                   "warnings": list(comp.Warnings)}
entry = legend_entries().get(comp.Label)
RESULTS["hole_legend"] = None if entry is None else {"texts": entry.texts(),
                                                     "outside": list(entry.outside)}
comp.ViewObject.Points = True

# -- built faces: round and build told apart -------------------------------------------------------
for _ in range(2):
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(doc.Name, comp.Name)
    Gui.runCommand("SurfComp_BuildFace")
    Gui.updateGui()
RESULTS["built_labels"] = [o.Label for o in doc.Objects if o.Name.startswith("CorrectedFace")]

# -- the Filter task panel and the legend panel side by side ---------------------------------------
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, comp.Name)
Gui.runCommand("SurfComp_Filter")
for _ in range(5):
    Gui.updateGui()
    time.sleep(0.05)


def global_rect(w):
    tl = w.mapToGlobal(QtCore.QPoint(0, 0))
    return [tl.x(), tl.y(), w.width(), w.height()]


tasks = [w for w in mw.findChildren(QtGui.QWidget)
         if w.metaObject().className() == "Gui::TaskView::TaskView" and w.isVisible()]
d = legend.dock(create=False)
RESULTS["task_and_legend"] = {
    "tasks": [global_rect(w) for w in tasks], "legend": global_rect(d.widget()),
    "legend_shown": [d.isVisible(), not d.isFloating(), mw.tabifiedDockWidgets(d) == [],
                     [e.name for e in d.widget().entries if e.isVisible()]],
    "entry": global_rect(d.widget().entries[0]) if d.widget().entries else None,
    "window": mw.grab().save(os.path.join(TMP, "window_task.png")),
    "dialog": Gui.Control.activeDialog()}
Gui.Control.closeDialog()
Gui.updateGui()

# -- a unit stored in a document is kept -----------------------------------------------------------
comp.ViewObject.Unit = "mm"
saved = os.path.join(TMP, "holed.FCStd")
doc.saveAs(saved)
name = comp.Name
FreeCAD.closeDocument(doc.Name)
doc = FreeCAD.openDocument(saved)
Gui.updateGui()
RESULTS["unit_stored_mm"] = doc.getObject(name).ViewObject.Unit
FreeCAD.closeDocument(doc.Name)

RESULTS["report_view_end"] = report_view_text()

# -- a disc-trimmed face smaller than the measured area: refused in GUI words ----------------------
doc = FreeCAD.newDocument("Disc")
disc = doc.addObject("Part::Feature", "Disc")
c = Part.Geom2d.Circle2d(FreeCAD.Base.Vector2d(0.5, 0.5), 0.35)
disc.Shape = Part.Face(bs, Part.Wire([c.toShape(bs)]))
doc.recompute()
# the import preview already refuses the file on the selected disc face (the points lie
# beyond its border), so nothing is added; made by script, the map refuses it
n_before = len(doc.Objects)
del PREVIEWS[:]
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, disc.Name, "Face1")
FILES.append(MEAS)
Gui.runCommand("SurfComp_ImportMeasurements")
RESULTS["disc_preview"] = [PREVIEWS[-1] if PREVIEWS else "", len(doc.Objects) - n_before]
meas = features.make_measurement(doc, MEAS)
del ERRORS[:]
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, disc.Name, "Face1")
Gui.Selection.addSelection(doc.Name, meas.Name)
Gui.runCommand("SurfComp_DeviationMap")
Gui.updateGui()
RESULTS["disc_errors"] = ERRORS[:]
RESULTS["disc_objects"] = sorted(o.Name for o in doc.Objects)
