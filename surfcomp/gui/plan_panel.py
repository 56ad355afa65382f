# SPDX-License-Identifier: LGPL-2.1-or-later
"""Task panel of the Plan measurement command: the layout, its count and the probe.

The panel makes a ``SurfComp_MeasurementPlan`` object on the selected face (one undo step
with everything the panel does): **Plan** applies the fields and recomputes (the points show
in the 3D view, the counts and the drops in the panel), OK applies them and keeps the
object, Cancel removes it. An error (a tip larger than the face's concave radius, no
reachable point) stays in the panel; OK then keeps the panel open. No numerics here: the
object's proxy (:mod:`surfcomp.app.plan_feature`) plans.
"""

import FreeCAD
import FreeCADGui
from PySide import QtGui

from ..app import features
from ..app.undo import UndoStep
from ..core.measurement.planning import POINT_LAYOUTS
from ..core.option_tables import PLAN
from . import option_labels
from .task_panel import UndoTaskPanel

translate = FreeCAD.Qt.translate


def show_points(obj):
    """Draw a plan object's points: the Part view provider's own (FreeCAD's idiom: a view
    proxy of 0, no view provider class of ours) in its Points mode, 6 px, red. A creation
    hook of :mod:`surfcomp.app.features` (so plans made by scripts show too); idempotent."""
    from ..app.plan_feature import PLAN_TYPE

    vobj = getattr(obj, "ViewObject", None)
    if vobj is None or getattr(getattr(obj, "Proxy", None), "Type", None) != PLAN_TYPE:
        return
    if vobj.Proxy is None:
        vobj.Proxy = 0
        vobj.PointSize = 6
        vobj.PointColor = (0.85, 0.1, 0.1)
    if vobj.DisplayMode != "Points" and "Points" in vobj.listDisplayModes():
        vobj.DisplayMode = "Points"


def _spin(value, low, high, step=1.0, decimals=None):
    box = QtGui.QDoubleSpinBox() if decimals is not None else QtGui.QSpinBox()
    if decimals is not None:
        box.setDecimals(decimals)
    box.setRange(low, high)
    box.setSingleStep(step)
    box.setValue(value)
    return box


class PlanPanel(UndoTaskPanel):
    """Task panel (module docstring). ``instance``: the open panel (None when closed), for
    scripts and tests."""

    def __init__(self, nominal, face):
        PlanPanel.instance = self
        self.doc = nominal.Document
        self.step = UndoStep(self.doc, translate("SurfComp", "Plan measurement")).open()
        FreeCADGui.addModule("surfcomp.app.plan_feature")
        FreeCADGui.doCommand("_plan = surfcomp.app.plan_feature.make_measurement_plan("
                             "App.getDocument(%r), App.getDocument(%r).getObject(%r), %r)"
                             % (self.doc.Name, self.doc.Name, nominal.Name, face))
        self.obj = self.doc.Objects[-1]
        obj = self.obj
        self.form = QtGui.QWidget()
        self.form.setWindowTitle(translate("SurfComp", "Plan measurement"))
        lay = QtGui.QFormLayout(self.form)
        self.layout = QtGui.QComboBox()
        self.layout.addItems(list(PLAN["layout"].choices))
        u, v = (int(x) for x in obj.Count.lower().split("x"))
        self.count_u, self.count_v = _spin(u, 1, 1000), _spin(v, 1, 1000)
        self.points = _spin(int(obj.Points), PLAN["points"].low, PLAN["points"].high)
        self.tip = _spin(obj.TipRadius, 0.001, 100.0, 0.1, 3)
        self.margin = _spin(obj.EdgeMargin, 0.0, 100.0, 0.1, 3)
        tilt = PLAN["max_tilt"]
        self.tilt = _spin(obj.MaxTilt, tilt.low, tilt.high, 5.0, 1)
        # read-only text that wraps at the panel's width and scrolls: the task box keeps the
        # height it opened with, so a label growing with the message (an error with its
        # position, the dropped points' reasons) would be cut off below it
        self.result = QtGui.QPlainTextEdit()
        self.result.setReadOnly(True)
        self.result.setMinimumHeight(8 * self.result.fontMetrics().lineSpacing())
        self.plan_button = QtGui.QPushButton(translate("SurfComp", "Plan"))
        # labels and tooltips are the option registry's, as messages name the options
        # (the count, U x V, is two fields)
        for name, field, text in (
                ("layout", self.layout, None),
                ("count", self.count_u, translate("SurfComp", "Points along u (x)")),
                ("count", self.count_v, translate("SurfComp", "Points along v (y)")),
                ("points", self.points, None), ("tip_radius", self.tip, "%s (mm)"),
                ("edge_margin", self.margin, "%s (mm)"),
                ("max_tilt", self.tilt, translate("SurfComp", "%s (deg)"))):
            label = option_labels.label(name, ("plan",))
            field.setToolTip(option_labels.tip(name, "plan"))
            lay.addRow(label if text is None else text.replace("%s", label), field)
        lay.addRow(self.plan_button)
        lay.addRow(self.result)
        self.layout.currentIndexChanged.connect(self._enable)
        self.plan_button.clicked.connect(self.apply)
        self._enable()
        self.apply()

    def _enable(self, *_args):
        points = self.layout.currentText() in POINT_LAYOUTS
        self.points.setEnabled(points)
        self.count_u.setEnabled(not points)
        self.count_v.setEnabled(not points)

    def values(self):
        return {"Layout": self.layout.currentText(),
                "Count": "%dx%d" % (self.count_u.value(), self.count_v.value()),
                "Points": int(self.points.value()), "TipRadius": float(self.tip.value()),
                "EdgeMargin": float(self.margin.value()), "MaxTilt": float(self.tilt.value())}

    def apply(self):
        """Check the fields (a trial plan, nothing written), then write them to the object
        (macro lines) and recompute; show the outcome. Returns True when the plan has
        points."""
        from ..app.plan_feature import dropped, trial_plan
        from ..errors import SurfcompError

        try:
            plan = trial_plan(self.obj, **self.values())
        except SurfcompError as exc:
            self.result.setPlainText(option_labels.shown(exc, ("plan",)))
            self.result.setStyleSheet("color: #c53030;")
            return False
        lines = ["_plan = App.getDocument(%r).getObject(%r)" % (self.doc.Name, self.obj.Name)]
        lines += ["_plan.%s = %r" % (k, v) for k, v in self.values().items()]
        lines.append("App.getDocument(%r).recompute()" % self.doc.Name)
        for line in lines:
            FreeCADGui.doCommand(line)
        show_points(self.obj)
        obj = self.obj
        if "Invalid" in obj.State or "Error" in obj.State:
            self.result.setPlainText(obj.getStatusString())
            self.result.setStyleSheet("color: #c53030;")
            return False
        text = translate("SurfComp", "%d of %d points kept; travel %.1f mm (%s order); "
                                     "safe Z %.3f mm") % (obj.Kept, obj.Placed, obj.Travel,
                                                          obj.Order, obj.SafeZ)
        if obj.Dropped:
            # the plan the object now holds (the same fields): its reasons name the options
            # by the fields' labels, where the property names them by the properties
            text += "\n" + translate("SurfComp", "Dropped: %s") % "; ".join(
                option_labels.shown(reason, ("plan",)) for reason in dropped(plan))
        self.result.setPlainText(text)
        self.result.setStyleSheet("")
        return True


if show_points not in features.NEW_OBJECT_HOOKS:
    features.NEW_OBJECT_HOOKS.append(show_points)
