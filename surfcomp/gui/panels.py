# SPDX-License-Identifier: LGPL-2.1-or-later
"""Task panels and dialogs of the workbench: filter panel, report (the import preview is
in :mod:`surfcomp.gui.preview`).

No numerics: the filter panel edits the compensation's properties and recomputes it, the
report shows the statistics the compensation stored.
"""

import json

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui
from PySide.QtCore import QT_TRANSLATE_NOOP

from ..app import reports
from ..app.undo import UndoStep
from ..core import colormap
from ..core.compensation import plausibility
from ..core.compensation.deviations import Statistics, cell_text, format_table
from ..core.options import OPTIONS, tooltip
from ..errors import SurfcompError
from . import dialogs, option_labels, prefs
from .task_panel import ok_cancel_buttons

translate = FreeCAD.Qt.translate

#: order of the report's columns (the papers' Tables 1-5)
REPORT_COLUMNS = (("deviation", "Deviation"), ("determined", "Determined"),
                  ("random", "Random"), ("increment", "Increment"),
                  ("correction", "Correction"))


def statistics_columns(obj):
    """``[(header, Statistics)]`` of a computed compensation, in report order."""
    data = json.loads(obj.Statistics or "{}")
    return [(head, Statistics.from_dict(data[key])) for key, head in REPORT_COLUMNS if key in data]


def map_style(obj):
    """Scheme and range of the object's map, for the HTML report: the range when the map
    has a manual or shared one, else None (each map on its own symmetric range, as the
    GUI's automatic range)."""
    vobj = obj.ViewObject
    if vobj is None or "Scheme" not in vobj.PropertiesList:
        return None
    proxy = getattr(vobj, "Proxy", None)
    scene = getattr(proxy, "scene", None)
    fixed = not vobj.AutoRange or vobj.Shared
    rng = tuple(scene.range) if fixed and scene is not None and scene.range else None
    return {"scheme": vobj.Scheme, "range": rng}


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
        for j, (_, st) in enumerate(cols):
            for i, (_label, value) in enumerate(st.rows(self.unit)):
                item = QtGui.QTableWidgetItem(cell_text(value, i, self.unit))
                item.setTextAlignment(QtCore.Qt.AlignRight | QtCore.Qt.AlignVCenter)
                self.table.setItem(i, j, item)
        self.table.resizeColumnsToContents()
        lay = QtGui.QVBoxLayout(self)
        lay.addWidget(QtGui.QLabel(translate("SurfComp", "Deviations in %s")
                                   % colormap.UNIT_TEXT[self.unit]))
        lay.addWidget(self.table)
        assumes = plausibility.residual_assumption(obj.Method, float(obj.Stock.Value))
        self.assumes = QtGui.QLabel(translate("SurfComp", "Predicted residual: %s.") % assumes
                                    if assumes else "")
        self.assumes.setWordWrap(True)
        lay.addWidget(self.assumes)
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
            reports.write_html_report(self.obj, path, style=map_style(self.obj))
        except SurfcompError as exc:
            dialogs.show_error(translate("SurfComp", "Report"), str(exc))
            return None
        return path


def _choices(name, current):
    """A combo box of option ``name``'s choices (the option registry), ``current`` chosen,
    with the property's tooltip."""
    box = QtGui.QComboBox()
    box.addItems(list(OPTIONS[name].choices))
    box.setCurrentIndex(list(OPTIONS[name].choices).index(current))
    box.setToolTip(translate("App::Property", tooltip(name)))
    return box


