# SPDX-License-Identifier: LGPL-2.1-or-later
"""A measurement plan, and the probe log of its program joined to it (no FreeCAD).

A plan (``python3 -m surfcomp plan``) is a measurement file of the table contract
(:mod:`surfcomp.io.measurements`) with an id, the nominal point ``x_nom y_nom z_nom`` and
the unit outward normal ``i j k`` of every point, in mm and in visiting order. Its probing
program (:mod:`surfcomp.io.probe_program`) probes the points in that order, so the probe
log's lines are the plan's points in order: line ``k`` (``touches`` lines per point, the
last one the measurement) is the tip centre ``c`` at the contact with point ``k``. The
joined set holds the plan's nominal points and normals and the log's centres as measured
points; the pipeline's tip-radius compensation then takes the contact point as
``c - R n`` along the plan's normal ``n`` and the deviation as ``(c - p) . n - R``
(:func:`surfcomp.core.compensation.pipeline.prepare`).
"""

from dataclasses import dataclass

import numpy as np

from ..core.compensation.pipeline import Options, option_name
from ..core.limits import MAX_TOUCHES
from ..errors import InputError, MeasurementFileError
from .files import read_bytes
from .measurement_set import MeasurementSet
from .measurements import parse_measurements

#: most probe moves per point a log may hold (``--touches``)


@dataclass
class Plan:
    """Planned points: ``ids`` (N,), ``points`` and ``normals`` (N, 3) in mm, ``lines`` the
    1-based line of each point in ``source``, ``sha256`` of the file."""

    ids: list
    points: np.ndarray
    normals: np.ndarray
    lines: np.ndarray
    source: str
    sha256: str

    def __len__(self):
        return len(self.ids)


def read_plan(path, units="mm"):
    """Read a plan file: ids, nominal points and unit normals in visiting order.

    Parameters
    ----------
    path : str
    units : str, optional
        Unit of length columns without a unit suffix (default mm).

    Returns
    -------
    Plan

    Raises
    ------
    MeasurementFileError
        As for any measurement table (file, line, column); a plan without normals.
    """
    source = str(path)
    ms = parse_measurements(read_bytes(source), source=source, units=units, plan=True)
    ids = ms.ids if ms.ids is not None else ["P%d" % (k + 1) for k in range(len(ms))]
    return Plan(ids=list(ids), points=ms.nominal, normals=ms.normal, lines=ms.lines,
                source=source, sha256=ms.sha256)


def join_plan(plan, ms, options=None, touches=1):
    """The probe log ``ms`` (tip centres, in the plan's order) joined to ``plan``.

    Parameters
    ----------
    plan : Plan
    ms : MeasurementSet
        Measured points only (a LinuxCNC probe log or the Fanuc program's DPRNT output,
        read by :func:`surfcomp.io.readers.read_any`).
    options : surfcomp.core.compensation.pipeline.Options
        ``tip_radius`` (R, mm) and ``max_offset`` (mm) are used.
    touches : int
        Probe moves per point in the log (2 for a LinuxCNC program with a second touch);
        the last of each point is the measurement.

    Returns
    -------
    MeasurementSet
        ``nominal`` and ``normal`` from the plan, ``measured`` the log's centres, ``ids``
        the plan's, ``lines`` the log's lines (messages name the log), ``deviation`` None.

    Raises
    ------
    MeasurementFileError
        The log's line count is not ``touches`` times the plan's point count, or a line's
        centre less ``R n`` lies more than ``max_offset`` from its planned point: the first
        line that does not fit is named (the log's file and line, or the plan's for a
        point the log has no line for).
    """
    options = options or Options()
    if isinstance(touches, bool) or not isinstance(touches, int) or \
            not 1 <= touches <= MAX_TOUCHES:
        raise InputError("touches %r: expected a whole number from 1 to %d"
                         % (touches, MAX_TOUCHES))
    if ms.nominal is not None or ms.measured is None:
        raise InputError("a plan joins the measured points of a probe log to its planned "
                         "points; this file holds %s (give it without the plan)"
                         % ("nominal points" if ms.nominal is not None else "no measured point"),
                         file=ms.source)
    _check_count(plan, ms, touches)
    R = float(options.tip_radius or 0.0)
    k = np.arange(len(ms)) // touches
    contact = ms.measured - R * plan.normals[k]
    off = np.linalg.norm(contact - plan.points[k], axis=1)
    bad = np.nonzero(~(off <= options.max_offset))[0]
    if bad.size:
        b = bad[0]
        raise MeasurementFileError(
            "probe line %d (%.4f, %.4f, %.4f), less the tip radius %g mm along the normal, "
            "lies %.4f mm from its planned point %s (%s:%d, (%.4f, %.4f, %.4f)); expected at "
            "most %s %g mm (%d line(s) do not fit): is the log from this plan's program, "
            "with the same tip radius and %d touch(es) per point?"
            % ((b + 1,) + tuple(ms.measured[b]) + (R, off[b], plan.ids[k[b]], plan.source,
                                                  plan.lines[k[b]]) + tuple(plan.points[k[b]])
               + (option_name(options, "max_offset"), options.max_offset, bad.size, touches)),
            file=ms.source, line=int(ms.lines[b]), options=("max_offset",))
    last = slice(touches - 1, None, touches)
    return MeasurementSet(
        nominal=plan.points, measured=ms.measured[last], normal=plan.normals, deviation=None,
        ids=list(plan.ids), lines=ms.lines[last], source=ms.source, sha256=ms.sha256,
        units=ms.units, columns={"x_nom": "plan x_nom", "y_nom": "plan y_nom",
                                 "z_nom": "plan z_nom", "i": "plan i", "j": "plan j",
                                 "k": "plan k", **{"%s_meas" % a: a.upper() for a in "xyz"}},
        ignored_columns=list(ms.ignored_columns), warnings=list(ms.warnings),
        separator=ms.separator, tip_centres=ms.tip_centres)


def _check_count(plan, ms, touches):
    want = touches * len(plan)
    if len(ms) == want:
        return
    per = "" if touches == 1 else " (%d per point)" % touches
    if len(ms) > want:
        raise MeasurementFileError(
            "probe line %d has no planned point: the plan %s holds %d points, so the log "
            "should hold %d lines%s, but it holds %d (expected the log of this plan's "
            "program, run once)" % (want + 1, plan.source, len(plan), want, per, len(ms)),
            file=ms.source, line=int(ms.lines[want]))
    k = len(ms) // touches
    raise MeasurementFileError(
        "planned point %s has no probe line: the log %s holds %d lines, expected %d%s for "
        "the plan's %d points (was the program stopped early?)"
        % (plan.ids[k], ms.source, len(ms), want, per, len(plan)),
        file=plan.source, line=int(plan.lines[k]))
