# SPDX-License-Identifier: LGPL-2.1-or-later
"""``compensate DOC.FCStd MEAS --object O --faces F1,F2|auto [--replace] --save OUT.FCStd
[--gcode OUT.ngc] [--align ...]``: a region of faces compensated in a shop document (issue
30); ``--object`` naming a region object adds its next round."""

import sys

from ..errors import InputError
from .common import ProgressLine
from .option_flags import shown
from .region import ignored


def run_region_document_command(args):
    if not args.nominal.lower().endswith(".fcstd"):
        raise InputError("--replace/--save/--gcode with --faces work on a FreeCAD document: "
                         "NOMINAL must be an .FCStd file", file=args.nominal)
    if not args.object:
        raise InputError("--object NAME is required with --faces and --replace/--save (the "
                         "object holding the region's faces)", file=args.nominal)
    for flag, value in (("--face", args.face), ("-o", args.output), ("--report", args.report),
                        ("--points", args.points),
                        ("--curves", args.curves), ("--html", args.html),
                        ("--weights", args.weights), ("--face-only", args.face_only),
                        ("--flip-normals", args.flip_normals),
                        ("--tip-radius", args.tip_radius), ("--stock", args.stock)) \
            + ignored(args):
        if value:
            raise InputError("%s cannot be combined with --faces on a document" % flag)
    if not 0.0 <= args.min_coverage <= 1.0:
        raise InputError("--min-coverage must be between 0 and 1 (got %g)" % args.min_coverage)
    from ..app import fcenv

    fcenv.import_freecad()
    from ..app.region_docroute import run_region_document, summary_lines
    from ..app.region_route import check_options
    from .compensate import align_of

    # as given, before the region object's properties clamp them (MaxOffset -1 reads 0)
    check_options(args.method, args.mask, args.mask_kind, args.sigma, args.max_offset,
                  args.smoothing)

    res = run_region_document(
        args.nominal, args.measurements, args.object, args.faces, args.save,
        replace=args.replace, overwrite_input=args.overwrite_input, units=args.units or "mm",
        gcode=args.gcode, post=args.post, post_args=args.post_args, job_name=args.job,
        align=align_of(args),
        deviation_units=args.deviation_units, fmt=args.fmt, sample=args.sample,
        max_memory=args.max_memory, progress=ProgressLine(args.quiet), Method=args.method,
        MaskSize=args.mask, MaskKind=args.mask_kind, Sigma=args.sigma or 0.0,
        MaxOffset=args.max_offset, MinCoverage=args.min_coverage,
        Smoothing=args.smoothing or 0.0)
    for line in summary_lines(res):
        print(line)
    for w in res.alignment_warnings:
        print("warning: " + shown(w), file=sys.stderr)
    return 0