class FilterPanel:
    """Task panel: mask size, kind, weights, edge handling, with live maps of the
    determined and random components and their RMS. Every change is checked first (no
    failed recompute), then recomputed as a preview (the compensation alone, refiltering
    the points it located before) and redrawn as soon as the queued events are handled.
    The weights, when given, set the mask size. OK keeps the change (one undo step),
    Cancel reverts it."""

    #: the open panel (None when closed), for scripts and tests
    instance = None
    #: delay of the live preview after a change (ms). None: the update runs as soon as
    #: the events already queued are handled, so the keys of one burst (a paste, a held
    #: arrow key's repeats) and those typed while an update runs are taken together by one
    #: update; the map should follow a key within 0.3 s (issue 24), and a fixed delay would
    #: spend a large part of that (bench/bench_filter_panel.py measures it)
    DEBOUNCE = 0

    def __init__(self, obj):
        FilterPanel.instance = self
        self.obj = obj
        self.doc = obj.Document
        self.form = QtGui.QWidget()
        self.form.setWindowTitle(translate("SurfComp", "Filter"))
        lay = QtGui.QFormLayout(self.form)
        size = OPTIONS["mask_size"]
        self.mask = QtGui.QSpinBox()
        self.mask.setRange(size.low, size.high)
        self.mask.setSingleStep(2)
        self.mask.setValue(int(obj.MaskSize))
        self.kind = _choices("mask_kind", obj.MaskKind)
        self.weights = QtGui.QLineEdit(obj.Weights)
        self.weights.setPlaceholderText(translate("SurfComp", "e.g. 1 2 1; 2 4 2; 1 2 1"))
        self.edge = _choices("edge", obj.Edge)
        for widget, name in ((self.mask, "mask_size"), (self.weights, "weights")):
            widget.setToolTip(translate("App::Property", tooltip(name)))
        self.show = QtGui.QComboBox()
        self.show.addItems(["determined", "random", "deviation", "residual"])
        self.status = QtGui.QLabel("")
        self.status.setWordWrap(True)
        self.figures = QtGui.QLabel("")
        self.figures.setWordWrap(True)
        self.figures.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
        for name, field in (("mask_size", self.mask), ("mask_kind", self.kind),
                            ("weights", self.weights), ("edge", self.edge)):
            lay.addRow(option_labels.label(name), field)    # the names messages show
        lay.addRow(translate("SurfComp", "Show map"), self.show)
        lay.addRow(self.figures)
        lay.addRow(self.status)
        self.timer = QtCore.QTimer()
        self.timer.setSingleShot(True)
        self.timer.setInterval(self.DEBOUNCE)
        self.timer.timeout.connect(self.update)
        self.mask.valueChanged.connect(self.changed)
        self.kind.currentIndexChanged.connect(self.changed)
        self.weights.textChanged.connect(self.changed)
        self.edge.currentIndexChanged.connect(self.changed)
        self.show.currentIndexChanged.connect(self.show_map)
        # Cancel leaves the objects touched before as they were (marked for a recompute)
        self.touched = {o.Name for o in self.doc.Objects if "Touched" in o.State}
        self.step = UndoStep(self.doc, translate("SurfComp", "Filter %s") % obj.Label).open()
        vobj = obj.ViewObject
        if vobj is not None and "Map" in vobj.PropertiesList:
            vobj.DisplayMode = "Map"
        self._sync_mask()
        self.show_map()
        self._show_figures()

    def values(self):
        return {"MaskSize": int(self.mask.value()), "Weights": self.weights.text().strip(),
                "MaskKind": self.kind.currentText(), "Edge": self.edge.currentText()}

    def changed(self, *_args):
        """A field changed: check it now, recompute after the debounce."""
        if self._sync_mask():
            self.timer.start()
        else:
            self.timer.stop()

    def _sync_mask(self):
        """Check the values; weights set the size (the spin box follows, disabled).
        Returns False (message shown) when they are not valid."""
        from ..app.features import check_filter

        custom = bool(self.weights.text().strip())
        self.mask.setEnabled(not custom)
        self.kind.setEnabled(not custom)
        try:
            size = check_filter(self.obj, **self.values())
        except SurfcompError as exc:
            self._message(option_labels.shown(exc), bad=True)
            return False
        if custom and size != self.mask.value():
            self.mask.blockSignals(True)
            self.mask.setValue(size)
            self.mask.blockSignals(False)
        self._message("")
        return True

    def show_map(self, *_args):
        vobj = self.obj.ViewObject
        if vobj is not None and "Map" in vobj.PropertiesList:
            vobj.Map = self.show.currentText()

    def update(self):
        """Apply the panel's values and recompute (live preview inside the transaction);
        redraw the map at once. False when the values are not valid. Called again while
        it runs (events processed during a recompute), it updates once more afterwards."""
        self.timer.stop()
        if getattr(self, "_busy", False):
            self._again = True
            return False
        self._busy = True
        try:
            return self._update()
        finally:
            self._busy = False
            if getattr(self, "_again", False):
                self._again = False
                self.timer.start()

    def _update(self):
        if not self._sync_mask():
            return False
        for name, value in self.values().items():
            if getattr(self.obj, name) != value:
                setattr(self.obj, name, value)
        if not self.obj.Preview:  # live maps without rebuilding the face on every change
            self.obj.Preview = True
        # the compensation alone: a preview leaves its Shape as it is, so what uses the
        # face (a Path job after Replace) has nothing to recompute until OK
        if "Touched" in self.obj.State:
            self.obj.recompute()
        ok = self._show_state()
        proxy = getattr(self.obj.ViewObject, "Proxy", None)
        if ok and getattr(proxy, "_dirty", False):
            proxy.redraw()      # drawn now, not after the next event loop round
        self._show_figures()
        # ask the 3D view to paint now: left to Coin's idle sensors, a repaint after a key
        # sometimes waited for the next input event (FreeCAD 1.1)
        view = getattr(FreeCADGui.getDocument(self.doc.Name), "ActiveView", None)
        if ok and hasattr(view, "redraw"):
            view.redraw()
        return ok

    def _show_figures(self):
        try:
            fig = reports.filter_summary(self.obj)
        except SurfcompError:
            self.figures.setText("")
            return
        um = 1000.0
        self.figures.setText(translate(
            "SurfComp", "RMS  deviation %.2f µm, determined %.2f µm, random %.2f µm.\n"
                        "Predicted residual %.2f µm RMS; next part %.2f µm RMS "
                        "(residual + a new random scatter).")
            % (fig["deviation"] * um, fig["determined"] * um, fig["random"] * um,
               fig["residual"] * um, fig["next_part"] * um))

    def _message(self, text, bad=False):
        self.status.setText(text)
        self.status.setStyleSheet("color: #c53030;" if bad else "")

    def _show_state(self):
        bad = "Invalid" in self.obj.State or "Error" in self.obj.State
        self._message(self.obj.getStatusString() if bad else "", bad)
        return not bad

    def accept(self):
        self.timer.stop()
        if not self._sync_mask():
            return False        # not valid: keep the panel open with the message
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
        from ..app.recompute import settle_after_undo

        self.timer.stop()
        self.step.abort()
        # the undo put back every property the previews wrote: nothing is left to recompute
        settle_after_undo(self.doc, self.touched)
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
        return ok_cancel_buttons()


