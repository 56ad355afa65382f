# SPDX-License-Identifier: LGPL-2.1-or-later
"""One entry point for every measurement file format (no FreeCAD).

QIF, PC-DMIS XYZIJK and LinuxCNC probe logs are recognised by their content
(:func:`surfcomp.io.pointfiles.detect_format`); everything else is read as a
table with a header (:mod:`surfcomp.io.measurements`), and, when its header names
none of the table's columns, as plain measured XYZ points.
"""

import dataclasses

from ..core.choices import MEASUREMENT_FORMATS
from ..errors import InputError, MeasurementFileError, note
from .align_files import face_column
from .files import read_once
from .measurements import read_measurements
from .pointfiles import detect_format, read_point_file
from .units import unit_factor

#: measurement file formats (the choices, importable without numpy)
FORMATS = MEASUREMENT_FORMATS


def read_any(path, units="mm", fmt="auto", sample=None, deviation_units=None):
    """Read a measurement file of any supported format.

    Parameters
    ----------
    path : str
    units : {'mm', 'um', 'in'} or None
        Units of values without a unit of their own (default mm).
    deviation_units : {'mm', 'um', 'in'}, optional
        Unit of a deviation column without a unit of its own, when it differs from the
        coordinates' (``units``); a deviation computed from the points keeps theirs.
    fmt : str
        One of :data:`FORMATS`; ``auto`` detects it.
    sample : int or str, optional
        Which measurement result of a QIF file holding several (default the first).

    Returns
    -------
    surfcomp.io.measurements.MeasurementSet
    """
    ms, kind = _read_any(path, units, fmt, sample)
    if (deviation_units is None or ms.deviation is None or "dev" not in (ms.columns or {})
            or unit_factor(deviation_units) == unit_factor(units or "mm")):
        return ms
    if kind != "table":
        # a QIF file's deviations are lengths of the file's own unit, as its points are:
        # read in another unit, they would no longer match the points they were checked on
        raise InputError(note(("deviation_units",), " %s applies to the deviation column of a "
                              "table; this %s file gives its deviations in the unit of its "
                              "points (%s; expected no " % (deviation_units, kind.upper(),
                                                           ms.units),
                              ("deviation_units",), ", or the same as ", ("units",), ")"),
                         file=str(path))
    # the file again with the deviation's unit: the dev column as the reader scales it
    # (one with a unit of its own keeps it), the coordinates of the first reading
    dev = _read_any(path, deviation_units, fmt, sample)[0].deviation
    return dataclasses.replace(ms, deviation=dev, units="%s, deviation %s"
                               % (ms.units or units or "mm", deviation_units))


def _read_any(path, units, fmt, sample):
    if fmt not in FORMATS:
        raise MeasurementFileError("unknown format %r (expected one of %s)"
                                   % (fmt, ", ".join(FORMATS)), file=path)
    with read_once(path):
        ms, kind = _read(path, units, fmt, sample)
        faces = face_column(ms)    # the same bytes as the points (read_once)
    return (ms if faces is None else dataclasses.replace(ms, faces=faces)), kind


def _read(path, units, fmt, sample):
    """(the measurement set, the format it was read as: ``table`` or a point format)"""
    if fmt != "auto" and fmt != "table":
        return read_point_file(path, fmt=fmt, units=units, sample=sample), fmt
    detected = "table" if fmt == "table" else detect_format(path)
    if detected not in ("xyz", "table"):
        return read_point_file(path, fmt=detected, units=units, sample=sample), detected
    if sample is not None:
        raise InputError("sample=%r applies to QIF files only, this is a table or XYZ file"
                         % (sample,), file=str(path))
    if fmt == "table":
        return read_measurements(path, units=units), "table"
    try:
        return read_measurements(path, units=units), "table"
    except MeasurementFileError as table_error:
        try:
            return read_point_file(path, fmt="xyz", units=units), "xyz"
        except MeasurementFileError as xyz_error:
            # the reading that got further is the file's: a plain x y z file with a bad
            # value on line 7 is that, not a table whose header names no known column
            raise (xyz_error if (xyz_error.line or 0) > (table_error.line or 0)
                   else table_error) from None


def read_measured(job):
    """The measurement set of a job (:class:`surfcomp.app.file_route.Job`: its
    ``measurements``, ``units``, ``fmt``, ``sample``, ``deviation_units``, ``plan``,
    ``touches`` and ``options``): the file, joined to the plan when the job has one.

    The plan is in mm whatever ``units`` says (``plan`` writes it so, and the columns of a
    plan written by hand may carry their own unit): ``units`` is the log's, which is in
    inches when the program ran in G20 (a CAM post-processor set to inches)."""
    if job.plan is None and job.touches != 1:
        raise InputError(note(("touches",), " applies to a probe log read with a "
                              "measurement plan (", ("plan",), ")"))
    ms = read_any(job.measurements, job.units, job.fmt, job.sample,
                  deviation_units=job.deviation_units)
    if job.plan is None:
        return ms
    from .plan_join import join_plan, read_plan

    return join_plan(read_plan(job.plan), ms, job.options, job.touches)
