# SPDX-License-Identifier: LGPL-2.1-or-later
"""The import preview: what a measurement file holds, before anything enters the document.

Sample rows, the value ranges in the units chosen for columns without a unit of their own
(one selector for the coordinates, one for the deviation column; each reads the file
again), and the plausibility checks of :mod:`surfcomp.core.compensation.plausibility` (the same as
the command line's): a deviation larger than the max offset is an error that keeps OK
disabled; deviations all far beyond the face's size tolerance are a warning. With a
nominal face at hand the points are also located on it as the deviation map will locate
them (:mod:`surfcomp.app.precheck`): points off the face, beyond its border or farther
than the max offset are errors here, before anything enters the document.
"""

import FreeCAD
import FreeCADGui
from PySide import QtGui

from ..core.compensation import plausibility
from ..errors import SurfcompError
from ..io.units import UNIT_FACTORS
from . import option_labels, prefs
from .result_box import result_box, show_message

translate = FreeCAD.Qt.translate

#: rows of the file shown in the preview
SAMPLE_ROWS = 6
UNIT_CHOICES = prefs.FILE_UNIT_CHOICES


def _unit_text(unit):
    return "µm" if unit == "um" else unit


def _fmt(value_mm, unit):
    return "%.4g" % (value_mm / UNIT_FACTORS[unit])


def checks(ms, max_offset=plausibility.DEFAULT_MAX_OFFSET, face=None):
    """``(errors, warnings)`` of a measurement set: the plausibility checks (lists of str),
    and, with ``face`` (a callable ``face(ms) -> (errors, warnings)``), the points located
    on the nominal face as the deviation map will locate them."""
    errors, warnings = [], []
    if ms.deviation is not None:
        errors = plausibility.offset_errors(ms.deviation, ms.lines, max_offset, ms.source)
        base = ms.nominal if ms.nominal is not None else ms.measured
        size = plausibility.largest_dimension(base) if base is not None else 0.0
        message = plausibility.units_warning(ms.deviation, size)
        if message and face is None:        # the face's own size is checked below
            warnings.append(message.replace("of the face", "of the face (taken as the "
                                            "points' largest extent)"))
    if face is not None and not errors:
        on_face, notes = face(ms)
        errors += on_face
        warnings += notes
    return errors, warnings


def preview_text(ms, unit=None, max_offset=plausibility.DEFAULT_MAX_OFFSET, dev_unit=None,
                 face=None, face_name=""):
    """What the import preview says about a measurement set (plain text); ``unit`` is the
    coordinates' unit, ``dev_unit`` the deviations' (default the same); ``face`` and
    ``face_name`` as :func:`checks` (the nominal face the points are checked against)."""
    unit = unit or ms.units or "mm"
    dev_unit = dev_unit or unit
    lines = [translate("SurfComp", "File: %s") % ms.source,
             translate("SurfComp", "Points: %d") % len(ms),
             translate("SurfComp", "Columns: %s") % ms.kind(),
             translate("SurfComp", "Unit of columns without a unit: coordinates %s, deviation "
                                   "%s (stored in mm)") % (_unit_text(unit),
                                                           _unit_text(dev_unit))]
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
    lines.append(translate("SurfComp", "Checked against the nominal face: %s") % face_name
                 if face is not None else
                 translate("SurfComp", "No nominal face to check the points against (select "
                                       "it): they are checked when the map is made"))
    lines += [""] + _ranges(ms, unit, dev_unit) + [""] + _samples(ms, unit, dev_unit) + [""]
    errors, warnings = checks(ms, max_offset, face)
    problems = list(ms.warnings or []) + warnings
    if errors:
        lines.append(translate("SurfComp", "ERRORS (%d): the file cannot be used as it is")
                     % len(errors))
        lines += ["  " + e for e in errors]
    if problems:
        lines.append(translate("SurfComp", "Problems found (%d):") % len(problems))
        lines += ["  " + option_labels.shown(w) for w in problems[:50]]
    elif not errors:
        lines.append(translate("SurfComp", "Problems found: none"))
    return "\n".join(lines)


def _ranges(ms, unit, dev_unit):
    cols = {}
    for name, arr in (("nominal", ms.nominal), ("measured", ms.measured)):
        if arr is not None:
            for k, axis in enumerate("xyz"):
                cols["%s %s" % (name, axis)] = arr[:, k]
    cols["deviation"] = ms.deviation
    ranges = plausibility.value_ranges(cols)
    out = [translate("SurfComp", "Value ranges (coordinates in %s, deviation in %s):")
           % (_unit_text(unit), _unit_text(dev_unit))]
    for name, (lo, hi) in ranges.items():
        u = dev_unit if name == "deviation" else unit
        out.append("  %-11s %12s .. %-12s %s" % (name, _fmt(lo, u), _fmt(hi, u), _unit_text(u)))
    if "deviation" in ranges and dev_unit != "mm":
        lo, hi = ranges["deviation"]
        out.append("  %-11s %12s .. %-12s mm" % ("", "%.4g" % lo, "%.4g" % hi))
    return out


