# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_surface_dressup_gui.py: a document made headless
# (surfdressup_headless.py: the example nominal, a compensation, a Job with a finishing
# operation on a 6 mm ball end mill), opened here. The command refuses a wrong selection
# and a Job that already machines the compensation (Replace in document), each with a
# message and nothing changed; then, with the operation and the compensation selected, a
# real click on its toolbar button adds the dressup in the operation's place; one undo
# step removes it.
import subprocess

from surfcomp.gui import surface_dressup_cmd

made = os.path.join(TMP, "surfdressup.FCStd")
maker = os.path.join(ROOT, "tests", "gui", "surfdressup_headless.py")
run = subprocess.run(["/usr/bin/python3", maker, ROOT, made], capture_output=True, text=True,
                     timeout=600, cwd=TMP)
RESULTS["made"] = [run.returncode, run.stderr[-600:]]
assert run.returncode == 0, run.stderr[-2000:]
doc = FreeCAD.openDocument(made)
Gui.activateWorkbench("SurfCompWorkbench")
Gui.updateGui()
job, op = doc.getObject("Job"), doc.getObject("Finish")
comp = [o for o in doc.Objects if o.Name.startswith("Compensation")][0]
n0 = len(doc.Objects)
moves0 = [(c.Name, dict(c.Parameters)) for c in op.Path.Commands]


def attempt(names):
    """The command run on a selection of the objects ``names``: [errors, objects added]."""
    Gui.Selection.clearSelection()
    for name in names:
        Gui.Selection.addSelection(doc.Name, name)
    del ERRORS[:]
    before = len(doc.Objects)
    Gui.runCommand("SurfComp_AddSurfaceCorrection")
    Gui.updateGui()
    return [[m for _t, m in ERRORS], len(doc.Objects) - before]


RESULTS["active"] = active(surface_dressup_cmd.AddSurfaceCorrection)
RESULTS["nothing_selected"] = attempt([])
RESULTS["job_selected"] = attempt([job.Name])
RESULTS["model_selected"] = attempt(["Nominal", comp.Name])
# the Job machining the corrected face already: refused, then the nominal put back
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, comp.Name)
del ERRORS[:], INFOS[:]
Gui.runCommand("SurfComp_ReplaceInDocument")
Gui.updateGui()
RESULTS["replace_messages"] = [ERRORS[:], INFOS[:]]
RESULTS["replaced_model"] = [o.Name for c in job.Model.Group
                             for o in (getattr(c, "Objects", []) or [])]
RESULTS["after_replace"] = attempt([op.Name, comp.Name])
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, comp.Name)
Gui.runCommand("SurfComp_RestoreNominal")
Gui.updateGui()
RESULTS["restored_model"] = [o.Name for c in job.Model.Group
                             for o in (getattr(c, "Objects", []) or [])]
RESULTS["ops_before"] = [o.Name for o in job.Operations.Group]
del ERRORS[:]
# the real thing: operation and compensation selected, the toolbar button clicked
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, op.Name)
Gui.Selection.addSelection(doc.Name, comp.Name)
buttons = []
for bar in mw.findChildren(QtGui.QToolBar):
    for action in bar.actions():
        if action.text().replace("&", "") == "Add surface correction to operation" and \
                bar.isVisible():
            buttons.append(bar.widgetForAction(action))
RESULTS["buttons"] = len(buttons)
for _ in range(50):         # FreeCAD refreshes the enabled state on a timer
    Gui.updateGui()
    if buttons[0].isEnabled():
        break
    time.sleep(0.1)
RESULTS["button_enabled"] = buttons[0].isEnabled()
n1 = len(doc.Objects)
click(buttons[0])
Gui.updateGui()
RESULTS["command_errors"] = [m for _t, m in ERRORS]
made = [o for o in doc.Objects if o.Name.startswith("DressupSurfaceCorrection")]
d = made[0] if made else None
RESULTS["dressup"] = None if d is None else {
    "added": len(doc.Objects) - n1, "state": list(d.State), "base": d.Base.Name,
    "compensation": d.Compensation.Name, "radius": d.BallRadius.Value,
    "moved": d.MovedMoves, "max_move": d.MaxMove.Value, "contact": d.ContactPoints,
    "commands": len(d.Path.Commands), "ops": [o.Name for o in job.Operations.Group],
    "base_hidden": not op.ViewObject.Visibility,
    "op_kept": [(c.Name, dict(c.Parameters)) for c in op.Path.Commands] == moves0}
RESULTS["op_commands"] = len(moves0)
RESULTS["status"] = fcgui.status_text()
RESULTS["report_tail"] = report_view_text()[-600:]
# the picture: the moved path over the nominal, the stock and the tool bit hidden
for o in doc.Objects:
    if o.ViewObject and not (o is d or o.Name == "Nominal"):
        o.ViewObject.Visibility = False
for o in (d, doc.getObject("Nominal")):
    if o is not None and o.ViewObject:
        o.ViewObject.Visibility = True
# the tool tips ride the face: its outline only, so the path is not hidden in it
doc.getObject("Nominal").ViewObject.DisplayMode = "Wireframe"
view = Gui.ActiveDocument.ActiveView
Gui.Selection.clearSelection()
settle(view)
view.viewIsometric()
Gui.SendMsgToActiveView("ViewFit")
settle(view)       # FreeCAD 1.x animates the camera: a picture taken before it ends varies
view.saveImage(os.path.join(TMP, "surfdressup.png"), 800, 600, "White")
d.ViewObject.Visibility = False
Gui.updateGui()
view.saveImage(os.path.join(TMP, "surfdressup_hidden.png"), 800, 600, "White")
d.ViewObject.Visibility = True
mw.grab().save(os.path.join(TMP, "surfdressup_window.png"))
# one undo step: the dressup gone, the operation back in the Job
doc.undo()
Gui.updateGui()
RESULTS["after_undo"] = [len(doc.Objects) - n1, [o.Name for o in job.Operations.Group]]
RESULTS["errors_at_end"] = [m for _t, m in ERRORS]
