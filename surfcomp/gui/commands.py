# SPDX-License-Identifier: LGPL-2.1-or-later
"""The workbench's commands (ids ``SurfComp_<Verb><Noun>``).

One base class, :class:`Command`, carries the boilerplate: resources (icon named after
the command id in ``resources/icons``, translatable texts), ``IsActive`` from the
selection, and ``Activated`` running the command's macro lines (``Gui.addModule`` +
``Gui.doCommand`` calling the app factories) inside one transaction. A
:class:`~surfcomp.errors.SurfcompError` aborts the transaction (the document is left as
it was) and is shown with the CLI's message through :mod:`surfcomp.gui.dialogs`.
"""

import os

import FreeCAD
import FreeCADGui
from PySide.QtCore import QT_TRANSLATE_NOOP

from .. import paths
from ..app import features
from ..app.undo import UndoStep
from ..errors import ComputationError, InputError, SurfcompError
from . import dialogs, fcgui, option_labels, plan_panel, prefs

translate = FreeCAD.Qt.translate

CAD_FILTER = "CAD files (*.step *.stp *.iges *.igs *.brep *.brp);;All files (*)"
MEASUREMENT_FILTER = ("Measurements (*.csv *.txt *.xyz *.qif *.dat *.log);;All files (*)")


# -- selection ------------------------------------------------------------------------------
def selected_face():
    """``(object, 'FaceN')`` of the one selected face, or None."""
    faces = [(s.Object, n) for s in FreeCADGui.Selection.getSelectionEx()
             for n in s.SubElementNames if n.startswith("Face")]
    return faces[0] if len(faces) == 1 else None


def selected(kind):
    """Selected objects for which ``kind(obj)`` is true."""
    return [o for o in FreeCADGui.Selection.getSelection() if kind(o)]


def selected_compensation():
    found = selected(features.is_compensation)
    return found[0] if len(found) == 1 else None


def measurement_for_selection(doc):
    """The selected measurement object, else the only one of the document, else None."""
    found = selected(features.is_measurement)
    if len(found) == 1:
        return found[0]
    if found:
        return None
    every = [o for o in doc.Objects if features.is_measurement(o)] if doc else []
    return every[0] if len(every) == 1 else None


def _state_error(obj):
    """The error of an object that failed to recompute, as a SurfcompError."""
    status = obj.getStatusString() if hasattr(obj, "getStatusString") else ""
    return ComputationError("%s could not be computed: %s" % (obj.Label, status or
                                                              ", ".join(obj.State)))


