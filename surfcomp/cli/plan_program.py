# SPDX-License-Identifier: LGPL-2.1-or-later
"""The probing program options of ``python3 -m surfcomp plan`` and the program they write.

:func:`add_program_options` adds the ``probing program`` option group to the ``plan``
parser (``--program`` comes from :mod:`surfcomp.cli.registry`, so it is checked against
the command's inputs and outputs); :func:`write_from_args` writes the program of a plan
(:mod:`surfcomp.io.probe_program`) and returns the summary lines;
:func:`program_from_args` gives the text for the plan command to stage beside the plan in
one transaction. The tip radius, the stand-off and the clearance are the plan command's own
``--tip-radius``, ``--stand-off`` and ``--clearance`` (its reach checks test the moves the
program makes with them).
"""

from ..core.option_tables import PROGRAM
from ..errors import InputError
from ..io.atomic import write_text
from ..io.probe_program import ProbeSettings, program_summary, program_text
from . import registry
from .common import wrote
from .options import add_arguments


def add_program_options(parser):
    """Add ``--program`` and the options of the probing program to ``parser``."""
    g = parser.add_argument_group(
        registry.PROBE_PROGRAM,
        "Positions are stylus tip centres (set the probe's tool length to the ball's centre); "
        "the points are probed in the plan's order along their normals.")
    registry.add_options(parser, "plan", {registry.PROBE_PROGRAM: g}, flags=("--program",))
    add_arguments(g, tuple(PROGRAM), PROGRAM)


def check_args(args):
    """Refuse, before any planning, program options that cannot take effect: any of them
    without ``--program``, and settings :meth:`ProbeSettings.validate` refuses."""
    if not getattr(args, "program", None):
        given = [o.flag for name, o in PROGRAM.items()
                 if getattr(args, o.dest or name) != (False if o.type is bool else o.default)]
        if len(given) == 1:
            raise InputError("%s is an option of the probing program: expected --program "
                             "PROBE.ngc with it, or no %s" % (given[0], given[0]))
        if given:
            raise InputError("%s are options of the probing program: expected --program "
                             "PROBE.ngc with them, or none of them" % ", ".join(given))
        return
    settings_from_args(args, 0.0, "").validate()


def settings_from_args(args, safe_z, plan_hash):
    """The :class:`ProbeSettings` of a command line (``args.tip_radius``, ``args.clearance``
    and ``args.stand_off`` are the plan's)."""
    return ProbeSettings(
        dialect=args.dialect, tip_radius=args.tip_radius, tool=args.tool,
        work_offset=args.work_offset, safe_z=safe_z, clearance=args.clearance,
        stand_off=args.stand_off, overtravel=args.overtravel, feed=args.feed,
        touch_feed=args.touch_feed, second_touch=args.second_touch,
        second_feed=args.second_feed, backoff=args.backoff, plan_hash=plan_hash,
        log_file=args.probe_log)


def program_from_args(args, ids, points, normals, safe_z, plan_hash):
    """The program text of ``args.program`` for the plan and its summary lines.

    Parameters
    ----------
    args : argparse.Namespace
        With the options of :func:`add_program_options` and the plan's ``tip_radius``,
        ``clearance`` and ``stand_off``.
    ids, points, normals
        The plan in visiting order (points and unit outward normals (N, 3), mm).
    safe_z : float
        The part's top (mm).
    plan_hash : str
        Hex SHA-256 of the plan file's text.

    Returns
    -------
    (str, list of str)
        The program and the summary lines (the program, the travel, ``wrote ...``).
    """
    s = settings_from_args(args, safe_z, plan_hash)
    text, moves = program_text(ids, points, normals, s)
    res = program_summary(args.program, moves, s)
    t = res["travel"]
    log = ("probe log %s, %d lines" % (s.log_name(), res["log_lines"])
           if s.dialect == "linuxcnc" else "DPRNT log, %d lines" % res["log_lines"])
    return text, [
        "Program:      %s (%s, %d points, tip radius %g mm, %s, %s, safe height Z%.3f)"
        % (args.program, s.dialect, res["points"], s.tip_radius, s.work_offset, log,
           res["safe_height"]),
        "Travel:       %.1f mm (traverse %.1f mm, feed %.1f mm, probing %.1f mm)"
        % (t["total"], t["traverse"], t["feed"], t["probe"]),
        wrote(args.program)]


def write_from_args(args, ids, points, normals, safe_z, plan_hash):
    """Write ``args.program`` for the plan (nothing without ``--program``); arguments as
    for :func:`program_from_args`; returns the summary lines."""
    if not getattr(args, "program", None):
        return []
    text, lines = program_from_args(args, ids, points, normals, safe_z, plan_hash)
    write_text(args.program, text, inputs=registry.declared(args, "plan")[1],
               option="--program")
    return lines
