# SPDX-License-Identifier: LGPL-2.1-or-later
"""Path dressup: compensate the machine's axis errors on every move of a base operation.

A thin proxy in the manner of Path's own dressups (``PathDressupPathBoundary``): the proxy
turns properties into arrays, calls :func:`surfcomp.io.gcode.compensate_commands` (which
uses :mod:`surfcomp.core.axis.axis_errors`, Dobariya 2015 eq. 6-16), and writes ``Path`` and a
few result properties back. No FreeCADGui, no PySide: it recomputes in ``freecadcmd``.

Unlike Path's Z-correct dressup it keeps every parameter of a move (feed rates included,
on every piece of a split move), keeps non-move commands (spindle, tool changes, comments,
planes) in place and applies the compensation exactly once: each programmed point ``X``
becomes the command ``X'`` with ``X' + E(X') = X``.

The error measurements live in the document (float-list properties), not only as a path
to a CSV file: the model is refitted from them on every recompute, so ``Model``,
``Reference`` and ``WorkOffset`` can be changed without the file.

Import this module where FreeCAD is importable: inside FreeCAD, or from a plain ``python3``
after :func:`surfcomp.app.fcenv.import_freecad` (which puts the CAM workbench's ``Path``
package of 1.x on the path too).
"""

import os

import FreeCAD
import numpy as np
import Path

from ..core.axis.axis_errors import AXES, MODEL_CHOICES, fit_axis_errors
from ..core.command_options import GCODE
from ..errors import InputError
from ..io.axis_csv import AxisErrorTable, read_axis_errors
from ..io.gcode import compensate_commands
from . import cam
from .dressups import DressupProxy, check_base, place

#: marks property tooltips for translation (FreeCAD translates them in the "App::Property"
#: context when it shows them)
QT_TRANSLATE_NOOP = FreeCAD.Qt.QT_TRANSLATE_NOOP

#: version of the document object's property set; onDocumentRestored upgrades older ones
VERSION = 1

_GROUP_DATA = "AxisErrors"
_GROUP_COMP = "Compensation"
_GROUP_RESULT = "Result"

