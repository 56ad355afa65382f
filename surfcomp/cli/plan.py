# SPDX-License-Identifier: LGPL-2.1-or-later
"""``python3 -m surfcomp plan NOMINAL [--face F] -o PLAN.csv``: where to probe the face.

Places measurement points on the nominal face (``--layout grid|xy|adaptive``,
:mod:`surfcomp.core.measurement.planning`), keeps those a 3-axis probe reaches (margin to the trim
boundary and holes, ``--max-tilt``, the stylus' moves along the normal clear of the face
and, for a face of a solid, of the part, its rapid moves ``--clearance`` from them:
:mod:`surfcomp.app.plan_reach`), orders them for a short travel and
writes the plan: the measurement-file contract (``id,x_nom,y_nom,z_nom,i,j,k``, mm) or, with
``--format xyzijk``, a PC-DMIS nominal point file. Dropped points are counted by reason
(every one of them, with ``--dropped FILE``). Bad input (a face with no reachable point, a
tip radius above the face's smallest concave radius, a count of 0 or above 10^6) exits 2
and writes nothing.

With ``--program PROBE.ngc`` (:mod:`surfcomp.cli.plan_program`) the probing program of
the plan is written too, in the same transaction as the plan (both or neither): the
plan's points in visiting order, probed along their normals, from the safe height and
retract points the reach checks tested; its header records the SHA-256 of the plan file's
text, the tip radius and the dialect.
"""

import hashlib
import os

from ..core.measurement.planning import (
    POINT_LAYOUTS,
    REASONS,
    PlanSettings,
    check_points,
    parse_count,
)
from ..core.measurement.planning_reach import NEAREST_LIMIT
from ..core.option_tables import INPUTS, PLAN
from ..errors import InputError
from ..io.atomic import Transaction
from ..io.plan_file import dropped_text, plan_text
from . import SUMMARIES, plan_program, registry
from .common import ProgressLine, wrote
from .option_flags import shown
from .options import add_arguments

#: the probe's options (the plan's reach checks and its probing program use them)
PROBE = ("tip_radius", "edge_margin", "max_tilt", "stand_off", "clearance")
#: printed examples per drop reason
_EXAMPLES = 3
#: what each visiting order is (:func:`surfcomp.core.measurement.planning_reach.visiting_order`)
ORDER_TEXT = {
    "serpentine": "row by row, every other row reversed",
    "nearest": "greedy nearest neighbour from the first point of the serpentine",
}


def add_parser(subparsers):
    p = subparsers.add_parser(
        "plan", help=SUMMARIES["plan"],
        description="Place measurement points on the nominal face (grid along the parameter "
                    "lines, grid in the machine's XY plane, or adaptive: denser where the slope "
                    "changes fast, mirror paper 2019), keep those a 3-axis probe reaches, order "
                    "them for a short travel and write the plan (id, nominal XYZ, outward "
                    "normal IJK in mm; or a PC-DMIS XYZIJK nominal file).",
        epilog="Margin to the boundary and holes: --tip-radius + --edge-margin (mm, in space). "
               "Reach: the outward normal within --max-tilt of +Z; the stylus ball "
               "--clearance from the part on the rapid move from the safe height (ball "
               "centre at part top + --tip-radius + --clearance) down to the retract point "
               "(the larger of --stand-off and --clearance out along the normal), and clear "
               "of it on the feed along the normal to the touch. See README 'On-machine "
               "probing'.")
    registry.add_options(p, "plan", flags=("nominal",))
    add_arguments(p, ("face", "object"), INPUTS)
    registry.add_options(p, "plan", flags=("-o",))
    add_arguments(p, ("plan_format", "layout", "count", "points"), PLAN)
    add_arguments(p.add_argument_group("probe"), PROBE, PLAN)
    add_arguments(p, ("order",), PLAN)
    registry.add_options(p, "plan", flags=("--dropped",))
    plan_program.add_program_options(p)
    p.add_argument("--quiet", action="store_true", help="print no progress lines")
    p.set_defaults(run=run)
    return p


def settings_from_args(args):
    """The :class:`PlanSettings` of the command line (checked)."""
    return PlanSettings(tip_radius=args.tip_radius, edge_margin=args.edge_margin,
                        max_tilt=args.max_tilt, stand_off=args.stand_off,
                        clearance=args.clearance).check()


def layout_count(args):
    """``(layout, count)`` from ``--layout``, ``--count`` and ``--points`` (checked)."""
    if args.layout in POINT_LAYOUTS:
        if args.count is not None:
            raise InputError("--count applies to the grid and xy layouts; the %s layout "
                             "takes --points N" % args.layout)
        return args.layout, check_points(PLAN["points"].stored if args.points is None
                                         else args.points)
    if args.points is not None:
        raise InputError("--points applies to the %s layouts; the %s layout takes --count "
                         "UxV" % (" and ".join(POINT_LAYOUTS), args.layout))
    return args.layout, parse_count(PLAN["count"].stored if args.count is None
                                    else args.count)


