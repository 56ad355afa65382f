# SPDX-License-Identifier: LGPL-2.1-or-later
"""``simulate`` with a measurement plan: measure the simulated parts at a plan's points
(``--plan PLAN.csv``, or ``--layout``/``--count``/``--points`` planned on the face as
``python3 -m surfcomp plan`` does, with its default probe), and ``--compare-layouts N``:
N adaptive against N uniform points on the same parts
(:mod:`surfcomp.core.simulation.sim_layouts`). ``--grid`` then sets the evaluation grid only (the
corrected parts are evaluated on it, nodes and points between them)."""

import json
from dataclasses import dataclass

import numpy as np

from ..core.measurement.planning import (
    POINT_LAYOUTS,
    PlanSettings,
    check_points,
    parse_count,
)
from ..core.option_tables import SIM_PLAN
from ..errors import InputError, MeasurementFileError
from . import registry
from .options import add_arguments

#: a plan's point farther than this (mm) from the nominal face is refused
PLAN_TOLERANCE = 0.01
GROUP = "measurement plan (instead of the --grid nodes)"


def add_options(p):
    g = p.add_argument_group(GROUP)
    registry.add_options(p, "simulate", {GROUP: g}, flags=("--plan",))
    add_arguments(g, SIM_PLAN, SIM_PLAN)      # the plan's records (option_tables.PLAN)


@dataclass
class PlanChoice:
    """Where the simulated parts are measured: ``points`` (P, 3) and how they came."""

    points: np.ndarray
    text: str
    info: dict


def wanted(args):
    """Whether the command line asks for plan points or a comparison."""
    return any(x is not None for x in (args.plan, args.plan_layout, args.plan_count,
                                       args.plan_points, args.compare_layouts))


def check(args):
    """Refuse contradicting plan options (exit 2) before any work."""
    if not wanted(args):
        return
    given = [o for o, v in (("--plan", args.plan), ("--layout", args.plan_layout),
                            ("--compare-layouts", args.compare_layouts)) if v is not None]
    if len(given) > 1:
        raise InputError("%s: give one of --plan, --layout or --compare-layouts"
                         % " and ".join(given))
    if args.html:
        raise InputError("--html shows the maps of grid measurements; it does not go with %s"
                         % (given[0] if given else "--count/--points"))
    if args.compare_layouts is not None:
        check_points(args.compare_layouts, "compare_layouts")
    if (args.plan_count is not None or args.plan_points is not None) and not args.plan_layout:
        raise InputError("--count and --points go with --layout")
    if args.plan_layout:
        _layout_count(args)


def _layout_count(args):
    if args.plan_layout in POINT_LAYOUTS:
        if args.plan_count is not None or args.plan_points is None:
            raise InputError("--layout %s takes --points N" % args.plan_layout)
        return check_points(args.plan_points)
    if args.plan_points is not None or args.plan_count is None:
        raise InputError("--layout %s takes --count UxV" % args.plan_layout)
    return parse_count(args.plan_count)


def domain_of(args, surface, outward):
    """The face for planning: the file's face with its trim boundary, or the preset's."""
    from ..core.measurement.planning_face import FaceDomain

    if args.nominal is None:
        return FaceDomain(surface, outward)
    from ..app.nominal import boundary_polylines, load_nominal

    nominal = load_nominal(args.nominal, args.face, args.object)
    return FaceDomain(surface, outward, boundary_polylines(nominal.bspline_face))


def resolve(args, surface, outward):
    """The :class:`PlanChoice` of the command line (None: the grid nodes)."""
    if args.plan is not None:
        return _read_plan(args.plan, surface)
    if args.plan_layout is None:
        return None
    from ..core.measurement.planning import plan_points

    count = _layout_count(args)
    plan = plan_points(domain_of(args, surface, outward), args.plan_layout, count,
                       PlanSettings())
    what = ("%d points" % count if args.plan_layout in POINT_LAYOUTS
            else "%d x %d" % tuple(count))
    return PlanChoice(plan.points, "%d points of the %s layout (%s placed, %d dropped)"
                      % (len(plan), args.plan_layout, what, len(plan.dropped)),
                      {"layout": args.plan_layout, "placed": plan.requested,
                       "points": len(plan), "dropped": plan.drop_counts()})


def _read_plan(path, surface):
    from ..core.surface.projection import Projector
    from ..io.hashing import sha256_file
    from ..io.measurements import read_measurements

    ms = read_measurements(path, plan=True)
    dist = np.abs(Projector(surface).project(ms.nominal).distance)
    bad = np.flatnonzero(~(dist <= PLAN_TOLERANCE))
    if bad.size:
        k = int(bad[0])
        raise MeasurementFileError("point %s lies %.4g mm from the nominal face (expected the "
                                   "plan of this face: at most %g mm)"
                                   % (ms.ids[k] if ms.ids else k + 1, dist[k], PLAN_TOLERANCE),
                                   file=path, line=int(ms.lines[k]))
    return PlanChoice(ms.nominal, "%d points of %s" % (len(ms.nominal), path),
                      {"path": path, "sha256": sha256_file(path), "points": len(ms.nominal)})


def run_compare(args, surface, outward, model, loop, inputs, progress):
    """``--compare-layouts N``: both loops, their tables, the comparison; JSON if asked."""
    from ..core.simulation.sim_layouts import compare_layouts
    from ..io.atomic import Transaction
    from .common import wrote

    cmp = compare_layouts(domain_of(args, surface, outward), model, args.compare_layouts,
                          progress=progress, **loop)
    for layout in ("uniform", "adaptive"):
        res = cmp.results[layout]
        print("%s layout: %d points measured, evaluated on %d x %d; %d replica(s), seed %d"
              % ((layout.capitalize(), len(cmp.plans[layout])) + res.eval_shape
                 + (res.replicas, res.seed)))
        print(res.table())
        print("")
    print(cmp.table())
    if args.json:
        data = {"command": "simulate", "inputs": inputs, "compare_layouts": cmp.as_dict(),
                "uniform": cmp.results["uniform"].as_dict(),
                "adaptive": cmp.results["adaptive"].as_dict()}
        with Transaction(*registry.declared(args, "simulate")) as tx:
            tx.stage_text(args.json, json.dumps(data, indent=1, allow_nan=False) + "\n")
            tx.commit()
        print(wrote(args.json))
    return 0