#: (type, name, group, tooltip, default, editor mode) of every property
PROPERTIES = (
    ("App::PropertyLink", "Base", "Base",
     QT_TRANSLATE_NOOP("App::Property", "The base path to modify"),
     None, 0),
    ("App::PropertyStringList", "MeasuredAxis", _GROUP_DATA,
     QT_TRANSLATE_NOOP("App::Property", "Moving slide (X, Y or Z) of every measured row"),
     None, 0),
    ("App::PropertyFloatList", "MeasuredPosition", _GROUP_DATA,
     QT_TRANSLATE_NOOP("App::Property", "Position of the moving slide of every row (mm)"),
     None, 0),
    ("App::PropertyFloatList", "MeasuredErrorX", _GROUP_DATA,
     QT_TRANSLATE_NOOP("App::Property", "Tool-position error along X of every row (mm, actual - "
                                        "commanded)"),
     None, 0),
    ("App::PropertyFloatList", "MeasuredErrorY", _GROUP_DATA,
     QT_TRANSLATE_NOOP("App::Property", "Tool-position error along Y of every row (mm, actual - "
                                        "commanded)"),
     None, 0),
    ("App::PropertyFloatList", "MeasuredErrorZ", _GROUP_DATA,
     QT_TRANSLATE_NOOP("App::Property", "Tool-position error along Z of every row (mm, actual - "
                                        "commanded)"),
     None, 0),
    ("App::PropertyString", "SourceFile", _GROUP_DATA,
     QT_TRANSLATE_NOOP("App::Property", "File the measurements were read from (information only: "
                                        "the data is stored above)"),
     "", 1),
    ("App::PropertyEnumeration", "Model", _GROUP_DATA,
     QT_TRANSLATE_NOOP("App::Property", "Degree of the error functions: auto (F-test per "
                                        "function), linear or quadratic"),
     ["auto"] + [m for m in MODEL_CHOICES if m != "auto"], 0),
    ("App::PropertyVector", "Reference", _GROUP_DATA,
     QT_TRANSLATE_NOOP("App::Property", "Where the other slides stood while one slide was measured"
                                        " (measurement coordinates)"),
     None, 0),
    ("App::PropertyVector", "WorkOffset", _GROUP_DATA,
     QT_TRANSLATE_NOOP("App::Property", "Measurement (machine) coordinates of the path's zero"),
     None, 0),
    ("App::PropertyLength", "SegmentLength", _GROUP_COMP,
     QT_TRANSLATE_NOOP("App::Property", "Longest piece of a split G1 move or of an arc turned into"
                                        " G1 segments"),
     GCODE["segment_length"].default, 0),
    ("App::PropertyLength", "Tolerance", _GROUP_COMP,
     QT_TRANSLATE_NOOP("App::Property", "Split a long G1 move only where the compensated path "
                                        "leaves its chord by more"),
     GCODE["tolerance"].default, 0),
    ("App::PropertyLength", "ArcTolerance", _GROUP_COMP,
     QT_TRANSLATE_NOOP("App::Property", "Largest chord-to-arc deviation of arcs turned into G1 "
                                        "segments"),
     GCODE["arc_tolerance"].default, 0),
    ("App::PropertyStringList", "FitSummary", _GROUP_RESULT,
     QT_TRANSLATE_NOOP("App::Property", "Fitted error functions and the 12 components"),
     None, 1),
    ("App::PropertyLength", "ErrorBefore", _GROUP_RESULT,
     QT_TRANSLATE_NOOP("App::Property", "Largest predicted tool-position error of the base path's "
                                        "points"),
     0.0, 1),
    ("App::PropertyLength", "ErrorAfter", _GROUP_RESULT,
     QT_TRANSLATE_NOOP("App::Property", "Largest predicted tool-position error after compensation"),
     0.0, 1),
    ("App::PropertyLength", "MaxCorrection", _GROUP_RESULT,
     QT_TRANSLATE_NOOP("App::Property", "Largest correction applied to a point"),
     0.0, 1),
    ("App::PropertyStringList", "Warnings", _GROUP_RESULT,
     QT_TRANSLATE_NOOP("App::Property", "What the compensation assumed (e.g. axes not yet "
                                        "programmed)"),
     None, 1),
    ("App::PropertyInteger", "Version", "Base",
     QT_TRANSLATE_NOOP("App::Property", "Property set version of this object"),
     VERSION, 2),
)


def set_measurements(obj, source):
    """Store measurements in the object's properties.

    Parameters
    ----------
    obj : the dressup document object
    source : str, AxisErrorTable or mapping
        A CSV file (read with :func:`surfcomp.io.axis_csv.read_axis_errors`), a table, or
        ``{'x': (positions (n,), errors (n, 3))}`` in mm.
    """
    if isinstance(source, (str, os.PathLike)):
        table = read_axis_errors(os.fspath(source))
        obj.SourceFile = os.path.abspath(os.fspath(source))
        data = table.data
    elif isinstance(source, AxisErrorTable):
        data = source.data
        obj.SourceFile = source.path or ""
    else:
        data = {str(k).lower(): v for k, v in dict(source).items()}
    axis, pos, ex, ey, ez = [], [], [], [], []
    for ax in AXES:
        if ax not in data:
            continue
        p, e = data[ax]
        p = np.asarray(p, dtype=float).reshape(-1)
        e = np.asarray(e, dtype=float).reshape(-1, 3)
        if e.shape[0] != p.size:
            raise InputError("axis %s: %d positions but %d error rows" % (ax.upper(), p.size,
                                                                          e.shape[0]))
        axis += [ax.upper()] * p.size
        pos += p.tolist()
        ex += e[:, 0].tolist()
        ey += e[:, 1].tolist()
        ez += e[:, 2].tolist()
    obj.MeasuredAxis = axis
    obj.MeasuredPosition = pos
    obj.MeasuredErrorX = ex
    obj.MeasuredErrorY = ey
    obj.MeasuredErrorZ = ez


