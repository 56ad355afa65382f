"""Task panels and dialogs of the workbench: filter panel, report (the import preview is
in :mod:`surfcomp.gui.preview`).

No numerics: the filter panel edits the compensation's properties and recomputes it, the
report shows the statistics the compensation stored.
"""

import json

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from ..app import reports
from ..app.undo import UndoStep
from ..core.deviations import Statistics, format_table
from ..core.filters import EDGE_MODES
from ..errors import SurfcompError
from . import dialogs, prefs

translate = FreeCAD.Qt.translate

#: order of the report's columns (the papers' Tables 1-5)
REPORT_COLUMNS = (("deviation", "Deviation"), ("determined", "Determined"),
                  ("random", "Random"), ("increment", "Increment"),
                  ("correction", "Correction"))


def statistics_columns(obj):
    """``[(header, Statistics)]`` of a computed compensation, in report order."""
    data = json.loads(obj.Statistics or "{}")
    return [(head, Statistics(**data[key])) for key, head in REPORT_COLUMNS if key in data]


class ReportDialog(QtGui.QDialog):
    """The statistics table of a compensation (like the papers' Tables 1-5), copyable."""

    def __init__(self, obj, unit=None, parent=None):
        super().__init__(parent or FreeCADGui.getMainWindow())
        self.unit = unit or prefs.display_unit()
        self.setWindowTitle(translate("SurfComp", "Report: %s") % obj.Label)
        cols = statistics_columns(obj)
        if not cols:
            raise SurfcompError("%s has no statistics (recompute it first)" % obj.Label)
        self.text = format_table(cols, unit=self.unit, title=obj.Label)
        rows = cols[0][1].rows(self.unit)
        self.table = QtGui.QTableWidget(len(rows), len(cols))
        self.table.setHorizontalHeaderLabels([h for h, _ in cols])
        self.table.setVerticalHeaderLabels([r[0] for r in rows])
        fmt = "%.2f" if self.unit == "um" else "%.4f"
        for j, (_, st) in enumerate(cols):
            for i, (_label, value) in enumerate(st.rows(self.unit)):
                text = str(value) if i == 0 else fmt % value
                item = QtGui.QTableWidgetItem(text)
                item.setTextAlignment(QtCore.Qt.AlignRight | QtCore.Qt.AlignVCenter)
                self.table.setItem(i, j, item)
        self.table.resizeColumnsToContents()
        lay = QtGui.QVBoxLayout(self)
        lay.addWidget(QtGui.QLabel(translate("SurfComp", "Deviations in %s") % self.unit))
        lay.addWidget(self.table)
        box = QtGui.QDialogButtonBox(QtGui.QDialogButtonBox.Close)
        copy = box.addButton(translate("SurfComp", "Copy"), QtGui.QDialogButtonBox.ActionRole)
        copy.clicked.connect(self.copy)
        html = box.addButton(translate("SurfComp", "Save HTML report..."),
                             QtGui.QDialogButtonBox.ActionRole)
        html.clicked.connect(self.save_html)
        self.obj = obj
        box.rejected.connect(self.reject)
        lay.addWidget(box)
        self.resize(760, 320)

    def copy(self):
        """Put the table as text (the CLI's format) on the clipboard."""
        QtGui.QApplication.clipboard().setText(self.text)

    def save_html(self):
        """Write the self-contained HTML report (maps, histograms, tables, checks), as
        ``compensate --html`` does; returns the path or None."""
        path = dialogs.ask_save_file(translate("SurfComp", "Save HTML report"),
                                     "HTML (*.html *.htm)", self.obj.Label + ".html")
        if not path:
            return None
        try:
            reports.write_html_report(self.obj, path)
        except SurfcompError as exc:
            dialogs.show_error(translate("SurfComp", "Report"), str(exc))
            return None
        return path


