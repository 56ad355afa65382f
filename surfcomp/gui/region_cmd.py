# SPDX-License-Identifier: LGPL-2.1-or-later
"""The Compensate region command (issue 30): several faces of one object selected in the 3D
view and a measurement object (selected, or the document's only one) give a
``SurfComp_RegionCompensation`` (:mod:`surfcomp.app.region_doc`): the faces corrected
together, continuity kept. One undo step; a region that cannot be corrected (a face covered
too little, a step across an edge, a neighbour the correction would move) leaves the document
as it was and says why. With one region object selected (and the measurement of the part
machined from its result), the same command adds its next round: a region object whose
``Base`` is the selected one, the same faces and options (:func:`selected_round`). No
numerics.

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
                               "edges, so they stay closed and tangent. With a region "
                               "compensation selected: its next round, from the measurement "
                               "of the part machined from its result"))


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


def selected_round():
    """The one selected region object when no faces are selected (its next round is made),
    or None."""
    from ..app.region_doc import is_region

    if selected_region() is not None:
        return None
    regions = [o for o in FreeCADGui.Selection.getSelection() if is_region(o)]
    return regions[0] if len(regions) == 1 else None


def round_measurement(doc, base):
    """The measurement of a next round of ``base``: the selected measurement object, else
    the document's only one that no earlier round used; raises with what to select."""
    from ..app.region_doc import chain

    used = {r.Measurement.Name for r in chain(base) if r.Measurement is not None}
    picked = [o for o in FreeCADGui.Selection.getSelection() if features.is_measurement(o)]
    if not picked:
        picked = [o for o in doc.Objects if features.is_measurement(o) and o.Name not in used]
    if len(picked) == 1 and picked[0].Name not in used:
        return picked[0]
    what = (translate("SurfComp", "%s already took part in a round of %s")
            % (picked[0].Label, base.Label) if len(picked) == 1 else
            translate("SurfComp", "%d measurement objects to choose from") % len(picked))
    raise InputError(translate(
        "SurfComp", "A next round of %s needs the measurement of the part machined from its "
                    "result: import it (Import measurements), select it with the region "
                    "compensation (Ctrl+click in the tree) and run Compensate region again (%s)")
        % (base.Label, what))


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
        return selected_region() is not None or selected_round() is not None

    def inputs(self, doc):
        """``(nominal, faces, measurement, base, options)`` of the selection: the selected
        faces, or the next round of the selected region object."""
        from ..app.region_doc import options_record

        base = selected_round()
        if base is not None:
            options = options_record(base)
            faces = options.pop("Faces")
            if base.RegionFaces:
                faces = ",".join(base.RegionFaces)
            return base.Nominal, faces, round_measurement(doc, base), base, options
        region = selected_region()
        meas = measurement_for_selection(doc)
        if region is None or meas is None:
            raise InputError("select two or more faces of one solid (Ctrl+click) and a "
                             "measurement object")
        options = {"Method": "raw" if prefs.method() == "raw" else "filtered",
                   "MaskSize": prefs.mask_size()}
        return region[0], ",".join(region[1]), meas, None, options

    def run(self):
        doc = FreeCAD.ActiveDocument
        nominal, faces, meas, base, options = self.inputs(doc)
        before = {o.Name for o in doc.Objects}
        at = "App.getDocument(%r).getObject(%%r)" % doc.Name
        with UndoStep(doc, translate("SurfComp", "Compensate region"), rollback=doc.recompute):
            FreeCADGui.addModule("surfcomp.app.region_doc")
            FreeCADGui.doCommand(
                "_reg = surfcomp.app.region_doc.make_region(App.getDocument(%r), %s, %r, %s, "
                "base=%s, %s)"
                % (doc.Name, at % nominal.Name, faces, at % meas.Name,
                   "None" if base is None else at % base.Name,
                   ", ".join("%s=%r" % kv for kv in sorted(options.items()))))
            FreeCADGui.doCommand("App.getDocument(%r).recompute()" % doc.Name)
            reg = [o for o in self.new_objects(before) if o.isDerivedFrom("Part::Feature")][0]
            if "Invalid" in reg.State or "Error" in reg.State or reg.Shape.isNull():
                raise _state_error(reg)
            for hidden in [nominal, meas] + ([] if base is None else [base]):
                FreeCADGui.doCommand("App.getDocument(%r).getObject(%r).ViewObject.Visibility "
                                     "= False" % (doc.Name, hidden.Name))
        for line in reg.Continuity:
            FreeCAD.Console.PrintMessage(line + "\n")
        text = translate("SurfComp", "%s: %s corrected together (%s points); largest gap "
                                     "along the shared edges %.4f um, volume change %.4f mm^3") % (
            reg.Label, ", ".join(reg.RegionFaces), ", ".join(reg.PointsPerFace), reg.MaxGap,
            reg.VolChange)
        FreeCAD.Console.PrintMessage(text + "\n")
        fcgui.show_status(text)
        return reg
