# SPDX-License-Identifier: LGPL-2.1-or-later
"""``compensate SOLID MEAS --faces F1,F2,...|auto -o OUT``: a region of faces (issue 30)."""

from ..core.command_options import COMPENSATE
from ..core.option_tables import INPUTS
from ..core.options import OPTIONS
from ..errors import InputError


def ignored(args):
    """(flag, given) of the options of one face that a region does not read, given where
    they differ from their defaults: a plan's pairing, the grid layout, the grid filter's
    edge handling, the knot refinement and the mirror stock's acceptance."""
    return (("--plan", args.plan),
            ("--touches", args.touches != INPUTS["touches"].default),
            ("--layout", args.layout != OPTIONS["layout"].default),
            ("--edge", args.edge != OPTIONS["edge"].default),
            ("--refine", args.refine != OPTIONS["refine"].default),
            ("--accept-stock", args.accept_stock))


def run_region_command(args):
    if args.replace or args.save or args.gcode:
        from .region_document import run_region_document_command

        return run_region_document_command(args)
    if not args.output:
        raise InputError("--faces needs -o OUT (the corrected shape)")
    for flag, value in (("--face", args.face), ("--replace", args.replace),
                        ("--save", args.save), ("--gcode", args.gcode),
                        ("--points", args.points), ("--curves", args.curves),
                        ("--html", args.html), ("--weights", args.weights),
                        ("--face-only", args.face_only), ("--flip-normals", args.flip_normals),
                        ("--tip-radius", args.tip_radius), ("--stock", args.stock),
                        ("--align", args.align != "none"), ("--transform", args.transform),
                        ("--rps", args.rps), ("--align-faces", args.align_faces),
                        ("--align-dof", args.align_dof)) + ignored(args):
        if value:
            raise InputError("%s cannot be combined with --faces -o (it works with --faces on "
                             "a document: --save OUT.FCStd)" % flag
                             if flag.startswith(("--align", "--transform", "--rps")) else
                             "%s cannot be combined with --faces" % flag)
    share = COMPENSATE["min_coverage"]                 # the registry's domain
    if not share.low <= args.min_coverage <= share.high:
        raise InputError("%s must be between %g and %g (got %g)"
                         % (share.flag, share.low, share.high, args.min_coverage))
    from ..app import fcenv

    fcenv.import_freecad()
    from ..app.region_route import run_region

    run_region(args.nominal, args.measurements, args.faces, args.output, args.report,
               units=args.units or "mm", fmt=args.fmt, sample=args.sample,
               deviation_units=args.deviation_units, method=args.method, mask_size=args.mask,
               mask_kind=args.mask_kind, sigma=args.sigma, max_offset=args.max_offset,
               min_coverage=args.min_coverage, smoothing=args.smoothing,
               max_memory=args.max_memory, object_name=args.object)
    print("wrote %s" % args.output)
    if args.report:
        print("wrote %s" % args.report)
    return 0
