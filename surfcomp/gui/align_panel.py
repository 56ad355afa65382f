# SPDX-License-Identifier: LGPL-2.1-or-later
"""The Align measurements command and its task panel: how a compensation's measured points
are aligned to the nominal before the deviations (README "Alignment").

The settings are the measurement object's Align* properties (``AlignMethod``,
``AlignFaces``, ``AlignDof``, ``AlignRps``, ``AlignTransform``); the result is the
compensation's (``AlignMatrix``, ``Alignment``). **Apply** checks the fields
(:func:`surfcomp.app.align_doc.options_from`, then a trial alignment,
:func:`surfcomp.app.align_doc.trial`: nothing written when they are wrong), writes
them as macro lines and recomputes; the panel then shows the transform, the RMS before and
after and what a fit on the compensated face absorbed, or the compensation's error. OK
applies and keeps them (one undo step with everything the panel did); Cancel puts the
document back. The files (transform, 3-2-1 ids) are read into the properties, so the
document does not depend on them. No numerics here: :mod:`surfcomp.app.align_doc`.
"""

import FreeCAD
import FreeCADGui
from PySide import QtGui
from PySide.QtCore import QT_TRANSLATE_NOOP

from ..app import align_doc, features
from ..app.undo import UndoStep
from ..core.measurement.align import DOF_NAMES, parse_dof
from ..core.option_tables import ALIGN
from ..errors import SurfcompError
from . import dialogs, fit_view, option_labels
from .commands import Command, selected
from .result_box import result_box, show_message
from .task_panel import UndoTaskPanel

translate = FreeCAD.Qt.translate
ID = "SurfComp_AlignMeasurements"
TEXTS = (QT_TRANSLATE_NOOP(ID, "Align measurements"),
         QT_TRANSLATE_NOOP(ID, "Align the measured points of the selected compensation to the "
                               "nominal before the deviations: best fit, 3-2-1 or a known "
                               "transform, with what the alignment absorbed"))
TRANSFORM_FILTER = "Transform (*.json *.txt *.csv);;All files (*)"
RPS_FILTER = "3-2-1 set (*.json);;All files (*)"
#: lines of the result box (it scrolls), and the least height of the options (pixels) when
#: the task view is short (:mod:`surfcomp.gui.fit_view`)
RESULT_LINES, OPTIONS_LEAST = 9, 100


def compensation_of_selection(doc):
    """The selected compensation, else the document's only one, else None."""
    found = selected(features.is_compensation)
    if len(found) == 1:
        return found[0]
    every = [o for o in doc.Objects if features.is_compensation(o)] if doc else []
    return every[0] if len(every) == 1 and not found else None


class AlignMeasurements(Command):
    ID = ID
    MENU, TIP = TEXTS

    def active(self):
        comp = compensation_of_selection(FreeCAD.ActiveDocument)
        return comp is not None and features.is_measurement(comp.Measurement)

    def run(self):
        comp = compensation_of_selection(FreeCAD.ActiveDocument)
        FreeCADGui.Control.showDialog(AlignPanel(comp))


