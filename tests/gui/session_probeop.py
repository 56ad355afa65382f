# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_probe_op_gui.py: the shop document, a 5 x 4 plan on the block's top
# made with the Plan measurement panel, added to the Job with the toolbar button (a real
# click), the operation under the Job's Operations in the tree, posted by the Job's post.
import shutil

from surfcomp.app import probe_op
from surfcomp.gui import plan_panel, probe_op_cmd

src = os.path.join(ROOT, "tests", "data", "documents", "shop-0.20.FCStd")
path = os.path.join(TMP, "shop.FCStd")
shutil.copyfile(src, path)
doc = FreeCAD.openDocument(path)
Gui.activateWorkbench("SurfCompWorkbench")
Gui.updateGui()
job, block = doc.getObject("Job"), doc.getObject("Block")
RESULTS["active_without_plan"] = active(probe_op_cmd.AddProbeOperation)
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, block.Name, "Face2")
Gui.runCommand("SurfComp_PlanMeasurement")
Gui.updateGui()
panel = plan_panel.PlanPanel.instance
plan = panel.obj
type_value(panel.count_u, "5")
type_value(panel.count_v, "4")
click(panel.plan_button)
RESULTS["plan"] = [panel.result.toPlainText(), panel.accept(), plan.Kept]
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, plan.Name)
RESULTS["active_with_plan"] = active(probe_op_cmd.AddProbeOperation)
n0 = len(doc.Objects)
mw = Gui.getMainWindow()
buttons = []
for bar in mw.findChildren(QtGui.QToolBar):
    for action in bar.actions():
        if action.text().replace("&", "") == "Add probe plan to Job" and bar.isVisible():
            buttons.append(bar.widgetForAction(action))
RESULTS["buttons"] = len(buttons)
# FreeCAD refreshes the commands' enabled state on a timer: wait for the button as a user
# would see it enabled
import time

for _ in range(50):
    Gui.updateGui()
    if buttons[0].isEnabled():
        break
    time.sleep(0.1)
RESULTS["button_enabled"] = buttons[0].isEnabled()
click(buttons[0])
RESULTS["command_errors"] = ERRORS[:]
ops = [o for o in job.Operations.Group if probe_op.is_probe_operation(o)]
op = ops[0] if ops else None
RESULTS["op"] = [len(ops), op.Probes if op else None,
                 [c.Name for c in op.Path.Commands].count("G38.2") if op else None,
                 list(op.State) if op else None, len(doc.Objects) - n0,
                 int(op.ToolController.ToolNumber) if op else None]
# the tree: the operation's item under the Job's Operations folder
Gui.updateGui()


def tree_parents(label):
    """The labels of the tree items above each item labelled ``label``."""
    found = []
    for tree in mw.findChildren(QtGui.QTreeWidget):
        items = tree.findItems(label, QtCore.Qt.MatchExactly | QtCore.Qt.MatchRecursive)
        for item in items:
            chain, up = [], item.parent()
            while up is not None:
                chain.append(up.text(0))
                up = up.parent()
            found.append(chain)
    return found


# the Job's first operation (made headless, the document's Job draws its Operations folder
# where 0.20 puts it without the Job's view provider): the new one sits beside it
# (FreeCAD's tree adds a new object's item on a timer of its own: waited for, up to 5 s)
for _ in range(50):
    Gui.updateGui()
    if tree_parents(op.Label):
        break
    time.sleep(0.1)
RESULTS["tree"] = [tree_parents(op.Label), tree_parents(job.Operations.Group[0].Label),
                   job.Operations.Label]
text = probe_op.post_probe_job(job, "linuxcnc", "--no-show-editor --no-header")
RESULTS["posted_probes"] = sum(1 for ln in text.splitlines() if ln.startswith("G38.2"))
RESULTS["status"] = report_view_text()[-400:]
# the picture: the probe moves above the block, the stock hidden
others = [o for o in doc.Objects if o.Name.startswith(("Stock", "Dressup", "Surface"))]
for o in others + [plan]:
    if o.ViewObject:
        o.ViewObject.Visibility = False
RESULTS["op_view"] = [type(op.ViewObject.Proxy).__name__, op.ViewObject.DisplayMode]
RESULTS["bit_hidden"] = [o.Visibility for o in doc.Objects if o.Label.startswith("Probe ")]
Gui.Selection.clearSelection()
view = Gui.ActiveDocument.ActiveView
settle(view)
view.viewIsometric()
Gui.SendMsgToActiveView("ViewFit")
settle(view)       # FreeCAD 1.x animates the camera: a picture taken before it ends varies
view.saveImage(os.path.join(TMP, "probeop.png"), 800, 600, "White")
op.ViewObject.Visibility = False
Gui.updateGui()
view.saveImage(os.path.join(TMP, "probeop_hidden.png"), 800, 600, "White")
op.ViewObject.Visibility = True
mw.grab().save(os.path.join(TMP, "probeop_window.png"))
# one undo step removes the operation and its tool controller
doc.undo()
Gui.updateGui()
RESULTS["after_undo"] = [len(doc.Objects) - n0,
                         [o.Name for o in job.Operations.Group if probe_op.is_probe_operation(o)]]
# a document made headless (no view provider saved): opened here, its operation is drawn
import subprocess

made = os.path.join(TMP, "headless.FCStd")
maker = os.path.join(ROOT, "tests", "gui", "probeop_headless.py")
run = subprocess.run(["/usr/bin/python3", maker, ROOT, made], capture_output=True, text=True,
                     timeout=600, cwd=TMP)
RESULTS["headless_made"] = [run.returncode, run.stderr[-600:]]
other = FreeCAD.openDocument(made) if run.returncode == 0 else None
assert other is not None, run.stderr[-600:]
Gui.updateGui()
hop = other.getObject("ProbePlan")
RESULTS["headless_view"] = [type(hop.ViewObject.Proxy).__name__, hop.ViewObject.DisplayMode,
                            hop.Probes]
RESULTS["errors_at_end"] = ERRORS[:]