STOCK_TIP = QT_TRANSLATE_NOOP(
    "SurfComp",
    "Stock = the semi-finishing allowance: the part is measured after a semi-finishing pass "
    "programmed this far outside the nominal, so every measured deviation d carries it. The "
    "mirror method moves the face by -(d - stock): a point measured exactly at the stock "
    "stays; one with more material left moves inwards (Huang et al., mirror compensation, "
    "eq. 1-2).")


class StockDrawing(QtGui.QWidget):
    """The mirror method in one picture: nominal, semi-finished surface (nominal + stock),
    measured surface (nominal + d) and the corrected face (nominal - (d - stock))."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setMinimumSize(360, 190)
        self.stock = 0.1

    def _curves(self):
        """``[(offset(t), colour, label, dashed)]``: t in [0, 1] along the face, the offset
        in units of the stock."""
        import math

        s = 1.0

        def d(t):
            return s + 0.45 * math.sin(6.0 * t)          # measured: stock + machining error

        return [(lambda t: 0.0, (0, 0, 0), translate("SurfComp", "nominal"), False),
                (lambda t: s, (120, 120, 120), translate("SurfComp", "nominal + stock"), True),
                (d, (43, 108, 176), translate("SurfComp", "measured (d)"), False),
                (lambda t: -(d(t) - s), (197, 48, 48), translate("SurfComp", "corrected face"),
                 False)]

    def _line(self, offset):
        w, h = self.width(), self.height()
        y0, scale = 0.62 * h, 0.22 * h      # nominal line; 1 unit of stock in pixels
        return [QtCore.QPointF(x, y0 - scale * offset(x / w)) for x in range(10, w - 110, 4)]

    def label_places(self):
        """Each curve's label and its baseline ``(text, x, y)`` at the curve's right end,
        pushed apart by a line where the curves end close together (there "measured (d)"
        and "corrected face" were drawn over each other)."""
        spacing = self.fontMetrics().lineSpacing()
        ends = sorted((self._line(offset)[-1].y() + 4, label)
                      for offset, _colour, label, _dash in self._curves())
        places, last = [], None
        for y, label in ends:
            y = y if last is None else max(y, last + spacing)
            places.append((label, self.width() - 105, y))
            last = y
        return places

    def paintEvent(self, _event):
        p = QtGui.QPainter(self)
        p.setRenderHint(QtGui.QPainter.Antialiasing)
        p.fillRect(self.rect(), QtGui.QColor(255, 255, 255))
        at = {label: (x, y) for label, x, y in self.label_places()}
        for offset, colour, label, dash in self._curves():
            pen = QtGui.QPen(QtGui.QColor(*colour), 2)
            if dash:
                pen.setStyle(QtCore.Qt.DashLine)
            p.setPen(pen)
            pts = self._line(offset)
            for a, b in zip(pts[:-1], pts[1:]):
                p.drawLine(a, b)
            p.drawText(QtCore.QPointF(*at[label]), label)
        p.setPen(QtGui.QColor(0, 0, 0))
        p.drawText(QtCore.QPointF(8, 16), translate("SurfComp", "corrected = nominal - (d - "
                                                                "stock) along the normal"))
        p.end()


class StockDialog(QtGui.QDialog):
    """The mirror method's stock, explained: tooltip, text and drawing; checked against
    the measured deviations (:func:`surfcomp.core.compensation.plausibility.stock_check`). OK
    refuses an inconsistent stock, showing the measured mean, and offers a button that confirms
    it; :meth:`answer` is ``(stock, confirmed)``."""

    def __init__(self, title, value, deviation=None, parent=None):
        super().__init__(parent or FreeCADGui.getMainWindow())
        self.setWindowTitle(title)
        self.deviation = deviation
        self.confirmed = False
        lay = QtGui.QVBoxLayout(self)
        text = QtGui.QLabel(translate("SurfComp", STOCK_TIP))
        text.setWordWrap(True)
        lay.addWidget(text)
        self.drawing = StockDrawing()
        lay.addWidget(self.drawing)
        row = QtGui.QFormLayout()
        self.spin = QtGui.QDoubleSpinBox()
        self.spin.setDecimals(4)
        self.spin.setRange(OPTIONS["stock"].low, OPTIONS["stock"].high)
        self.spin.setSingleStep(0.05)
        self.spin.setSuffix(" mm")
        self.spin.setValue(float(value))
        self.spin.setToolTip(translate("SurfComp", STOCK_TIP))
        row.addRow(translate("SurfComp", "Stock (semi-finishing allowance)"), self.spin)
        lay.addLayout(row)
        self.check_text = QtGui.QLabel("")
        self.check_text.setWordWrap(True)
        lay.addWidget(self.check_text)
        box = QtGui.QDialogButtonBox(QtGui.QDialogButtonBox.Ok | QtGui.QDialogButtonBox.Cancel)
        self.confirm = box.addButton(translate("SurfComp", "Use this stock anyway"),
                                     QtGui.QDialogButtonBox.ActionRole)
        self.confirm.setVisible(False)
        self.confirm.clicked.connect(self.accept_anyway)
        box.accepted.connect(self.accept)
        box.rejected.connect(self.reject)
        self.buttons = box
        lay.addWidget(box)
        self.spin.valueChanged.connect(self.show_check)
        self.show_check()

    def value(self):
        return float(self.spin.value())

    def check(self):
        """The stock check of the current value, or None without deviations."""
        if self.deviation is None:
            return None
        return plausibility.stock_check(self.deviation, self.value())

    def show_check(self, *_args, refused=False):
        """The measured mean against the stock under the spin box; a new value withdraws
        the confirmation button."""
        self.confirm.setVisible(refused)
        c = self.check()
        if c is None:
            self.check_text.setText("")
            return
        if refused:
            head = translate("SurfComp", "Refused: the stock does not fit the measured "
                                         "deviations.")
        elif c.consistent:
            head = translate("SurfComp", "The stock fits the measured deviations.")
        else:
            head = translate("SurfComp", "The stock does not fit the measured deviations.")
        what = c.describe().replace("um", "µm").replace("+-", "±")
        self.check_text.setText("%s %s%s." % (head, what[0].upper(), what[1:]))
        self.check_text.setStyleSheet("" if c.consistent else "color: #c53030;%s"
                                      % (" font-weight: bold;" if refused else ""))

    def accept(self):
        """OK: an inconsistent stock is refused (the dialog stays, the confirmation button
        appears)."""
        c = self.check()
        if c is not None and not c.consistent and not self.confirmed:
            self.show_check(refused=True)
            return
        super().accept()

    def accept_anyway(self):
        self.confirmed = True
        super().accept()

    def answer(self):
        """``(stock in mm, confirmed)``: confirmed is True when the user chose a stock
        that does not fit the measured mean."""
        c = self.check()
        return self.value(), bool(self.confirmed and c is not None and not c.consistent)
