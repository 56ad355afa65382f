# SPDX-License-Identifier: LGPL-2.1-or-later
"""The Compensate region command (issue 30): several faces of one object selected in the 3D
view and a measurement object (selected, or the document's only one) give a
``SurfComp_RegionCompensation`` (:mod:`surfcomp.app.region_doc`): the faces corrected
together, continuity kept. One undo step; a region that cannot be corrected (a face covered
too little, a step across an edge, a neighbour the correction would move) leaves the document
as it was and says why. No numerics.

Replace in document and Restore nominal (:mod:`surfcomp.gui.commands`) take a region object
as they take a compensation: :func:`selected_replacing` finds it, and a wrong selection is
told what to select (:func:`replacing_or_refuse`).
"""

import FreeCAD
import FreeCADGui
from PySide.QtCore import QT_TRANSLATE_NOOP

from ..app import features
from ..app.undo import UndoStep
from ..errors import InputError
from . import fcgui, prefs
from .commands import Command, _state_error, measurement_for_selection

translate = FreeCAD.Qt.translate
ID = "SurfComp_CompensateRegion"
TEXTS = (QT_TRANSLATE_NOOP(ID, "Compensate region"),
         QT_TRANSLATE_NOOP(ID, "Compensate the selected faces of one solid together, with the "
                               "measurement object: one correction field across their shared "
                               "edges, so they stay closed and tangent"))


def selected_region():
    """``(object, ['FaceN', ...])`` when two or more faces of one object are selected."""
    picks = [(s.Object, n) for s in FreeCADGui.Selection.getSelectionEx()
             for n in s.SubElementNames if n.startswith("Face")]
    objects = {o.Name for o, _n in picks}
    if len(objects) != 1 or len({n for _o, n in picks}) < 2:
        return None
    names = []
    for _o, n in picks:
        if n not in names:
            names.append(n)
    return picks[0][0], names


def plain_view(obj):
    """Give a region object Part's own view provider (its shape drawn as a solid): a
    ``Part::FeaturePython`` whose view object has no proxy draws nothing. Run on every new
    surfcomp object and on those restored from a file."""
    from ..app.region_doc import is_region

    vobj = getattr(obj, "ViewObject", None)
    if vobj is None or not is_region(obj) or vobj.Proxy:
        return
    vobj.Proxy = 0
    modes = list(vobj.getEnumerationsOfProperty("DisplayMode") or [])
    if "Flat Lines" in modes:
        vobj.DisplayMode = "Flat Lines"


for _hooks in (features.NEW_OBJECT_HOOKS, features.RESTORED_HOOKS):
    if plain_view not in _hooks:
        _hooks.append(plain_view)


def selected_replacing():
    """The one selected compensation or region compensation (nothing else selected), or
    None."""
    from ..app.region_doc import is_region

    sel = FreeCADGui.Selection.getSelection()
    if len(sel) != 1 or not (features.is_compensation(sel[0]) or is_region(sel[0])):
        return None
    return sel[0]


def replacing_or_refuse(while_replacing):
    """The selected compensation or region compensation; raises with what to select when
    the selection holds something else."""
    comp = selected_replacing()
    if comp is not None:
        return comp
    labels = [o.Label for o in FreeCADGui.Selection.getSelection()]
    if while_replacing:
        what = translate("SurfComp", "Select the one compensation or region compensation "
                                     "that replaces its nominal (in the tree or the 3D view), "
                                     "then run Restore nominal")
    else:
        what = translate("SurfComp", "Select one compensation or region compensation (in the "
                                     "tree or the 3D view): its result takes the nominal's "
                                     "place, then run Replace in document")
    raise InputError(what + translate("SurfComp", "; the selection holds %s") % (
        ", ".join(labels) or translate("SurfComp", "nothing")))


class CompensateRegion(Command):
    ID = ID
    MENU, TIP = TEXTS

    def active(self):
        return selected_region() is not None

    def run(self):
        doc = FreeCAD.ActiveDocument
        region = selected_region()
        meas = measurement_for_selection(doc)
        if region is None or meas is None:
            raise InputError("select two or more faces of one solid (Ctrl+click) and a "
                             "measurement object")
        nominal, faces = region
        before = {o.Name for o in doc.Objects}
        with UndoStep(doc, translate("SurfComp", "Compensate region"), rollback=doc.recompute):
            FreeCADGui.addModule("surfcomp.app.region_doc")
            FreeCADGui.doCommand(
                "_reg = surfcomp.app.region_doc.make_region(App.getDocument(%r), "
                "App.getDocument(%r).getObject(%r), %r, App.getDocument(%r).getObject(%r), "
                "Method=%r, MaskSize=%d)"
                % (doc.Name, doc.Name, nominal.Name, ",".join(faces), doc.Name, meas.Name,
                   "raw" if prefs.method() == "raw" else "filtered", prefs.mask_size()))
            FreeCADGui.doCommand("App.getDocument(%r).recompute()" % doc.Name)
            reg = [o for o in self.new_objects(before) if o.isDerivedFrom("Part::Feature")][0]
            if "Invalid" in reg.State or "Error" in reg.State or reg.Shape.isNull():
                raise _state_error(reg)
            FreeCADGui.doCommand("App.getDocument(%r).getObject(%r).ViewObject.Visibility = "
                                 "False" % (doc.Name, nominal.Name))
            FreeCADGui.doCommand("App.getDocument(%r).getObject(%r).ViewObject.Visibility = "
                                 "False" % (doc.Name, meas.Name))
        for line in reg.Continuity:
            FreeCAD.Console.PrintMessage(line + "\n")
        text = translate("SurfComp", "%s: %s corrected together (%s points); largest gap "
                                     "along the shared edges %.4f um, volume change %.4f mm^3") % (
            reg.Label, ", ".join(reg.RegionFaces), ", ".join(reg.PointsPerFace), reg.MaxGap,
            reg.VolChange)
        FreeCAD.Console.PrintMessage(text + "\n")
        fcgui.show_status(text)
        return reg