#: menu text and tooltip of every command, marked for translation in the command's context
TEXTS = {
    "SurfComp_LoadNominal": (
        QT_TRANSLATE_NOOP("SurfComp_LoadNominal", "Load nominal"),
        QT_TRANSLATE_NOOP("SurfComp_LoadNominal", "Check the selected face as nominal, or read a "
                                                  "STEP/IGES/BREP file into the document")),
    "SurfComp_ImportMeasurements": (
        QT_TRANSLATE_NOOP("SurfComp_ImportMeasurements", "Import measurements"),
        QT_TRANSLATE_NOOP("SurfComp_ImportMeasurements", "Read a measurement file (CSV, XYZ, "
                                                         "XYZIJK, probe log, QIF): preview of "
                                                         "columns, units, points and problems "
                                                         "first")),
    "SurfComp_DeviationMap": (
        QT_TRANSLATE_NOOP("SurfComp_DeviationMap", "Deviation map"),
        QT_TRANSLATE_NOOP("SurfComp_DeviationMap", "Colour map of the deviations on the nominal "
                                                   "face (select the face and a measurement, or a"
                                                   " compensation)")),
    "SurfComp_ShowDeviation": (
        QT_TRANSLATE_NOOP("SurfComp_ShowDeviation", "Deviation"),
        QT_TRANSLATE_NOOP("SurfComp_ShowDeviation", "Show the measured deviation on the selected "
                          "compensation's map (+ = material left)")),
    "SurfComp_ShowDetermined": (
        QT_TRANSLATE_NOOP("SurfComp_ShowDetermined", "Determined component"),
        QT_TRANSLATE_NOOP("SurfComp_ShowDetermined", "Show the determined (filtered, systematic) "
                          "component of the deviation")),
    "SurfComp_ShowRandom": (
        QT_TRANSLATE_NOOP("SurfComp_ShowRandom", "Random component"),
        QT_TRANSLATE_NOOP("SurfComp_ShowRandom", "Show the random component: deviation - "
                          "determined")),
    "SurfComp_ShowCorrection": (
        QT_TRANSLATE_NOOP("SurfComp_ShowCorrection", "Correction"),
        QT_TRANSLATE_NOOP("SurfComp_ShowCorrection", "Show the correction the corrected face "
                          "realises (+ = material removed: the face moves in by it)")),
    "SurfComp_Filter": (
        QT_TRANSLATE_NOOP("SurfComp_Filter", "Filter"),
        QT_TRANSLATE_NOOP("SurfComp_Filter", "Mask size, weights and edge handling of the filter,"
                                             " with live maps of the determined and random "
                                             "components")),
    "SurfComp_Mirror": (
        QT_TRANSLATE_NOOP("SurfComp_Mirror", "Mirror (stock)"),
        QT_TRANSLATE_NOOP("SurfComp_Mirror", "Mirror method with a semi-finishing allowance: the "
                                             "corrected face mirrors the determined error (stock "
                                             "in mm)")),
    "SurfComp_BuildFace": (
        QT_TRANSLATE_NOOP("SurfComp_BuildFace", "Build corrected face"),
        QT_TRANSLATE_NOOP("SurfComp_BuildFace", "Add the corrected face of the selected "
                                                "compensation as a plain Part feature (for "
                                                "export); with a face and a measurement selected,"
                                                " compute the compensation first")),
    "SurfComp_ReplaceInDocument": (
        QT_TRANSLATE_NOOP("SurfComp_ReplaceInDocument", "Replace in document"),
        QT_TRANSLATE_NOOP("SurfComp_ReplaceInDocument", "Let the users of the nominal (Path jobs,"
                                                        " links) use the corrected face instead; "
                                                        "Restore puts the nominal back")),
    "SurfComp_RestoreNominal": (
        QT_TRANSLATE_NOOP("SurfComp_RestoreNominal", "Restore nominal"),
        QT_TRANSLATE_NOOP("SurfComp_RestoreNominal", "Undo Replace in document: the users of the "
                                                     "nominal use it again")),
    "SurfComp_Report": (
        QT_TRANSLATE_NOOP("SurfComp_Report", "Report"),
        QT_TRANSLATE_NOOP("SurfComp_Report", "Statistics of deviations, determined and random "
                                             "components and correction (like the papers' "
                                             "tables), copyable")),
    "SurfComp_PlanMeasurement": (
        QT_TRANSLATE_NOOP("SurfComp_PlanMeasurement", "Plan measurement"),
        QT_TRANSLATE_NOOP("SurfComp_PlanMeasurement", "Place the probing points on the "
                                                      "selected face (grid, XY grid or "
                                                      "adaptive) for on-machine measurement")),
}

# -- the base command -----------------------------------------------------------------------
class Command:
    """Boilerplate of every SurfComp command; subclasses set the texts and ``run``."""

    ID = ""

    @property
    def MENU(self):
        return TEXTS[self.ID][0]

    @property
    def TIP(self):
        return TEXTS[self.ID][1]

    def GetResources(self):
        return {"Pixmap": paths.icon(self.ID + ".svg"), "MenuText": self.MENU,
                "ToolTip": self.TIP, "StatusTip": self.TIP}

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and bool(self.active())

    def active(self):
        return True

    def Activated(self):
        doc = FreeCAD.ActiveDocument
        try:
            self.run()
        except SurfcompError as exc:
            if doc is not None and doc.HasPendingTransaction:
                doc.abortTransaction()
            dialogs.show_error(translate("SurfComp", "SurfComp: %s") % self.MENU,
                               option_labels.shown(exc))

    def run(self):
        raise NotImplementedError

    # helpers for run()
    @staticmethod
    def macro(label, lines, modules=()):
        """Run ``lines`` with ``Gui.doCommand`` (so they are recorded in macros) inside one
        transaction of the active document; abort it on any error and re-raise."""
        for mod in modules:
            FreeCADGui.addModule(mod)
        with UndoStep(FreeCAD.ActiveDocument, label):
            for line in lines:
                FreeCADGui.doCommand(line)

    @staticmethod
    def new_objects(before):
        doc = FreeCAD.ActiveDocument
        return [o for o in doc.Objects if o.Name not in before]


