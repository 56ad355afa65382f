# SPDX-License-Identifier: LGPL-2.1-or-later
"""The Add probe plan to Job command: the selected measurement plan (or the document's only
one) becomes a probe operation of the selected CAM Job (or the only one), so the Job's own
post-processor writes the probing program. One undo step; an operation that cannot be made
(a plan without points, a tool number taken) leaves the document as it was and says why.
No numerics: :func:`surfcomp.app.probe_op.add_probe_operation` makes the operation.
"""

import FreeCAD
import FreeCADGui
from PySide.QtCore import QT_TRANSLATE_NOOP

from ..app import cam_job
from ..app.plan_feature import PLAN_TYPE
from ..app.undo import UndoStep
from ..errors import InputError
from . import fcgui, probe_op_view  # noqa: F401 (registers the view provider hooks)
from .commands import Command, selected

translate = FreeCAD.Qt.translate
ID = "SurfComp_AddProbeOperation"
TEXTS = (QT_TRANSLATE_NOOP(ID, "Add probe plan to Job"),
         QT_TRANSLATE_NOOP(ID, "Add the selected measurement plan to the CAM Job as a probing "
                               "operation (G38.2 along the normals, PROBEOPEN log), posted "
                               "with the Job"))


def _is_plan(obj):
    return getattr(getattr(obj, "Proxy", None), "Type", None) == PLAN_TYPE


def _one(picked, every, what):
    """The selected one of ``every``, else the only one; InputError otherwise."""
    if len(picked) == 1:
        return picked[0]
    if len(every) == 1 and not picked:
        return every[0]
    raise InputError("select one %s (the document has %d)" % (what, len(every)))


def plan_and_job(doc):
    """``(plan, job)`` of the selection (module docstring)."""
    plans = [o for o in doc.Objects if _is_plan(o)]
    jobs = cam_job.jobs_of(doc)
    if not jobs:
        raise InputError("the document has no CAM Job: create one (CAM workbench, Job) on "
                         "the part first")
    return (_one(selected(_is_plan), plans, "measurement plan"),
            _one([j for j in selected(lambda o: True) if j in jobs], jobs, "CAM Job"))


class AddProbeOperation(Command):
    ID = ID
    MENU, TIP = TEXTS

    def active(self):
        doc = FreeCAD.ActiveDocument
        return any(_is_plan(o) for o in doc.Objects)

    def run(self):
        from ..app import probe_op

        doc = FreeCAD.ActiveDocument
        plan, job = plan_and_job(doc)
        before = {o.Name for o in doc.Objects}
        with UndoStep(doc, translate("SurfComp", "Add probe plan to Job")):
            FreeCADGui.addModule("surfcomp.app.probe_op")
            FreeCADGui.doCommand(
                "_op = surfcomp.app.probe_op.add_probe_operation(App.getDocument(%r).getObject("
                "%r), App.getDocument(%r).getObject(%r), check=False)"
                % (doc.Name, job.Name, doc.Name, plan.Name))
            op = next(o for o in self.new_objects(before) if probe_op.is_probe_operation(o))
            probe_op.check_recomputed(op)
        text = translate("SurfComp", "%s: %d probe moves added to %s (post the Job to write "
                                     "them)") % (op.Label, op.Probes, job.Label)
        FreeCAD.Console.PrintMessage(text + "\n")
        fcgui.show_status(text)
        return op
