# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_replace.py: Build corrected face (hidden, named by method and round),
# Replace in document with a Path job (summary, the model clone renamed, Esc cancels),
# Replace refused without users, Restore.
doc = FreeCAD.newDocument("Replace")
nominal, meas = load_example(doc)
comp = make_map(doc, nominal, meas)

# -- build corrected face --------------------------------------------------------------------
Gui.Selection.addSelection(doc.Name, comp.Name)
Gui.runCommand("SurfComp_BuildFace")
Gui.updateGui()
cf = [o for o in doc.Objects if o.Name.startswith("CorrectedFace")]
RESULTS["corrected_face"] = [len(cf), cf[0].Shape.Area if cf else 0, comp.Shape.Area,
                             cf[0].Label if cf else "", cf[0].ViewObject.Visibility if cf else
                             None, comp.ViewObject.Visibility]
view = view_top()
RESULTS["shot_after_build"] = shot(view, "after_build")
nodes = np.array(comp.Nodes).reshape(-1, 3)
dev = np.array(comp.Deviation)
i_max, _ = colormap.extremes(dev)
RESULTS["extreme_pixel"] = project(view, nodes[[i_max]])[0]

# -- replace with nothing using the nominal: refused with a message ------------------------
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, comp.Name)
del ERRORS[:], INFOS[:]
Gui.runCommand("SurfComp_ReplaceInDocument")
RESULTS["replace_without_users"] = [ERRORS[:], INFOS[:], comp.ReplacedLinks]
del ERRORS[:]

# -- a Path job on the nominal: its model clone is labelled after the nominal ----------------
from surfcomp.app import cam

cam.setup_workbench(require_ocl=False)
job = cam.create_job(doc, [nominal])
doc.recompute()
clone = job.Model.Group[0]
RESULTS["clone_before"] = [clone.Name, clone.Label]
user = doc.addObject("Part::Mirroring", "UserOfNominal")
user.Source = nominal
doc.recompute()
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, comp.Name)
RESULTS["replace_active"] = [active(commands.ReplaceInDocument), active(commands.RestoreNominal)]

# Esc while the users recompute: the step is undone (FreeCAD's progress indicator raises)
from surfcomp.app import progress as app_progress

real = app_progress.FreeCADProgress.__call__


def pressed_esc(self, fraction, message=""):
    from PySide import QtCore, QtGui

    if fraction > 0:
        ev = QtGui.QKeyEvent(QtCore.QEvent.KeyPress, QtCore.Qt.Key_Escape, QtCore.Qt.NoModifier)
        QtGui.QApplication.postEvent(mw, ev)
        QtGui.QApplication.processEvents()
    return real(self, fraction, message)


ASKED = []


def answer_yes():
    """FreeCAD asks whether to abort: answer Yes (a real user's second key press)."""
    box = QtGui.QApplication.activeModalWidget()
    if isinstance(box, QtGui.QMessageBox):
        ASKED.append(box.text())
        yes = box.button(QtGui.QMessageBox.Yes)
        (yes or box.defaultButton() or box.buttons()[0]).click()


answer = QtCore.QTimer()
answer.setInterval(50)
answer.timeout.connect(answer_yes)
answer.start()
app_progress.FreeCADProgress.__call__ = pressed_esc
del INFOS[:]
Gui.runCommand("SurfComp_ReplaceInDocument")
app_progress.FreeCADProgress.__call__ = real
answer.stop()
RESULTS["asked"] = ASKED[:]
RESULTS["after_esc"] = [INFOS[:], clone.Objects[0].Name if hasattr(clone, "Objects") else None,
                        user.Source.Name, comp.ReplacedLinks, clone.Label]

del INFOS[:]
t0 = time.perf_counter()
Gui.runCommand("SurfComp_ReplaceInDocument")
RESULTS["replace_seconds"] = time.perf_counter() - t0
RESULTS["after_replace"] = [user.Source.Name, active(commands.ReplaceInDocument),
                            active(commands.RestoreNominal), INFOS[:], clone.Label,
                            [o.Name for o in getattr(clone, "Objects", [])]]
del INFOS[:]
Gui.runCommand("SurfComp_RestoreNominal")
RESULTS["after_restore"] = [user.Source.Name, clone.Label, INFOS[:]]
RESULTS["errors_at_end"] = ERRORS[:]
RESULTS["report_view_end"] = report_view_text()