class AlignPanel(UndoTaskPanel):
    """Task panel (module docstring). ``instance``: the open panel (None when closed), for
    scripts and tests."""

    def __init__(self, comp):
        AlignPanel.instance = self
        self.comp, self.meas = comp, comp.Measurement
        self.doc = comp.Document
        self.step = UndoStep(self.doc, translate("SurfComp", "Align measurements"),
                             rollback=self.doc.recompute).open()
        meas = self.meas
        self.matrix = list(meas.AlignTransform or [])
        self.form = QtGui.QWidget()
        self.form.setWindowTitle(translate("SurfComp", "Align measurements"))
        options = QtGui.QWidget()
        lay = QtGui.QVBoxLayout(options)
        lay.setContentsMargins(0, 0, 0, 0)
        methods = list(ALIGN["align"].choices)
        self.method = QtGui.QComboBox()
        self.method.addItems(methods)
        self.method.setCurrentIndex(methods.index(meas.AlignMethod))
        self.faces = QtGui.QLineEdit(meas.AlignFaces)
        self.faces.setPlaceholderText(translate("SurfComp", "the compensated face"))
        self.faces_button = QtGui.QPushButton(translate("SurfComp", "From selection"))
        self.faces_button.setToolTip(translate(
            "SurfComp", "The faces selected in the 3D view (datum faces of the nominal)"))
        self.dof = {}
        dof_grid = QtGui.QGridLayout()
        given = parse_dof(meas.AlignDof or "all")
        for k, name in enumerate(DOF_NAMES):
            box = QtGui.QCheckBox(name)
            box.setChecked(name in given)
            self.dof[name] = box
            dof_grid.addWidget(box, k // 3, k % 3)      # x y z over rx ry rz
        self.rps = QtGui.QLineEdit(meas.AlignRps)
        self.rps.setPlaceholderText("P1,P2,P3;P4,P5;P6")
        self.rps_button = QtGui.QPushButton(translate("SurfComp", "File..."))
        self.transform = QtGui.QLabel("")
        self.transform.setWordWrap(True)
        self.transform_button = QtGui.QPushButton(translate("SurfComp", "Transform file..."))
        self.clear_button = QtGui.QPushButton(translate("SurfComp", "No transform"))
        self.apply_button = QtGui.QPushButton(translate("SurfComp", "Apply"))
        # the transform, the RMS and what the fit absorbed: a label would widen the panel
        self.result = result_box(RESULT_LINES)
        # labels above their fields (the task view is narrow); labels and tooltips are the
        # option registry's, as messages name the options
        for name, field in (("align", self.method),
                            ("align_faces", _row(self.faces, self.faces_button)),
                            ("align_dof", dof_grid),
                            ("rps", _row(self.rps, self.rps_button)),
                            ("transform", self.transform)):
            label = QtGui.QLabel(option_labels.label(name, ("align",)))
            label.setToolTip(option_labels.tip(name, "align"))
            lay.addWidget(label)
            if isinstance(field, QtGui.QLayout):
                lay.addLayout(field)
            else:
                field.setToolTip(option_labels.tip(name, "align"))
                lay.addWidget(field)
        lay.addWidget(_row(self.transform_button, self.clear_button))
        lay.addStretch(1)
        # the options scroll when the task view is short; Apply and the result stay in sight
        self.options = fit_view.options_area(options)
        self.fit = fit_view.FitInView(self.form, self.options, OPTIONS_LEAST)
        outer = QtGui.QVBoxLayout(self.form)
        outer.addWidget(self.options)
        outer.addWidget(self.apply_button)
        outer.addWidget(self.result)
        self.method.currentIndexChanged.connect(self._enable)
        self.faces_button.clicked.connect(self.faces_from_selection)
        self.rps_button.clicked.connect(self.rps_from_file)
        self.transform_button.clicked.connect(self.transform_from_file)
        self.clear_button.clicked.connect(self.clear_transform)
        self.apply_button.clicked.connect(self.apply)
        self._enable()
        self._show_transform()
        self.show_result()

    # -- fields -----------------------------------------------------------------------------
    def _enable(self, *_args):
        method = self.method.currentText()
        for box in self.dof.values():
            box.setEnabled(method == "bestfit")
        self.rps.setEnabled(method == "rps")
        self.rps_button.setEnabled(method == "rps")
        self.faces.setEnabled(method != "none")
        self.faces_button.setEnabled(method != "none")

    def _show_transform(self):
        self.transform.setText(align_doc.transform_text(self.matrix))
        self.clear_button.setEnabled(bool(self.matrix))

    def _message(self, text):
        show_message(self.result, text, bad=True)

    def faces_from_selection(self):
        """The faces selected in the 3D view (of any object) into the faces field."""
        names = [n for s in FreeCADGui.Selection.getSelectionEx() for n in s.SubElementNames
                 if n.startswith("Face")]
        if not names:
            self._message(translate("SurfComp", "Select the reference faces of the nominal in "
                                                "the 3D view first"))
            return
        self.faces.setText(",".join(dict.fromkeys(names)))

    def transform_from_file(self):
        path = dialogs.ask_open_file(translate("SurfComp", "Known transform"),
                                     TRANSFORM_FILTER)
        if not path:
            return
        try:
            self.matrix = align_doc.transform_from_file(path)
        except SurfcompError as exc:
            self._message(option_labels.shown(exc, ("align",)))
            return
        self._show_transform()

    def clear_transform(self):
        self.matrix = []
        self._show_transform()

    def rps_from_file(self):
        path = dialogs.ask_open_file(translate("SurfComp", "3-2-1 point ids"), RPS_FILTER)
        if not path:
            return
        try:
            self.rps.setText(align_doc.rps_from_file(path))
        except SurfcompError as exc:
            self._message(option_labels.shown(exc, ("align",)))

    def values(self):
        """The fields as property values."""
        # the boxes apply to the best fit (3-2-1 fixes all six)
        dof = [n for n in DOF_NAMES if self.dof[n].isChecked()
               or self.method.currentText() != "bestfit"]
        return {"AlignMethod": self.method.currentText(),
                "AlignFaces": ",".join(f.strip() for f in self.faces.text().split(",")
                                       if f.strip()),
                "AlignDof": "all" if len(dof) == len(DOF_NAMES) else ",".join(dof),
                "AlignRps": self.rps.text().strip(),
                "AlignTransform": list(self.matrix)}

    # -- apply, OK, Cancel ----------------------------------------------------------------------
    def apply(self):
        """Check the fields (nothing written when they are wrong), write them to the
        measurement object (macro lines), recompute and show the outcome. Returns True when
        the compensation computed."""
        v = self.values()
        if v["AlignMethod"] == "bestfit" and not v["AlignDof"]:
            self._message(translate("SurfComp", "Choose at least one degree of freedom"))
            return False
        try:
            opts = align_doc.options_from(self.meas.Label, v["AlignMethod"], v["AlignFaces"],
                                          v["AlignDof"], v["AlignRps"], v["AlignTransform"])
            align_doc.trial(self.comp, opts)
        except SurfcompError as exc:
            self._message(option_labels.shown(exc, ("align",)))
            return False
        lines = ["_meas = App.getDocument(%r).getObject(%r)" % (self.doc.Name, self.meas.Name)]
        lines += ["_meas.%s = %r" % (k, x) for k, x in v.items()]
        lines.append("App.getDocument(%r).recompute()" % self.doc.Name)
        for line in lines:
            FreeCADGui.doCommand(line)
        return self.show_result()

    def show_result(self):
        """The compensation's alignment (or its error) in the panel; True when it computed."""
        comp = self.comp
        if "Invalid" in comp.State or "Error" in comp.State:
            self._message(comp.getStatusString())
            return False
        lines = list(comp.Alignment) or [translate(
            "SurfComp", "No alignment: the measured points are used in the nominal's frame")]
        show_message(self.result, "\n".join(lines))
        return True


def _row(*widgets):
    w = QtGui.QWidget()
    lay = QtGui.QHBoxLayout(w)
    lay.setContentsMargins(0, 0, 0, 0)
    for x in widgets:
        lay.addWidget(x)
    return w