class FilterPanel:
    """Task panel: mask size, weights, edge handling, with live maps of the determined
    and random components. OK keeps the change (one undo step), Cancel reverts it."""

    #: the open panel (None when closed), for scripts and tests
    instance = None

    def __init__(self, obj):
        FilterPanel.instance = self
        self.obj = obj
        self.doc = obj.Document
        self.form = QtGui.QWidget()
        self.form.setWindowTitle(translate("SurfComp", "Filter"))
        lay = QtGui.QFormLayout(self.form)
        self.mask = QtGui.QSpinBox()
        self.mask.setRange(1, 99)
        self.mask.setSingleStep(2)
        self.mask.setValue(int(obj.MaskSize))
        self.weights = QtGui.QLineEdit(obj.Weights)
        self.weights.setPlaceholderText(translate("SurfComp", "e.g. 1 2 1; 2 4 2; 1 2 1"))
        self.edge = QtGui.QComboBox()
        self.edge.addItems(list(EDGE_MODES))
        self.edge.setCurrentIndex(list(EDGE_MODES).index(obj.Edge))
        self.show = QtGui.QComboBox()
        self.show.addItems(["determined", "random", "deviation"])
        self.status = QtGui.QLabel("")
        self.status.setWordWrap(True)
        lay.addRow(translate("SurfComp", "Mask size"), self.mask)
        lay.addRow(translate("SurfComp", "Weights"), self.weights)
        lay.addRow(translate("SurfComp", "Edge handling"), self.edge)
        lay.addRow(translate("SurfComp", "Show map"), self.show)
        lay.addRow(self.status)
        self.timer = QtCore.QTimer()
        self.timer.setSingleShot(True)
        self.timer.setInterval(300)
        self.timer.timeout.connect(self.update)
        self.mask.valueChanged.connect(self.timer.start)
        self.weights.editingFinished.connect(self.timer.start)
        self.edge.currentIndexChanged.connect(self.timer.start)
        self.show.currentIndexChanged.connect(self.show_map)
        self.step = UndoStep(self.doc, translate("SurfComp", "Filter %s") % obj.Label).open()
        vobj = obj.ViewObject
        if vobj is not None and "Map" in vobj.PropertiesList:
            vobj.DisplayMode = "Map"
        self.show_map()

    def values(self):
        return {"MaskSize": int(self.mask.value()), "Weights": self.weights.text().strip(),
                "Edge": self.edge.currentText()}

    def show_map(self, *_args):
        vobj = self.obj.ViewObject
        if vobj is not None and "Map" in vobj.PropertiesList:
            vobj.Map = self.show.currentText()

    def update(self):
        """Apply the panel's values and recompute (live preview inside the transaction)."""
        self.timer.stop()
        if getattr(self, "_busy", False):
            return False
        self._busy = True
        try:
            return self._update()
        finally:
            self._busy = False

    def _update(self):
        for name, value in self.values().items():
            if getattr(self.obj, name) != value:
                setattr(self.obj, name, value)
        if not self.obj.Preview:  # live maps without rebuilding the face on every change
            self.obj.Preview = True
        self.doc.recompute()
        return self._show_state()

    def _show_state(self):
        bad = "Invalid" in self.obj.State or "Error" in self.obj.State
        message = self.obj.getStatusString() if bad else ""
        self.status.setText(message)
        self.status.setStyleSheet("color: #c53030;" if bad else "")
        return not bad

    def accept(self):
        self.timer.stop()
        applied = all(getattr(self.obj, k) == v for k, v in self.values().items())
        if applied and not self._show_state():
            return False        # these values already failed: keep the panel open
        self.obj.Preview = False  # the final recompute builds the corrected face
        lines = ["obj = App.getDocument(%r).getObject(%r)" % (self.doc.Name, self.obj.Name)]
        lines += ["obj.%s = %r" % (k, v) for k, v in self.values().items()]
        lines.append("App.getDocument(%r).recompute()" % self.doc.Name)
        for line in lines:
            FreeCADGui.doCommand(line)
        if not self._show_state():
            return False
        self.step.commit()
        self._close()
        return True

    def reject(self):
        self.timer.stop()
        self.step.abort()
        self._close()
        vobj = self.obj.ViewObject
        if vobj is not None and vobj.Proxy is not None and hasattr(vobj.Proxy, "redraw"):
            vobj.Proxy._data = {}
            vobj.Proxy.redraw()
        return True

    def _close(self):
        FilterPanel.instance = None
        FreeCADGui.Control.closeDialog()
        if FreeCADGui.ActiveDocument is not None:
            FreeCADGui.ActiveDocument.resetEdit()

    def getStandardButtons(self):
        buttons = QtGui.QDialogButtonBox.Ok | QtGui.QDialogButtonBox.Cancel
        # Qt5 flags convert with int(); Qt6 (PySide6) flags are Python enums with .value
        return buttons.value if hasattr(buttons, "value") else int(buttons)