def make_plan(path, face_name, object_name, layout, count, settings, order="auto",
              progress=None):
    """``(plan, nominal, checked_part)``: load the nominal face and plan on it; the part's
    other faces (a solid's) are checked too (``checked_part`` True then)."""
    from ..app.nominal import load_nominal
    from ..app.plan_reach import plan_face

    nominal = load_nominal(path, face_name, object_name)
    plan, part = plan_face(nominal, layout, count, settings, order, progress)
    return plan, nominal, part


def _comments(args, plan, nominal):
    s = plan.settings
    count = ("%d points" % plan.requested if plan.layout in POINT_LAYOUTS
             else "%s" % (args.count or PLAN["count"].stored))
    return ["surfcomp measurement plan of %s (%s)" % (os.path.basename(args.nominal),
                                                    nominal.face_name),
            "layout %s %s: %d placed, %d kept, %d dropped"
            % (plan.layout, count, plan.requested, len(plan), len(plan.dropped)),
            "tip radius %g mm, edge margin %g mm, max tilt %g deg, stand-off %g mm, safe Z "
            "%.6f mm (part top %.6f + tip radius + clearance %g)"
            % (s.tip_radius, s.edge_margin, s.max_tilt, s.stand_off, plan.safe_z, plan.top_z,
               s.clearance),
            "visiting order %s (%s%s), travel %.3f mm between retract positions"
            % (plan.order, ORDER_TEXT[plan.order], _auto_text(args, plan), plan.travel),
            "nominal surface points (mm) and outward unit normals; no deviation: not measured"]


def _auto_text(args, plan):
    """How ``--order auto`` chose the plan's order (empty for an order given by name)."""
    if args.order != "auto":
        return ""
    if len(plan) > NEAREST_LIMIT:
        return "; order auto: nearest is not tried above %d points" % NEAREST_LIMIT
    return "; order auto: the shorter of serpentine and nearest"


def _reason_text(key):
    from ..app.plan_reach import REASONS as PART

    return shown(REASONS.get(key) or PART.get(key, key))       # options named as flags


def _write(args, plan, nominal):
    """Stage and commit the outputs; return the plan file's SHA-256 and the program's
    summary lines."""
    text = plan_text(args.plan_format, plan.ids, plan.points, plan.normals,
                     _comments(args, plan, nominal))
    sha256 = hashlib.sha256(text.encode("utf-8")).hexdigest()
    with Transaction(*registry.declared(args, "plan")) as tx:
        tx.stage_text(args.output, text)
        if args.dropped:
            tx.stage_text(args.dropped, dropped_text(
                [(d.index, _reason_text(d.reason), d.u, d.v, d.point) for d in plan.dropped]))
        lines = []
        if args.program:
            program, lines = plan_program.program_from_args(
                args, plan.ids, plan.points, plan.normals, plan.top_z, sha256)
            tx.stage_text(args.program, program)
        tx.commit()
    return sha256, lines


def run(args):
    layout, count = layout_count(args)
    settings = settings_from_args(args)
    plan_program.check_args(args)
    progress = ProgressLine(args.quiet)
    plan, nominal, part = make_plan(args.nominal, args.face, args.object, layout, count,
                                    settings, args.order, progress)
    sha256, program_lines = _write(args, plan, nominal)
    _print(args, plan, nominal, part, sha256)
    for line in program_lines:
        print(line)
    return 0


def _print(args, plan, nominal, part, sha256):
    s = plan.settings
    surf = nominal.surface
    print("Nominal:   %s (%s), %d x %d poles; %s" % (
        args.nominal, nominal.face_name, surf.shape[0], surf.shape[1],
        "paths checked against the part's other faces" if part
        else "a lone face: paths checked against the face itself"))
    extra = ""
    if "clipped" in plan.info:
        extra = " (%d nodes with no face under them)" % plan.info["clipped"]
    print("Layout:    %s: %d placed%s, %d kept, %d dropped"
          % (plan.layout, plan.requested, extra, len(plan), len(plan.dropped)))
    for key, n in plan.drop_counts().items():
        first = [d for d in plan.dropped if d.reason == key][:_EXAMPLES]
        where = "; ".join("#%d at (%.3f, %.3f, %.3f)" % ((d.index + 1,) + d.point)
                          for d in first)
        print("Dropped:   %d %s: %s%s" % (n, _reason_text(key), where,
                                          " ..." if n > len(first) else ""))
    radius = ("%.4g mm" % plan.min_concave_radius if plan.min_concave_radius < float("inf")
              else "none (nowhere concave)")
    print("Probe:     tip radius %g mm, margin %g mm, max tilt %g deg, stand-off %g mm; "
          "smallest concave radius of the face %s"
          % (s.tip_radius, s.margin, s.max_tilt, s.stand_off, radius))
    print("Safe Z:    %.4f mm (part top %.4f + tip radius + clearance %g)"
          % (plan.safe_z, plan.top_z, s.clearance))
    print("Order:     %s; travel %.1f mm between retract positions" % (plan.order,
                                                                          plan.travel))
    print("Plan:      %d points, SHA-256 %s" % (len(plan), sha256))
    for out in (args.output, args.dropped):
        if out is not None:
            print(wrote(out))
