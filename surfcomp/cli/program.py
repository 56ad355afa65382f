# SPDX-License-Identifier: LGPL-2.1-or-later
"""``compensate ... --program FINISH.ngc --tool ball:R -o OUT.ngc``: move the finishing
program by the correction (:mod:`surfcomp.app.program_route`) instead of writing the face."""

import math
import sys

from ..core.command_options import PROGRAM_MOVE
from ..core.limits import MIN_SEGMENT_LENGTH
from ..core.memory import collector_paused
from ..errors import InputError
from . import registry
from .common import ProgressLine, job_from_args, wrote
from .option_flags import shown
from .options import add_arguments, check_range


def add_program_options(p):
    """The option group of direct program compensation (the ``gcode`` command's names
    where they fit)."""
    g = p.add_argument_group(
        registry.PROGRAM,
        "Move the cutter-location points of a ball-end finishing program by the correction "
        "along the face normal at their contact (exact for a ball end) instead of "
        "regenerating the CAM operation on the corrected face. Flat and bull-nose cutters "
        "are refused.")
    registry.add_options(p, "compensate", {registry.PROGRAM: g}, flags=("--program",))
    add_arguments(g, PROGRAM_MOVE, PROGRAM_MOVE)

#: outputs and modes that do not go with --program
_NOT_WITH = (("replace", "--replace"), ("save", "--save"), ("gcode", "--gcode"),
             ("report", "--report"), ("points", "--points"), ("curves", "--curves"),
             ("html", "--html"), ("face_only", "--face-only"))
#: the alignment's options, which the moved program does not apply
_ALIGN = (("transform", "--transform"), ("rps", "--rps"), ("align_faces", "--align-faces"),
          ("align_dof", "--align-dof"))


def _positive(value, option, minimum=0.0):
    if not (math.isfinite(value) and value > minimum):
        raise InputError("%s %r: expected a length in mm greater than %g"
                         % (option, value, minimum))
    return value


def run_program(args):
    """Run the direct program compensation of a command line."""
    for dest, flag in _NOT_WITH:
        if getattr(args, dest, None):
            raise InputError("%s cannot be combined with --program (it writes the moved "
                             "program only); run 'compensate' without --program for it" % flag)
    given = (["--align %s" % args.align] if args.align not in (None, "none") else []) + [
        flag for dest, flag in _ALIGN if getattr(args, dest, None)]
    if given:
        raise InputError("%s cannot be combined with --program: the program is moved by the "
                         "correction of measured points in the nominal's frame, and no "
                         "alignment is applied to them; expected measurements in the "
                         "nominal's frame (or 'compensate -o' for an aligned face)" % given[0])
    if not args.output:
        raise InputError("--program needs -o OUT.ngc, the moved program")
    if not args.tool:
        raise InputError("--program needs --tool ball:R, the ball end mill's radius in mm")
    _positive(args.tolerance, "--tolerance")
    _positive(args.blend, "--blend")
    if not (math.isfinite(args.segment_length) and args.segment_length >= MIN_SEGMENT_LENGTH):
        raise InputError("--segment-length %r: expected a length of at least %g mm (1 um)"
                         % (args.segment_length, MIN_SEGMENT_LENGTH))
    check_range(PROGRAM_MOVE["decimals"], args.decimals)
    from ..app import cadread

    try:
        with collector_paused():
            # the nominal's reader child starts first (a fork while this process has one
            # thread and no FreeCAD, before the numerics' imports start theirs): it imports
            # FreeCAD, reads the file and sends the face back while they run
            if not args.object:
                cadread.prefetch_face(args.nominal, args.face)
            from ..app.program_route import ProgramJob, run_program_job, summary_lines
            from ..core.compensation.program_offset import parse_tool

        parse_tool(args.tool)
        job = job_from_args(args, "compensate")
        job.output = None
        pj = ProgramJob(job, args.program, args.output, args.tool, blend=args.blend,
                        tolerance=args.tolerance, segment_length=args.segment_length,
                        decimals=args.decimals)
        comp, po = run_program_job(pj, *registry.declared(args, "compensate"),
                                   progress=ProgressLine(args.quiet),
                                   max_memory=args.max_memory)
    finally:
        cadread.discard()
    for w in comp.prepared.warnings:    # the measurements' and the corrected face's, as -o
        print("warning: " + shown(w), file=sys.stderr)
    for line in summary_lines(comp, po, pj):      # warnings on standard error, as -o's
        print(line, file=sys.stderr if line.startswith("warning: ") else sys.stdout)
    print(wrote(args.output))
    return 0