def _samples(ms, unit, dev_unit):
    n = min(SAMPLE_ROWS, len(ms))
    head = ["line", "id"]
    cols = []
    for name, arr in (("nom", ms.nominal), ("meas", ms.measured)):
        if arr is not None:
            for k, axis in enumerate("xyz"):
                head.append("%s_%s" % (axis, name))
                cols.append((arr[:, k], unit))
    if ms.deviation is not None:
        head.append("dev")
        cols.append((ms.deviation, dev_unit))
    out = [translate("SurfComp", "First %d rows (coordinates in %s, deviation in %s):")
           % (n, _unit_text(unit), _unit_text(dev_unit)),
           "  " + " ".join("%10s" % h for h in head)]
    for i in range(n):
        row = [str(int(ms.lines[i])) if ms.lines is not None else str(i + 1),
               ms.ids[i] if ms.ids else "-"]
        row += [_fmt(c[i], u) for c, u in cols]
        out.append("  " + " ".join("%10s" % r for r in row))
    return out


class PreviewDialog(QtGui.QDialog):
    """Shows what a measurement file holds before anything is added to the document.

    ``reader(units, deviation_units)`` reads the file (again) with the units of columns
    that have none: one selector for the coordinates, one for the deviation column. With
    ``face`` (``face(ms) -> (errors, warnings)``, see :func:`checks`) the points are
    located on the nominal face ``face_name`` with the chosen coordinate unit. OK stays
    disabled while the file has errors.
    """

    def __init__(self, ms, reader=None, parent=None, face=None, face_name=""):
        super().__init__(parent or FreeCADGui.getMainWindow())
        self.setWindowTitle(translate("SurfComp", "Import measurements: preview"))
        self.reader = reader
        self.face, self.face_name = face, face_name
        self.ms = ms
        self.errors = []
        lay = QtGui.QVBoxLayout(self)
        row = QtGui.QFormLayout()
        start = UNIT_CHOICES.index(ms.units if ms.units in UNIT_CHOICES else "mm")
        self.coord_unit = self._selector(start, translate(
            "SurfComp", "Unit of x, y, z columns without a unit of their own (nominal and "
                        "measured points); the points are checked against the nominal face "
                        "with it"))
        row.addRow(option_labels.label("units") + ":", self.coord_unit)
        self.unit = self._selector(start, translate(
            "SurfComp", "Unit of the deviation column when it has none of its own (a "
                        "deviation computed from the points keeps theirs)"))
        row.addRow(option_labels.label("deviation_units") + ":", self.unit)
        lay.addLayout(row)
        # the dialog keeps the size it was shown at: an error of three lines in a label
        # pushed the preview under the buttons
        self.status = result_box(3)
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
        self.coord_unit.currentIndexChanged.connect(self.reread)
        self.unit.currentIndexChanged.connect(self.reread)
        self.show_set(ms)

    def _selector(self, index, tip):
        box = QtGui.QComboBox()
        box.addItems([_unit_text(u) for u in UNIT_CHOICES])
        box.setCurrentIndex(index)
        box.setToolTip(tip + translate("SurfComp", "; the file is read again"))
        box.setEnabled(self.reader is not None)
        return box

    def units(self):
        """The coordinates' unit (``mm``, ``um``, ``in``)."""
        return UNIT_CHOICES[self.coord_unit.currentIndex()]

    def deviation_units(self):
        """The deviation column's unit (``mm``, ``um``, ``in``)."""
        return UNIT_CHOICES[self.unit.currentIndex()]

    def reread(self, *_args):
        try:
            self.show_set(self.reader(self.units(), self.deviation_units()))
        except SurfcompError as exc:
            self.ms = None
            self.text.setPlainText(option_labels.shown(exc))
            self._state([option_labels.shown(exc)])

    def show_set(self, ms):
        self.ms = ms
        face = None
        if self.face is not None:
            found = self.face(ms)           # located once per reading

            def face(_ms):
                return found
        self.text.setPlainText(preview_text(ms, self.units(), dev_unit=self.deviation_units(),
                                            face=face, face_name=self.face_name))
        self._state(checks(ms, face=face)[0])

    def _state(self, errors):
        self.errors = list(errors)
        ok = self.buttons.button(QtGui.QDialogButtonBox.Ok)
        ok.setEnabled(not errors)
        if errors:
            show_message(self.status, translate("SurfComp", "Cannot import: %s") % errors[0],
                         bad=True, bold=True)
        else:
            show_message(self.status, translate("SurfComp", "%d points, no errors")
                         % len(self.ms))

    def accept(self):
        if self.ms is None or self.errors:
            return      # errors: OK does nothing (also when called by a script)
        super().accept()

    def accepted_ok(self):
        """True when the dialog may be accepted (no errors)."""
        return self.buttons.button(QtGui.QDialogButtonBox.Ok).isEnabled()
