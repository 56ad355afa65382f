# SPDX-License-Identifier: LGPL-2.1-or-later
"""The probing program of a measurement plan: LinuxCNC or Fanuc macro B text (no FreeCAD).

The moves are those of :mod:`surfcomp.io.probe_path` (tip-centre positions, one touch per
point by default); this module writes them in a dialect.

``linuxcnc``
    ``G38.2`` probe moves between ``(PROBEOPEN file)`` and ``(PROBECLOSE)``: LinuxCNC writes
    one line ``X Y Z A B C U V W`` per probe move to the file, the tip centre where the
    probe tripped, which ``compensate``/``inspect`` read back with ``--plan``. A second
    touch backs off from the trip point ``#5061``-``#5063`` (the probe result in the work
    offset) and probes again, so each point then has two lines, the second the slow one.
``fanuc``
    Custom macro B: ``G31`` skip moves; after the (last) touch of a point the skip position
    ``#5061`` (X), ``#5062`` (Y), ``#5063`` (Z) (work coordinates of the programmed point,
    the tip centre when the tool length is set to it) is written with ``DPRNT`` between
    ``POPEN`` and ``PCLOS``, as ``X Y Z 0 0 0 0 0 0`` with 4 decimals (format ``[44]``), the
    LinuxCNC log's layout, so the same reader reads it (one line per point). No other
    variable is read or written. The output goes to the control's external output device
    (I/O channel setting), not to a named file. How DPRNT prints leading zeros and signs
    depends on the control's parameters (No. 6001, PRT); the reader needs nine blank-
    separated numbers per line, so compare a real output's first lines with it before
    relying on it (no Fanuc control or interpreter was available to check this).

Both record the plan's SHA-256, the tip radius and the dialect in their header.
"""

import re

import numpy as np

from ..errors import InputError
from .atomic import write_text
from .probe_path import ProbeSettings, probe_path, travel_summary

__all__ = ["ProbeSettings", "program_text", "write_probe_program"]

#: Fanuc's [44] output format holds at most 4 integer digits
FANUC_LIMIT = 9999.9999


def _num(value):
    text = "%.4f" % value
    return "0.0000" if text == "-0.0000" else text


def _header(path, s, comment):
    n = len(path.ids)
    plan = s.plan_hash or "not given"
    lines = [comment("surfcomp probing program, dialect %s" % s.dialect),
             comment("plan sha256 %s" % plan[:32]),
             comment("plan sha256 cont %s" % plan[32:]) if len(plan) > 32 else None,
             comment("tip radius %s mm, %d points, %s" % (_num(s.tip_radius), n,
                     "two touches per point" if s.second_touch else "one touch per point")),
             comment("positions are stylus tip centres: tool %d length set to the ball centre"
                     % s.tool),
             comment("safe height Z%s = part top %s + tip radius + clearance %s"
                     % (_num(path.safe), _num(s.safe_z), _num(s.clearance)))]
    return [ln for ln in lines if ln]


#: the motion words of the dialects: rapid, feed, probe
_WORDS = {"linuxcnc": ("G0", "G1", "G38.2"), "fanuc": ("G00", "G01", "G31")}
_DPRNT = "DPRNT[#5061[44]*#5062[44]*#5063[44]*0*0*0*0*0*0]"
_MINUS_ZERO = re.compile(r"([XYZ])-(0\.0000)(?!\d)")


def _fmt_feed(f):
    return ("%.3f" % f).rstrip("0").rstrip(".")


def _points_text(path, s, comments):
    """The lines of every point (module docstring of :mod:`surfcomp.io.probe_path`): one
    template filled per point with its numbers."""
    g0, g1, probe = _WORDS[s.dialect]
    xyz = "X%.4f Y%.4f Z%.4f"
    feed, touch, touch2 = (_fmt_feed(f) for f in (s.feed, s.touch_feed, s.touch2_feed()))
    lines = [g0 + " X%.4f Y%.4f", g0 + " Z%.4f"]
    columns = [path.retract]
    if path.approach:
        lines.append("%s %s F%s" % (g1, xyz, feed))
        columns.append(path.standoff)
    lines.append("%s %s F%s" % (probe, xyz, touch))
    columns.append(path.end)
    if s.second_touch:
        # back off along n from the trip point #5061..#5063 (signed offsets)
        lines += [g1 + " X[#5061%+.4f] Y[#5062%+.4f] Z[#5063%+.4f] F" + feed,
                  "%s %s F%s" % (probe, xyz, touch2)]
        columns += [path.backoff * path.normals, path.end]
    if s.dialect == "fanuc":
        lines.append(_DPRNT)
    lines += ["%s %s F%s" % (g1, xyz, feed), "%s Z%s" % (g0, _num(path.safe))]
    columns.append(path.retract)
    template = "%s\n" + "\n".join(lines)
    rows = np.concatenate(columns, axis=1).tolist()
    text = "\n".join(template % ((c,) + tuple(r)) for c, r in zip(comments, rows))
    return _MINUS_ZERO.sub(r"\g<1>\g<2>", text)


