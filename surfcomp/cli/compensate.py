# SPDX-License-Identifier: LGPL-2.1-or-later
"""``python3 -m surfcomp compensate``: nominal + measurements -> corrected face."""

import sys

from ..core.command_options import COMPENSATE
from ..core.option_tables import INPUTS
from ..errors import InputError
from . import SUMMARIES, registry
from .common import (
    ProgressLine,
    add_job_parser,
    add_method_options,
    options_from_args,
    run_job_command,
)
from .option_flags import shown
from .options import add_arguments


def add_parser(subparsers):
    p = add_job_parser(
        subparsers, "compensate", SUMMARIES["compensate"],
        "Build a corrected B-spline face from a nominal face and a measurement file (Werner "
        "2022 raw/filtered, mirror method, uniform offset).")
    registry.add_options(p, "compensate", flags=("-o",))
    p.add_argument("--face-only", action="store_true",
                   help="write the corrected face alone, also when it is a face of a solid or "
                        "shell")
    add_method_options(p)
    add_arguments(p, ("faces", "min_coverage"), COMPENSATE)
    registry.add_options(p, "compensate", flags=("--points", "--curves", "--html"))
    from .program import add_program_options

    add_program_options(p)
    doc = p.add_argument_group(
        registry.DOCUMENT,
        "Add the compensation to the document, put it in the nominal's place so Path "
        "regenerates the tool paths, save a copy and post the program. The input document "
        "is never overwritten unless --overwrite-input is given.")
    doc.add_argument("--replace", action="store_true",
                     help="rebind every user of the nominal (Path Job models, operations, "
                          "links) to the compensation and recompute")
    registry.add_options(p, "compensate", {registry.DOCUMENT: doc}, flags=("--save", "--gcode"))
    add_arguments(doc, ("post", "post_args", "job"), COMPENSATE)
    doc.add_argument("--overwrite-input", action="store_true",
                     help="allow --save to overwrite the input document")
    p.set_defaults(run=run)
    return p


def run(args):
    if args.program and args.faces:
        raise InputError("--program moves a finishing program by the correction of one face "
                         "and cannot be combined with --faces (expected --face F or no --faces)")
    if args.program:
        from .program import run_program

        return run_program(args)
    if args.faces:
        from .region import run_region_command

        return run_region_command(args)
    if args.replace or args.save or args.gcode:
        return run_document(args)
    return run_job_command(args, "compensate")


def align_of(args):
    """The :class:`AlignOptions` of the --align options, or None without them: the files
    are read and the transform checked before a document is opened."""
    from ..app.alignment import align_options

    if args.align != "none" or args.transform or args.rps or args.align_faces \
            or args.align_dof:
        return align_options(args)
    return None


def run_document(args):
    """The shop-document route: compensate, replace, save, post (see the option group)."""
    if not args.nominal.lower().endswith(".fcstd"):
        raise InputError("--replace/--save/--gcode work on a FreeCAD document: NOMINAL must be "
                         "an .FCStd file", file=args.nominal)
    if not args.object:
        raise InputError("--object NAME is required with --replace/--save/--gcode (the object "
                         "holding the nominal face)", file=args.nominal)
    other = [o for o in ("output", "report", "points", "curves", "html", "plan")
             if getattr(args, o)]
    if other:
        raise InputError("--%s cannot be combined with --replace/--save/--gcode; run "
                         "'compensate' without them for the files"
                         % other[0].replace("_", "-"))
    if args.touches != INPUTS["touches"].default:     # a probe log's, read with --plan only
        raise InputError("--touches reads a probe log with --plan, which cannot be combined "
                         "with --replace/--save/--gcode; run 'compensate' without them for the "
                         "files")
    from ..app import fcenv

    fcenv.import_freecad()
    from ..app.document_route import run_document_job, summary_lines

    align = align_of(args)

    res = run_document_job(args.nominal, args.measurements, args.object, face=args.face,
                           save=args.save, replace=args.replace, gcode=args.gcode,
                           post=args.post, post_args=args.post_args, job_name=args.job,
                           units=args.units or "mm", options=options_from_args(args),
                           output="face" if args.face_only else None,
                           overwrite_input=args.overwrite_input, fmt=args.fmt,
                           sample=args.sample, progress=ProgressLine(args.quiet),
                           deviation_units=args.deviation_units, max_memory=args.max_memory,
                           align=align)
    for line in summary_lines(res):
        print(line)
    for w in res.alignment_warnings:
        print("warning: " + shown(w), file=sys.stderr)
    return 0
