# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_shop_document.py, with and without OpenCamLib. Runs after OPEN (the
# test puts it first): FreeCAD opened the 0.20 shop document before anything of surfcomp but
# its Init.py ran. Then, as a user: select Round2, Restore nominal, select it again, Replace
# in document; the operation's feed moves and the summaries after each step; then, its tool
# number 0, Restore nominal again (the operation fails without an error state).
import sys

from tests.toolpath_checks import feed_moves, shop_surfaces

doc = SHOP
op = doc.getObject("Surface")
r2 = doc.getObject("Round2")
RESULTS["saved"] = feed_moves(op)


def run_on_round2(command):
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(doc.Name, r2.Name)
    del INFOS[:], ERRORS[:]
    Gui.runCommand(command)
    Gui.updateGui()
    return [INFOS[:], ERRORS[:]]


RESULTS["restore"] = run_on_round2("SurfComp_RestoreNominal")
RESULTS["restored"] = feed_moves(op)
RESULTS["after_restore"] = [doc.getObject("Clone").Objects[0].Name, r2.ReplacedLinks]
RESULTS["replace"] = run_on_round2("SurfComp_ReplaceInDocument")
RESULTS["replaced"] = feed_moves(op)
RESULTS["after_replace"] = [doc.getObject("Clone").Objects[0].Name, bool(r2.ReplacedLinks)]
RESULTS["surfaces"] = shop_surfaces(doc)
RESULTS["invalid"] = [o.Name for o in doc.Objects if "Invalid" in o.State or "Error" in o.State]
RESULTS["job_module"] = getattr(sys.modules.get("PathScripts.PathJob"), "__name__", None)
if op.Proxy is not None:
    # a tool controller without a tool number: FreeCAD's operation logs "No Tool Controller
    # is selected" and returns, keeping the path it had, in an object marked recomputed
    op.ToolController.ToolNumber = 0
    RESULTS["no_tool"] = run_on_round2("SurfComp_RestoreNominal")
    RESULTS["no_tool_kept"] = feed_moves(op) == RESULTS["replaced"]
RESULTS["report_view_end"] = report_view_text()
