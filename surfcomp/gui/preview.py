# SPDX-License-Identifier: LGPL-2.1-or-later
"""The import preview: what a measurement file holds, before anything enters the document.

Sample rows, the value ranges in the unit chosen for columns without a unit of their own,
a unit selector that reads the file again, and the plausibility checks of
:mod:`surfcomp.core.plausibility` (the same as the command line's): a deviation larger than
the max offset is an error that keeps OK disabled; deviations all far beyond the face's
size tolerance are a warning.
"""

import FreeCAD
import FreeCADGui
from PySide import QtGui

from ..core import plausibility
from ..errors import SurfcompError
from ..io.units import UNIT_FACTORS
from . import prefs

translate = FreeCAD.Qt.translate

#: rows of the file shown in the preview
SAMPLE_ROWS = 6
UNIT_CHOICES = prefs.FILE_UNIT_CHOICES


def _unit_text(unit):
    return "µm" if unit == "um" else unit


def _fmt(value_mm, unit):
    return "%.4g" % (value_mm / UNIT_FACTORS[unit])


def checks(ms, max_offset=plausibility.DEFAULT_MAX_OFFSET):
    """``(errors, warnings)`` of a measurement set: the plausibility checks (lists of str)."""
    errors, warnings = [], []
    if ms.deviation is not None:
        errors = plausibility.offset_errors(ms.deviation, ms.lines, max_offset, ms.source)
        base = ms.nominal if ms.nominal is not None else ms.measured
        size = plausibility.largest_dimension(base) if base is not None else 0.0
        message = plausibility.units_warning(ms.deviation, size)
        if message:
            warnings.append(message.replace("of the face", "of the face (taken as the "
                                            "points' largest extent)"))
    return errors, warnings


def preview_text(ms, unit=None, max_offset=plausibility.DEFAULT_MAX_OFFSET):
    """What the import preview says about a measurement set (plain text)."""
    unit = unit or ms.units or "mm"
    u = _unit_text(unit)
    lines = [translate("SurfComp", "File: %s") % ms.source,
             translate("SurfComp", "Points: %d") % len(ms),
             translate("SurfComp", "Columns: %s") % ms.kind(),
             translate("SurfComp", "Unit of columns without a unit: %s (stored in mm)") % u]
    if ms.columns:
        lines.append(translate("SurfComp", "Detected columns: %s") % ", ".join(
            "%s=%s" % (k, v) for k, v in ms.columns.items()))
    if ms.ignored_columns:
        lines.append(translate("SurfComp", "Ignored columns: %s") % ", ".join(ms.ignored_columns))
    if ms.row is not None and ms.col is not None:
        lines.append(translate("SurfComp", "Grid: %d x %d (from row/col indices)")
                     % (int(ms.row.max()) + 1, int(ms.col.max()) + 1))
    else:
        lines.append(translate("SurfComp", "Grid: detected on the face when the map is made"))
    lines += [""] + _ranges(ms, unit) + [""] + _samples(ms, unit) + [""]
    errors, warnings = checks(ms, max_offset)
    problems = list(ms.warnings or []) + warnings
    if errors:
        lines.append(translate("SurfComp", "ERRORS (%d): the file cannot be used as it is")
                     % len(errors))
        lines += ["  " + e for e in errors]
    if problems:
        lines.append(translate("SurfComp", "Problems found (%d):") % len(problems))
        lines += ["  " + w for w in problems[:50]]
    elif not errors:
        lines.append(translate("SurfComp", "Problems found: none"))
    return "\n".join(lines)


def _ranges(ms, unit):
    cols = {}
    for name, arr in (("nominal", ms.nominal), ("measured", ms.measured)):
        if arr is not None:
            for k, axis in enumerate("xyz"):
                cols["%s %s" % (name, axis)] = arr[:, k]
    cols["deviation"] = ms.deviation
    ranges = plausibility.value_ranges(cols)
    out = [translate("SurfComp", "Value ranges (%s):") % _unit_text(unit)]
    for name, (lo, hi) in ranges.items():
        out.append("  %-11s %12s .. %-12s" % (name, _fmt(lo, unit), _fmt(hi, unit)))
    if "deviation" in ranges and unit != "mm":
        lo, hi = ranges["deviation"]
        out.append("  %-11s %12s .. %-12s (mm)" % ("", "%.4g" % lo, "%.4g" % hi))
    return out