def _linuxcnc(path, s):
    def comment(text):
        return "(%s)" % text.replace("(", "[").replace(")", "]")

    out = _header(path, s, comment)
    out += ["G21 G90 G17 G40 G94", "T%d M6" % s.tool, "G43 H%d" % s.tool, s.work_offset,
            "G0 Z%s" % _num(path.safe), "(PROBEOPEN %s)" % s.log_name()]
    out.append(_points_text(path, s, [comment("point %d %s" % (k + 1, pid))
                                      for k, pid in enumerate(path.ids)]))
    out += ["(PROBECLOSE)", "M2"]
    return out


def _fanuc(path, s):
    def comment(text):
        return "(%s)" % re.sub(r"[^A-Z0-9 .,:=+*/#-]", "_", text.upper())

    big = np.nonzero((np.abs(np.concatenate([path.retract, path.end, path.standoff], axis=1))
                      > FANUC_LIMIT).any(axis=1))[0]
    if big.size:
        raise InputError("plan point %s: a tip-centre coordinate beyond %g mm does not fit "
                         "DPRNT's [44] format of the fanuc dialect" % (path.ids[big[0]],
                                                                       FANUC_LIMIT))
    header = _header(path, s, comment)
    out = ["%", "O%04d %s" % (s.program_number, header[0])] + header[1:]
    out += [comment("G31 skip, #5061 #5062 #5063 skip position X Y Z, DPRNT X Y Z 0 0 0 0 0 0"),
            "G21 G17 G40 G49 G80 G90 G94", "T%d M06" % s.tool, s.work_offset,
            "G43 H%d G00 Z%s" % (s.tool, _num(path.safe)), "POPEN"]
    out.append(_points_text(path, s, [comment("point %d %s" % (k + 1, pid))
                                      for k, pid in enumerate(path.ids)]))
    out += ["PCLOS", "M30", "%"]
    return out


def program_text(ids, points, normals, settings):
    """The program of a plan as text, and the moves it was written from.

    Parameters
    ----------
    ids : list of str (N,)
        Point names, in visiting order.
    points : array_like (N, 3)
        Nominal surface points (mm), in visiting order.
    normals : array_like (N, 3)
        Unit outward normals.
    settings : ProbeSettings

    Returns
    -------
    (str, surfcomp.io.probe_path.ProbePath)

    Raises
    ------
    InputError
        Bad settings or plan (see :func:`surfcomp.io.probe_path.probe_path`).
    """
    path = probe_path(ids, points, normals, settings)
    lines = (_linuxcnc if settings.dialect == "linuxcnc" else _fanuc)(path, settings)
    return "\n".join(lines) + "\n", path


def write_probe_program(path, ids, points, normals, settings, inputs=(), option="--program"):
    """Write the probing program of a plan atomically (nothing is written on error).

    Parameters
    ----------
    path : str
        The program file (``-``: standard output).
    ids, points, normals, settings
        As for :func:`program_text`.
    inputs : sequence
        ``(what, path)`` of the inputs the program must not overwrite.
    option : str
        The option naming ``path`` in messages.

    Returns
    -------
    dict
        ``path``, ``dialect``, ``points``, ``log_lines`` (lines the probe log will hold:
        two per point for LinuxCNC with a second touch), ``tip_radius``, ``safe_height``
        (tip-centre Z of the traverses) and ``travel`` (mm: ``traverse``, ``feed``,
        ``probe`` to the nominal contacts, ``total``; :func:`travel_summary`).
    """
    text, moves = program_text(ids, points, normals, settings)
    write_text(path, text, inputs=inputs, option=option)
    return program_summary(path, moves, settings)


def program_summary(path, moves, settings):
    """The summary :func:`write_probe_program` returns, for the moves of
    :func:`program_text`."""
    per_point = 2 if settings.second_touch and settings.dialect == "linuxcnc" else 1
    return {"path": path, "dialect": settings.dialect, "points": len(moves.ids),
            "log_lines": per_point * len(moves.ids), "tip_radius": settings.tip_radius,
            "safe_height": moves.safe, "travel": travel_summary(moves)}