def _check_on_face(nom, face, meas):
    """Refuse, before any object is made, a measurement whose points the new compensation
    could not locate on the face (off the face, beyond its border, beyond the max offset):
    the message in a dialog and the Report view, not a failed recompute's tracebacks."""
    from ..app import precheck

    errors = precheck.check_on_face(nom, face, features.measurement_set(meas))[0]
    if errors:
        raise InputError("%s: %s" % (meas.Label, errors[0]))


def create_compensation(label, display="Map", quantity="deviation"):
    """Macro: a compensation of the selected face and measurement with the preferences'
    method, mask and edge handling; computed and shown. Returns the new object.

    Raises SurfcompError (the document is then left unchanged) when the inputs are
    missing or the computation fails.
    """
    doc = FreeCAD.ActiveDocument
    sel = selected_face()
    meas = measurement_for_selection(doc)
    if sel is None or meas is None:
        raise InputError("select the nominal face (one face) and a measurement object")
    nom, face = sel
    _check_on_face(nom, face, meas)
    before = {o.Name for o in doc.Objects}
    lines = ["_doc = App.ActiveDocument",
             "_comp = surfcomp.app.features.make_compensation(_doc, _doc.getObject(%r), %r, "
             "_doc.getObject(%r), method=%r, mask_size=%d, edge=%r)"
             % (nom.Name, face, meas.Name, prefs.method(), prefs.mask_size(), prefs.edge()),
             "surfcomp.gui.viewproviders.attach(_comp)",
             "_comp.ViewObject.Map = %r" % quantity,
             "_doc.recompute()",
             # the map lies on the nominal face: hide what would cover it
             "_doc.getObject(%r).ViewObject.Visibility = False" % nom.Name,
             "_doc.getObject(%r).ViewObject.Visibility = False" % meas.Name]
    with UndoStep(doc, label, rollback=doc.recompute):
        FreeCADGui.addModule("surfcomp.app.features")
        FreeCADGui.addModule("surfcomp.gui.viewproviders")
        for line in lines:
            FreeCADGui.doCommand(line)
        comp = next(o for o in Command.new_objects(before) if features.is_compensation(o))
        if "Invalid" in comp.State or "Error" in comp.State or comp.Shape.isNull():
            raise _state_error(comp)
        comp.ViewObject.DisplayMode = display
    return comp


# -- the commands -----------------------------------------------------------------------------
class LoadNominal(Command):
    ID = "SurfComp_LoadNominal"

    def IsActive(self):
        return True

    def run(self):
        sel = selected_face()
        if sel is not None:
            from ..app.nominal import nominal_from_face

            obj, name = sel
            face = getattr(obj.Shape, name)
            nom = nominal_from_face(face, source=obj.Label, face_name=name)
            text = ("SurfComp nominal: %s.%s (%s, %d x %d poles)"
                    % (obj.Label, name, nom.converted or "BSplineSurface", *nom.surface.shape))
            FreeCAD.Console.PrintMessage(text + "\n")
            fcgui.show_status(text)
            dialogs.show_info(self.MENU, text + "\n" + translate(
                "SurfComp", "Area %.1f mm², ready to use as the nominal: select it with a "
                            "measurement and run Deviation map.") % face.Area)
            return
        path = dialogs.ask_open_file(translate("SurfComp", "Nominal face"), CAD_FILTER)
        if not path:
            return
        if FreeCAD.ActiveDocument is None:
            FreeCADGui.doCommand("App.newDocument()")
        label = os.path.splitext(os.path.basename(path))[0]
        self.macro(translate("SurfComp", "Load nominal"), [
            "_shape, _name = surfcomp.app.nominal.read_shape(%r)" % path,
            "_nominal = App.ActiveDocument.addObject('Part::Feature', 'Nominal')",
            "_nominal.Shape = _shape",
            "_nominal.Label = %r" % label,
            "App.ActiveDocument.recompute()",
            "Gui.SendMsgToActiveView('ViewFit')"], modules=("surfcomp.app.nominal",))