def _samples(ms, unit):
    n = min(SAMPLE_ROWS, len(ms))
    head = ["line", "id"]
    cols = []
    for name, arr in (("nom", ms.nominal), ("meas", ms.measured)):
        if arr is not None:
            for k, axis in enumerate("xyz"):
                head.append("%s_%s" % (axis, name))
                cols.append(arr[:, k])
    if ms.deviation is not None:
        head.append("dev")
        cols.append(ms.deviation)
    out = [translate("SurfComp", "First %d rows (%s):") % (n, _unit_text(unit)),
           "  " + " ".join("%10s" % h for h in head)]
    for i in range(n):
        row = [str(int(ms.lines[i])) if ms.lines is not None else str(i + 1),
               ms.ids[i] if ms.ids else "-"]
        row += [_fmt(c[i], unit) for c in cols]
        out.append("  " + " ".join("%10s" % r for r in row))
    return out


class PreviewDialog(QtGui.QDialog):
    """Shows what a measurement file holds before anything is added to the document.

    ``reader(units)`` reads the file (again) with the units of columns that have none;
    the unit selector calls it. OK stays disabled while the file has errors.
    """

    def __init__(self, ms, reader=None, parent=None):
        super().__init__(parent or FreeCADGui.getMainWindow())
        self.setWindowTitle(translate("SurfComp", "Import measurements: preview"))
        self.reader = reader
        self.ms = ms
        lay = QtGui.QVBoxLayout(self)
        row = QtGui.QHBoxLayout()
        row.addWidget(QtGui.QLabel(translate("SurfComp", "Unit of columns without a unit:")))
        self.unit = QtGui.QComboBox()
        self.unit.addItems([_unit_text(u) for u in UNIT_CHOICES])
        self.unit.setCurrentIndex(UNIT_CHOICES.index(ms.units if ms.units in UNIT_CHOICES
                                                     else "mm"))
        self.unit.setToolTip(translate("SurfComp", "The file is read again with this unit; "
                                                   "columns named with a unit keep theirs"))
        self.unit.setEnabled(reader is not None)
        row.addWidget(self.unit)
        row.addStretch(1)
        lay.addLayout(row)
        self.status = QtGui.QLabel("")
        self.status.setWordWrap(True)
        lay.addWidget(self.status)
        self.text = QtGui.QPlainTextEdit()
        self.text.setReadOnly(True)
        self.text.setMinimumSize(720, 360)
        font = QtGui.QFont("Monospace")
        font.setStyleHint(QtGui.QFont.TypeWriter)
        self.text.setFont(font)
        lay.addWidget(self.text)
        self.buttons = QtGui.QDialogButtonBox(QtGui.QDialogButtonBox.Ok |
                                              QtGui.QDialogButtonBox.Cancel)
        self.buttons.accepted.connect(self.accept)
        self.buttons.rejected.connect(self.reject)
        lay.addWidget(self.buttons)
        self.unit.currentIndexChanged.connect(self.reread)
        self.show_set(ms)

    def units(self):
        return UNIT_CHOICES[self.unit.currentIndex()]

    def reread(self, *_args):
        try:
            self.show_set(self.reader(self.units()))
        except SurfcompError as exc:
            self.ms = None
            self.text.setPlainText(str(exc))
            self._state([str(exc)])

    def show_set(self, ms):
        self.ms = ms
        self.text.setPlainText(preview_text(ms, self.units()))
        self._state(checks(ms)[0])

    def _state(self, errors):
        ok = self.buttons.button(QtGui.QDialogButtonBox.Ok)
        ok.setEnabled(not errors)
        if errors:
            self.status.setText(translate("SurfComp", "Cannot import: %s") % errors[0])
            self.status.setStyleSheet("color: #c53030; font-weight: bold;")
        else:
            self.status.setText(translate("SurfComp", "%d points, no errors") % len(self.ms))
            self.status.setStyleSheet("")

    def accept(self):
        if self.ms is None or checks(self.ms)[0]:
            return      # errors: OK does nothing (also when called by a script)
        super().accept()

    def accepted_ok(self):
        """True when the dialog may be accepted (no errors)."""
        return self.buttons.button(QtGui.QDialogButtonBox.Ok).isEnabled()