def measurements(obj):
    """The stored measurements as ``{'x': (positions, errors (n, 3))}`` (mm)."""
    axis = [str(a).strip().lower() for a in obj.MeasuredAxis]
    cols = [np.asarray(getattr(obj, n), dtype=float) for n in
            ("MeasuredPosition", "MeasuredErrorX", "MeasuredErrorY", "MeasuredErrorZ")]
    n = len(axis)
    if any(c.size != n for c in cols):
        raise InputError("%s: the measurement lists have different lengths (axis %d, "
                         "position %d, errors %d/%d/%d)"
                         % ((obj.Label, n) + tuple(c.size for c in cols)))
    axis = np.array(axis)
    out = {}
    for ax in AXES:
        sel = axis == ax
        if sel.any():
            out[ax] = (cols[0][sel], np.stack([c[sel] for c in cols[1:]], axis=1))
    return out


def _vec(v):
    return np.array([v.x, v.y, v.z], dtype=float)


def model_of(obj):
    """Fit the error model from the object's properties (in the path's coordinates)."""
    model = fit_axis_errors(measurements(obj), model=obj.Model, reference=_vec(obj.Reference),
                            source=obj.Label)
    return model, model.in_program_coordinates(_vec(obj.WorkOffset))


def compensate_path(obj):
    """Compute the dressup's Path from its base (what ``execute`` does), return the result."""
    base = obj.Base
    if base is None or not base.isDerivedFrom("Path::Feature"):
        return Path.Path(), None
    cmds = cam.placed_commands(base)
    model, prog_model = model_of(obj)
    # messages name the dressup and the operation under it; "line" = base command number
    source = "%s (on %s)" % (obj.Label, cam.base_operation(base).Label)
    res = compensate_commands([(c.Name, c.Parameters) for c in cmds], prog_model,
                              segment_length=float(obj.SegmentLength.Value),
                              tolerance=float(obj.Tolerance.Value),
                              arc_tolerance=float(obj.ArcTolerance.Value), source=source)
    out = [cmds[item] if isinstance(item, int) else Path.Command(item[0], item[1])
           for item in res.output]
    return Path.Path(out), (model, prog_model, res)


class DressupAxisErrors(DressupProxy):
    """Proxy of the axis-error compensation dressup (state lives in properties)."""

    PROPERTIES = PROPERTIES
    VERSION = VERSION

    def execute(self, obj):
        path, result = compensate_path(obj)
        obj.Path = path
        if result is None:      # no base: nothing compensated, no figures of an earlier run
            obj.FitSummary = []
            obj.Warnings = []
            obj.ErrorBefore = obj.ErrorAfter = obj.MaxCorrection = 0.0
            return
        model, prog_model, res = result
        pred = res.predicted(prog_model)
        obj.FitSummary = model.summary_lines()
        obj.ErrorBefore = pred["before"]["max_mm"]
        obj.ErrorAfter = pred["after"]["max_mm"]
        obj.MaxCorrection = res.max_correction()
        obj.Warnings = list(res.warnings)


def Create(base, model_csv_or_data, name="DressupAxisErrors"):
    """Create the axis-error compensation dressup on ``base``.

    Parameters
    ----------
    base : Path::Feature
        The operation (or another dressup) to compensate.
    model_csv_or_data : str, AxisErrorTable or mapping
        The per-axis measurements: a CSV file, a table, or ``{'x': (positions, errors)}``
        (mm). They are copied into the document.
    name : str
        Object name; keep ``Dressup`` in it (Path finds the tool controller of dressups by
        that part of the name).

    Returns
    -------
    The new ``Path::FeaturePython`` object (placed in the base's Job in place of the base,
    when there is one). Recompute the document to compute its Path.
    """
    check_base(base)
    doc = base.Document
    obj = doc.addObject("Path::FeaturePython", name)
    DressupAxisErrors(obj, base)
    set_measurements(obj, model_csv_or_data)
    place(obj, base)
    return obj