class ImportMeasurements(Command):
    ID = "SurfComp_ImportMeasurements"

    def run(self):
        from ..io.readers import read_any
        from .preview import PreviewDialog

        path = dialogs.ask_open_file(translate("SurfComp", "Measurement file"),
                                     MEASUREMENT_FILTER)
        if not path:
            return
        ms = read_any(path, units=prefs.file_units())
        face, face_name = _preview_face()
        dlg = PreviewDialog(ms, reader=lambda units, dev: read_any(path, units=units,
                                                                   deviation_units=dev),
                            face=face, face_name=face_name)
        # a file with implausible deviations or points off the face never reaches the document
        if not dialogs.run_dialog(dlg) or not dlg.accepted_ok():
            return
        units, dev = dlg.units(), dlg.deviation_units()
        self.macro(translate("SurfComp", "Import measurements"), [
            "_meas = surfcomp.app.features.make_measurement(App.ActiveDocument, %r, units=%r%s)"
            % (path, units, "" if dev == units else ", deviation_units=%r" % dev),
            "surfcomp.gui.viewproviders.attach(_meas)",
            "App.ActiveDocument.recompute()"],
            modules=("surfcomp.app.features", "surfcomp.gui.viewproviders"))


def _preview_face():
    """``(check, 'Label.FaceN')`` of the nominal face the import preview checks the points
    against (the selected face, else the document's only object with one B-spline face),
    or ``(None, '')``."""
    from ..app import precheck

    found = selected_face() or precheck.nominal_candidate(FreeCAD.ActiveDocument)
    if found is None:
        return None, ""
    obj, face = found

    def check(ms):
        return precheck.check_on_face(obj, face, ms)

    return check, "%s.%s" % (obj.Label, face)


class _MapCommand(Command):
    QUANTITY = "deviation"

    def active(self=None):
        if selected_compensation() is not None:
            return True
        return selected_face() is not None and \
            measurement_for_selection(FreeCAD.ActiveDocument) is not None

    def run(self):
        comp = selected_compensation()
        if comp is None:
            create_compensation(self.MENU, "Map", self.QUANTITY)
            return
        self.show(comp, self.QUANTITY)

    @staticmethod
    def show(comp, quantity):
        vobj = comp.ViewObject
        if vobj is None or "Map" not in vobj.PropertiesList:
            raise InputError("%s has no colour map view (open it with the SurfComp "
                             "workbench loaded)" % comp.Label)
        vobj.Map = quantity
        vobj.DisplayMode = "Map"
        vobj.Visibility = True
        for other in (comp.Nominal, comp.Measurement):
            if other is not None and other.ViewObject is not None:
                other.ViewObject.Visibility = False


#: the four maps: command and quantity
MAP_COMMANDS = (("SurfComp_ShowDeviation", "deviation"), ("SurfComp_ShowDetermined", "determined"),
                ("SurfComp_ShowRandom", "random"), ("SurfComp_ShowCorrection", "correction"))

ShowDeviation, ShowDetermined, ShowRandom, ShowCorrection = (
    type(cid[len("SurfComp_"):], (_MapCommand,), {"ID": cid, "QUANTITY": quantity})
    for cid, quantity in MAP_COMMANDS)


class ShowMaps:
    """Toolbar drop-down of the four maps (a FreeCAD command group)."""

    ID = "SurfComp_ShowMaps"
    ITEMS = tuple(row[0] for row in MAP_COMMANDS)

    def GetCommands(self):
        return self.ITEMS

    def GetDefaultCommand(self):
        return 0

    def GetResources(self):
        return {"Pixmap": paths.icon(self.ID + ".svg"),
                "MenuText": QT_TRANSLATE_NOOP("SurfComp_ShowMaps", "Show map"),
                "ToolTip": QT_TRANSLATE_NOOP("SurfComp_ShowMaps",
                                             "Deviation, determined, random or correction map "
                                             "of the selected compensation")}

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and _MapCommand.active(None)


class DeviationMap(_MapCommand):
    ID = "SurfComp_DeviationMap"


