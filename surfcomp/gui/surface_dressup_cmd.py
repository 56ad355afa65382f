# SPDX-License-Identifier: LGPL-2.1-or-later
"""The Add surface correction to operation command: the selected finishing operation of a
CAM Job (ball end mill) gets the "Surface correction" dressup
(:mod:`surfcomp.app.dressup_surface`) following the selected compensation (or the
document's only one), so the Job posts the program moved by the correction without running
the 3D Surface operation again. One undo step; a selection it cannot use (no operation, an
operation outside a Job, no tool diameter, a Job already machining the corrected face) or a
dressup that does not compute leaves the document as it was and says why. No numerics.
"""

import FreeCAD
import FreeCADGui
from PySide.QtCore import QT_TRANSLATE_NOOP

from ..app import cam_job, features
from ..app.undo import UndoStep
from ..errors import ComputationError, InputError
from . import fcgui, surface_dressup_view
from .commands import Command, selected

translate = FreeCAD.Qt.translate
ID = "SurfComp_AddSurfaceCorrection"
TEXTS = (QT_TRANSLATE_NOOP(ID, "Add surface correction to operation"),
         QT_TRANSLATE_NOOP(ID, "Move the selected finishing operation (ball end mill) of a CAM "
                               "Job by the selected compensation: a Surface correction "
                               "dressup, posted with the Job without recomputing the "
                               "operation"))

SELECT = ("select the finishing operation of a CAM Job (made with a ball end mill) and the "
          "compensation to move it by")


def _operations(jobs):
    """The Job of every operation at the top of a Job's Operations (a dressup chain's top),
    by the operation's name."""
    return {o.Name: job for job in jobs for o in job.Operations.Group}


def operation_and_compensation(doc):
    """``(operation, its Job, compensation)`` of the selection (module docstring);
    InputError with what to select otherwise."""
    jobs = cam_job.jobs_of(doc)
    ops = _operations(jobs)
    paths = selected(lambda o: o.isDerivedFrom("Path::Feature") and o not in jobs)
    picked = [o for o in paths if o.Name in ops]
    if not paths:
        raise InputError(SELECT)
    if not picked:
        raise InputError("%s is not an operation of a CAM Job's Operations (%s; an operation "
                         "under a dressup: select the dressup)" % (paths[0].Label, SELECT))
    if len(picked) > 1:
        raise InputError("%d operations are selected (%s: one operation)"
                         % (len(picked), SELECT))
    comps = selected(features.is_compensation)
    every = [o for o in doc.Objects if features.is_compensation(o)]
    if len(comps) == 1:
        comp = comps[0]
    elif not comps and len(every) == 1:
        comp = every[0]
    else:
        raise InputError("select one compensation beside the operation (the document has %d, "
                         "%d selected)" % (len(every), len(comps)))
    return picked[0], ops[picked[0].Name], comp


def check(op, job, comp):
    """Refuse what the dressup cannot use, before anything is made (module docstring)."""
    if "Invalid" in comp.State or "Error" in comp.State or comp.Shape.isNull():
        raise ComputationError("%s has no corrected face (recompute it; %s)"
                               % (comp.Label, comp.getStatusString() or ", ".join(comp.State)))
    for clone in job.Model.Group:
        source = (list(getattr(clone, "Objects", []) or []) or [clone])[0]
        if features.is_compensation(source):
            raise InputError("the model of %s is already the compensation %s (Replace in "
                             "document): its program cuts the corrected face, and the surface "
                             "correction would move it a second time (Restore nominal first)"
                             % (job.Label, source.Label))
    tc = cam_job.tool_controller_of(op)
    diameter = getattr(getattr(tc, "Tool", None), "Diameter", None)
    if diameter is None or not float(getattr(diameter, "Value", diameter)) > 0:
        raise InputError("%s has no tool controller with a tool diameter (the surface "
                         "correction needs the ball end mill's radius)" % op.Label)


class AddSurfaceCorrection(Command):
    ID = ID
    MENU, TIP = TEXTS

    def active(self):
        doc = FreeCAD.ActiveDocument
        return bool(cam_job.jobs_of(doc)) and any(features.is_compensation(o)
                                                   for o in doc.Objects)

    def run(self):
        doc = FreeCAD.ActiveDocument
        op, job, comp = operation_and_compensation(doc)
        check(op, job, comp)
        before = {o.Name for o in doc.Objects}
        with UndoStep(doc, translate("SurfComp", "Add surface correction to operation")):
            FreeCADGui.addModule("surfcomp.app.dressup_surface")
            FreeCADGui.doCommand(
                "_d = surfcomp.app.dressup_surface.Create(App.getDocument(%r).getObject(%r), "
                "App.getDocument(%r).getObject(%r))" % (doc.Name, op.Name, doc.Name, comp.Name))
            FreeCADGui.doCommand("App.getDocument(%r).recompute()" % doc.Name)
            made = [o for o in self.new_objects(before)
                    if o.isDerivedFrom("Path::Feature") and hasattr(o, "MovedMoves")]
            dressup = made[0]
            surface_dressup_view.attach(dressup)
            if "Invalid" in dressup.State or "Error" in dressup.State:
                raise ComputationError("%s could not be computed: %s"
                                       % (dressup.Label, dressup.getStatusString()
                                          or ", ".join(dressup.State)))
        text = translate("SurfComp", "%s: %d moves of %s moved by up to %.2f um onto %s (%d "
                                     "cutter-location points on the face); post the Job to "
                                     "write the program") % (
            dressup.Label, dressup.MovedMoves, op.Label, 1000.0 * dressup.MaxMove.Value,
            comp.Label, dressup.ContactPoints)
        FreeCAD.Console.PrintMessage(text + "\n")
        fcgui.show_status(text)
        return dressup