class _CompensationCommand(Command):
    """A command on the selected compensation: ``apply(comp)``."""

    def active(self):
        return selected_compensation() is not None

    def run(self):
        self.apply(selected_compensation())

    def apply(self, comp):
        raise NotImplementedError


class Filter(_CompensationCommand):
    ID = "SurfComp_Filter"

    def apply(self, comp):
        FreeCADGui.ActiveDocument.setEdit(comp.Name, 0)


class Mirror(_CompensationCommand):
    ID = "SurfComp_Mirror"

    def apply(self, comp):
        deviation = [float(x) for x in comp.Deviation] or None
        answer = dialogs.ask_stock(self.MENU, float(comp.Stock.Value) or 0.1, deviation)
        if answer is None:
            return
        stock, confirmed = answer
        doc = FreeCAD.ActiveDocument
        self.macro(self.MENU, [
            "_comp = App.ActiveDocument.getObject(%r)" % comp.Name,
            "_comp.Method = 'mirror'",
            "_comp.Stock = %r" % stock,
            "_comp.StockOk = %r" % bool(confirmed),
            "_comp.ViewObject.Map = 'correction'",
            "App.ActiveDocument.recompute()"])
        if "Invalid" in comp.State or "Error" in comp.State:
            err = _state_error(comp)
            doc.undo()
            doc.recompute()
            raise err


class BuildFace(Command):
    ID = "SurfComp_BuildFace"

    def active(self):
        return _MapCommand.active(self)

    def run(self):
        comp = selected_compensation()
        if comp is None:
            comp = create_compensation(self.MENU, "Shaded")
        self.macro(self.MENU, [
            "_comp = App.ActiveDocument.getObject(%r)" % comp.Name,
            "_face = App.ActiveDocument.addObject('Part::Feature', 'CorrectedFace')",
            "_face.Shape = _comp.Shape.copy()",
            "_face.Label = %r" % face_label(comp),
            # it lies on the map (within the correction): drawn over it, it z-fights
            "_face.ViewObject.Visibility = False",
            "App.ActiveDocument.recompute()"])


def face_label(comp):
    """Label of a built face: nominal, method (mirror with its stock), iteration round and
    build (``Nominal filtered round 1 build 2``: the second face built from round 1). The
    build is counted among the faces of the document with that label: FreeCAD's own suffix
    for a repeated label (``... r002``) would read as a round."""
    nominal = comp.Nominal.Label if comp.Nominal is not None else comp.Label
    method = comp.Method
    if method == "mirror":
        method += " %gmm" % float(comp.Stock.Value)
    base = "%s %s round %d build " % (nominal, method, int(comp.Round))
    builds = [o.Label[len(base):] for o in comp.Document.Objects if o.Label.startswith(base)]
    last = max((int(b) for b in builds if b.isdigit()), default=0)
    return base + str(last + 1)


class _ReplaceCommand(Command):
    """Replace in document / Restore nominal: one command, two directions."""

    #: ``surfcomp.app.replace`` function to call, and whether it needs a replacing compensation
    ACTION = "replace"
    WHILE_REPLACING = False

    def active(self):
        from ..app import replace
        from .region_cmd import selected_replacing

        # a wrong selection keeps the command active: run() says what to select
        comp = selected_replacing()
        return bool(FreeCADGui.Selection.getSelection()) and (
            comp is None or replace.is_replacing(comp) == self.WHILE_REPLACING)

    def run(self):
        from ..app import recompute, replace, toolpaths
        from ..errors import Cancelled
        from . import busy
        from .region_cmd import replacing_or_refuse

        # surfcomp.app.replace opens and commits its own transaction
        comp = replacing_or_refuse(self.WHILE_REPLACING)
        doc = comp.Document
        before = replace.summary(doc, comp) if self.WHILE_REPLACING else None
        paths_before = toolpaths.snapshot(doc)
        touched = {o.Name for o in doc.Objects if "Touched" in o.State}
        FreeCADGui.addModule("surfcomp.app.replace")
        FreeCADGui.doCommand("surfcomp.app.replace.%s(App.ActiveDocument, "
                             "App.ActiveDocument.getObject(%r))" % (self.ACTION, comp.Name))
        # the users regenerate, each once, the Path operations in a child process under a
        # progress dialog; Esc stops it and undoes the step (the operations keep their paths)
        try:
            busy.recompute(doc, "%s: %s" % (self.MENU, comp.Label))
        except Cancelled:
            doc.undo()
            recompute.settle_after_undo(doc, touched)
            dialogs.show_info(self.MENU, translate("SurfComp", "Cancelled: the document is "
                                                               "as before."))
            return
        done = before or replace.summary(doc, comp)
        done["toolpaths"] = toolpaths.compare(doc, paths_before, done["job_names"])
        dialogs.show_info(self.MENU, self.summary_text(done))

    def summary_text(self, s):
        verb = translate("SurfComp", "Restored") if self.WHILE_REPLACING \
            else translate("SurfComp", "Rebound")
        lines = [translate("SurfComp", "%s %d link(s) of %d object(s): %s")
                 % (verb, s["links"], len(s["objects"]), ", ".join(s["objects"]) or "-")]
        if s.get("deleted"):
            lines.append(translate("SurfComp", "Not restored (deleted since the replace): %s")
                         % ", ".join(s["deleted"]))
        # what the recompute did to each Job's operations, not just which Jobs use the face
        from ..app import toolpaths

        lines += toolpaths.describe(s["toolpaths"], lambda text: translate("SurfComp", text)) \
            or [translate("SurfComp", "Path jobs: none")]
        for old, new in s["renamed"]:
            lines.append(translate("SurfComp", "Renamed %s -> %s") % ((new, old) if
                                                                     self.WHILE_REPLACING
                                                                     else (old, new)))
        return "\n".join(lines)


class ReplaceInDocument(_ReplaceCommand):
    ID = "SurfComp_ReplaceInDocument"


class RestoreNominal(_ReplaceCommand):
    ID = "SurfComp_RestoreNominal"
    ACTION = "restore"
    WHILE_REPLACING = True


class Report(_CompensationCommand):
    ID = "SurfComp_Report"

    def active(self):
        comp = selected_compensation()
        return comp is not None and comp.Statistics not in ("", "{}")

    def apply(self, comp):
        from .panels import ReportDialog

        dialogs.run_dialog(ReportDialog(comp))


class PlanMeasurement(Command):
    ID = "SurfComp_PlanMeasurement"

    def active(self):
        return selected_face() is not None

    def run(self):
        nom, face = selected_face()
        FreeCADGui.Control.showDialog(plan_panel.PlanPanel(nom, face))


from .probe_op_cmd import AddProbeOperation  # noqa: E402 (its base class is above)
from .region_cmd import CompensateRegion  # noqa: E402 (its base class is above)
from .surface_dressup_cmd import AddSurfaceCorrection  # noqa: E402 (its base class is above)

COMMANDS = (LoadNominal, ImportMeasurements, DeviationMap, ShowDeviation, ShowDetermined,
            ShowRandom, ShowCorrection, Filter, Mirror, BuildFace, ReplaceInDocument,
            RestoreNominal, Report, PlanMeasurement, AddProbeOperation, AddSurfaceCorrection,
            CompensateRegion)
#: command groups (toolbar drop-downs)
GROUPS = (ShowMaps,)
#: toolbar/menu order (None: separator)
TOOLBAR = ("SurfComp_LoadNominal", "SurfComp_ImportMeasurements", None, "SurfComp_DeviationMap",
           "SurfComp_ShowMaps", "SurfComp_Filter", "SurfComp_Mirror", "SurfComp_BuildFace",
           "SurfComp_CompensateRegion", None,
           "SurfComp_ReplaceInDocument", "SurfComp_RestoreNominal", None, "SurfComp_Report",
           None, "SurfComp_PlanMeasurement", "SurfComp_AddProbeOperation",
           "SurfComp_AddSurfaceCorrection", None, "SurfComp_AlignMeasurements")


def register():
    """Add every command and command group to FreeCAD (idempotent)."""
    # its module imports this one (so it can be imported first), hence here
    from .align_panel import AlignMeasurements

    every = COMMANDS + (AlignMeasurements,) + GROUPS
    known = set(FreeCADGui.listCommands())
    for cls in every:
        if cls.ID not in known:
            FreeCADGui.addCommand(cls.ID, cls())
    return [c.ID for c in every]
