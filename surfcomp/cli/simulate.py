# SPDX-License-Identifier: LGPL-2.1-or-later
"""``python3 -m surfcomp simulate``: virtual machining loop before cutting metal.

For every method and replica: machine a part (a semi-finishing and a finishing pass)
from the nominal with the machining-process model, measure it on the grid (the mirror
method: its own semi-finished part), compensate, machine a part from the corrected face
and measure it against the nominal at the grid nodes and between them. Prints the
papers' table (max negative, max positive, mean, std, ISO 1101 profile; mean and range
over the replicas) and the per-replica standard deviations (mirror paper Tab. 2).

``--preset NAME`` runs a case that imitates a paper (``surfcomp.core.simulation.presets``:
werner2022, mirror2019-s1, -s2, -s3) on its own surface, so NOMINAL may be left out,
and prints the paper's table beside the simulated one. Given a NOMINAL too, the preset's
process runs on that face instead; options given explicitly override the preset's.

Machining-process model (``surfcomp.core.simulation.process_model``; lengths in mm, defaults in
brackets), error ``e`` of a pass along the outward normal, positive = material left::

    e = offset + slope_gain * s + abs_slope_gain * |s|
        + tilt_f * xi + tilt_c * eta + bow_f * xi^2 + bow_c * eta^2 + E_axis . n
        + a * (k_0 + k_s * s + k_a * |s|)
        + waviness * sin(2 pi p_f / wavelength) + random

``a`` the depth the pass removes: ``semi_engagement`` for the semi-finishing pass
(programmed ``stock`` outside the CAM surface), ``stock + e_semi`` for the finishing
pass.

--offset MM             constant error (tool radius / wear) [0]
--slope-gain MM         per unit slope along the feed, s = dz/dfeed (signed) [0.06]
--abs-slope-gain MM     per unit |slope| (deflection grows with steepness) [0.03]
--tilt F,C              linear error at the work-area border along / across the feed [0,0.02]
--bow F,C               quadratic error at the border along / across the feed [-0.02,0.02]
--deflection K0,KS,KA   deflection per mm of engagement, and its growth with s and |s| [0,0,0]
--stock MM              allowance the semi-finishing pass leaves; the mirror method's
                        stock (DH = stock / 2) [0.3]
--semi-engagement MM    depth the semi-finishing pass removes [the stock]
--waviness MM           amplitude of a periodic error along the feed [0]
--wavelength MM         its wavelength [10]
--feed X,Y,Z            feed direction [1,0,0]; --tool-axis X,Y,Z [0,0,1]
--sigma MM              random machining error of every pass, standard deviation [0.0015]
--correlation-length MM random part correlated as exp(-(r/L)^2); 0 = independent [0]
--probe-sigma MM        measurement noise of every probed point [0.0005]
--axis-errors ERR.csv   machine-axis errors (Dobariya 2015 model fitted from the per-axis
                        file, as for ``gcode``) added along the normal [none]

xi, eta: position along / across the feed from the work-area centre over the half
extent (-1 .. 1). With the defaults the bundled example face spans about
-0.030 .. +0.043 mm (Werner 2022 Tab. 1: -0.030 .. +0.045 mm).
"""

import json
import os
import sys

import numpy as np

from ..core import budget
from ..core.command_options import AXIS_FILE, PRESET_SET, SIMULATE
from ..core.option_tables import INPUTS, MODEL
from ..core.options import OPTIONS
from ..core.progress import sub
from ..core.simulation import presets as presets_
from ..core.simulation import simulate as sim
from ..errors import InputError
from ..io.atomic import Transaction, check_outputs
from ..io.hashing import sha256_file
from ..io.outpath import shown
from . import SUMMARIES, option_flags, registry, simulate_plan
from .common import ProgressLine, wrote
from .options import add_arguments


def _count(o):
    """How many comma-separated numbers a model option of the registry takes."""
    return len(o.default) if o.type is tuple else 1


#: the loop's options a preset sets are unset (None) when not given
_PRESET = {name: dict(default=None) for name in PRESET_SET}


ALIGN_GROUP = "alignment of the simulated measurements"


def _fmt(v):
    if v is None:
        return "the stock"
    return ",".join("%g" % x for x in v) if isinstance(v, tuple) else "%g" % v


def add_parser(subparsers):
    p = subparsers.add_parser(
        "simulate", help=SUMMARIES["simulate"],
        description="Virtual machining loop (Werner 2022, mirror paper 2019): machine parts with "
                    "a machining-process model (semi-finishing and finishing pass), measure, "
                    "compensate with each method, machine the corrected face, measure again; "
                    "statistics per method over replicas. --preset imitates a paper and prints "
                    "its table beside the simulated one.",
        epilog="Model: e = offset + slope_gain*s + abs_slope_gain*|s| + tilt_f*xi + tilt_c*eta "
               "+ bow_f*xi^2 + bow_c*eta^2 + E_axis.n + a*(k_0 + k_s*s + k_a*|s|) "
               "+ waviness*sin(2 pi p_f/wavelength) + random (s = slope along the feed, xi/eta "
               "= position over the half extent along/across the feed, a = depth the pass "
               "removes: semi-engagement, then stock + the semi-finishing error). Presets: %s. "
               "See README 'Virtual machining'." % ", ".join(presets_.PRESETS))
    registry.add_options(p, "simulate", flags=("nominal",))
    add_arguments(p, ("face", "object"), INPUTS)
    p.add_argument("--preset", metavar="NAME",
                   help="a case imitating a paper: %s (its surface, model, grid and the "
                        "paper's table)" % ", ".join(presets_.PRESETS))
    g = p.add_argument_group("loop")
    add_arguments(g, ("grid", "margin", "between", "replicas", "methods"), SIMULATE, **_PRESET)
    # (no --weights or mask --sigma here: --sigma is the model's; the Gaussian mask's sigma
    # is a quarter of its size)
    add_arguments(g, ("mask_size", "mask_kind", "edge"), mask_size=dict(
        type=str, default=str(OPTIONS["mask_size"].default), metavar="N[,N...]",
        help="odd mask size(s) of the filtered method; one column per size (default %d)"
             % OPTIONS["mask_size"].default), mask_kind=dict(
        help="mask shape of the filtered method: box, or gaussian with sigma a quarter of "
             "the mask size in grid steps (default %s)" % OPTIONS["mask_kind"].default))
    add_arguments(g, ("stock",), SIMULATE, **_PRESET)
    add_arguments(g, ("refine",))
    add_arguments(g, ("seed",), SIMULATE)
    m = p.add_argument_group(registry.SIM_MODEL)
    for o in MODEL.values():        # the preset's values apply where an option is not given
        m.add_argument(o.flag, dest=o.name, metavar=o.metavar, default=None,
                       help="%s (default %s, or the preset's)" % (o.help, _fmt(o.default)))
    registry.add_options(p, "simulate", {registry.SIM_MODEL: m}, flags=("--axis-errors",))
    add_arguments(m, AXIS_FILE, AXIS_FILE)
    simulate_plan.add_options(p)
    a = p.add_argument_group(
        ALIGN_GROUP, "Align every simulated measurement before its compensation, as "
        "compensate --align aligns a file (--align, --align-dof, --rps below; README "
        "'Alignment'): the points are first moved by the inverse of --transform when it is "
        "given. The corrected parts are judged in the nominal's frame, so the tables show "
        "what the alignment absorbed.")
    registry.add_options(p, "simulate", {ALIGN_GROUP: a}, flags=("--transform",))
    o = p.add_argument_group(registry.SIM_OUTPUT)
    registry.add_options(p, "simulate", {registry.SIM_OUTPUT: o}, flags=("--json", "--html"))
    o.add_argument("--report-method", metavar="LABEL",
                   help="method of the HTML report (default filtered, else the first compensation)")
    o.add_argument("--quiet", action="store_true", help="print no progress lines")
    p.set_defaults(run=run)
    return p


def _numbers(text, count, option, negative=True):
    parts = str(text).replace(";", ",").split(",")
    try:
        vals = [float(t) for t in parts]
    except ValueError:
        vals = []
    if len(vals) != count or not all(np.isfinite(vals)):
        raise InputError("%s %r: expected %s" % (option, text, "a finite number" if count == 1
                                                 else "%d comma-separated numbers"
                                                 % count))
    if not negative and any(v < 0 for v in vals):
        raise InputError("%s %r: %s must be >= 0 mm" % (option, text,
                                                         option.lstrip("-").replace("-", " ")))
    return tuple(vals)


def parse_grid(text):
    """``'45x45'`` -> (45, 45); at least 3 x 3, at most ``MAX_GRID`` per direction."""
    parts = str(text).lower().replace("*", "x").split("x")
    try:
        n, m = (int(t) for t in parts)
    except ValueError:
        raise InputError("--grid %r: expected NxM, e.g. 45x45" % (text,)) from None
    if n < 3 or m < 3:
        raise InputError("--grid %r: expected at least 3x3 points" % (text,))
    if n > sim.MAX_GRID or m > sim.MAX_GRID:
        raise InputError("--grid %r: expected at most %dx%d points"
                         % (text, sim.MAX_GRID, sim.MAX_GRID))
    return n, m


def check_loop_options(args):
    """Refuse non-finite or out-of-range loop options, naming the option (exit 2); the
    domains are the registry's (:data:`~surfcomp.core.command_options.SIMULATE`)."""
    margin, stock, replicas = SIMULATE["margin"], SIMULATE["stock"], SIMULATE["replicas"]
    if not (np.isfinite(args.margin) and margin.low <= args.margin < margin.high):
        raise InputError("%s %r: expected %s" % (margin.flag, args.margin, margin.what))
    if args.stock is not None and not (np.isfinite(args.stock) and args.stock >= stock.low):
        raise InputError("%s %r: expected a finite allowance >= %g mm"
                         % (stock.flag, args.stock, stock.low))
    for o in (SIMULATE["between"], replicas, OPTIONS["refine"], SIMULATE["seed"]):
        val = getattr(args, o.arg)
        if val is not None and val < o.low:
            raise InputError("%s %d: expected a whole number >= %d" % (o.flag, val, o.low))
    if args.replicas is not None and args.replicas > replicas.high:
        raise InputError("%s %d: expected at most %d (the mirror paper machines 4 parts per "
                         "method)" % (replicas.flag, args.replicas, replicas.high))


def check_unread(args):
    """Refuse options that only go with another one not given (exit 2): the face of a
    NOMINAL, the HTML report's method, how the axis error file is read."""
    if args.nominal is None and (args.face or args.object):
        raise InputError("%s picks the face of NOMINAL, and none is given (expected NOMINAL, "
                         "or the preset's own surface without %s)"
                         % ((("--face",) if args.face else ("--object",)) * 2))
    if args.report_method is not None and not args.html:
        raise InputError("--report-method picks the method of the HTML report (expected "
                         "--html OUT.html with it)")
    if not args.axis_errors:
        for o in AXIS_FILE.values():
            if getattr(args, o.name) != o.default:
                raise InputError("%s tells how --axis-errors ERR.csv is read (expected the "
                                 "file with it)" % o.flag)


def loop_value(args, preset, name):
    """Option ``name`` of :data:`~surfcomp.core.command_options.SIMULATE` that a preset
    sets: the command line's, else the preset's, else the registry's default (the grid
    as ``(n, m)``)."""
    given = getattr(args, name)
    if name == "grid":
        return (parse_grid(given) if given is not None
                else preset.grid if preset else parse_grid(SIMULATE["grid"].default))
    if given is not None:
        return given
    return getattr(preset, name) if preset else SIMULATE[name].default


def model_from_args(args, preset=None):
    """The :class:`MachiningModel` of the command-line options: explicit options, else the
    preset's values, else the dataclass' defaults."""
    kw = dict(preset.model) if preset is not None else {}
    for key, o in MODEL.items():
        val = getattr(args, key)
        if val is not None:
            vals = _numbers(val, _count(o), o.flag, o.low is None)
            kw[key] = vals[0] if _count(o) == 1 else vals
    if args.stock is not None:
        kw["stock"] = float(args.stock)
    if args.axis_errors:
        from ..core.axis.axis_errors import fit_axis_errors
        from ..io.axis_csv import read_axis_errors

        if not (np.isfinite(args.max_error) and args.max_error > 0):
            raise InputError("--max-error %r: expected a positive length in mm"
                             % (args.max_error,))
        table = read_axis_errors(args.axis_errors, units=args.axis_units,
                                 max_error=args.max_error)
        kw["axis_errors"] = fit_axis_errors(table.data, model="auto",
                                            reference=_numbers(args.reference, 3, "--reference"),
                                            source=args.axis_errors)
    return sim.MachiningModel(**kw)


def _report_label(args, specs):
    if not args.html:
        return None
    comp_labels = [s.label for s in specs if s.method != "none"]
    if not comp_labels:
        raise InputError("--html needs a compensating method in --methods (the report "
                         "shows a compensation)")
    if args.report_method is None:
        return next((x for x in comp_labels if x.startswith("filtered")), comp_labels[0])
    if args.report_method not in comp_labels:
        raise InputError("--report-method %r: expected one of %s"
                         % (args.report_method, ", ".join(comp_labels)))
    return args.report_method


def _nominal(args, preset):
    """(surface, outward, inputs['nominal'], printed name) of the file or the preset."""
    if args.nominal is None:
        surface, outward = preset.surface()
        info = {"preset": preset.name, "surface": "BSplineSurface",
                "built_by": "surfcomp.core.simulation.presets (%s)" % preset.imitates}
        name = "preset %s surface (%s)" % (preset.name, preset.imitates)
    else:
        from ..app.nominal import load_nominal

        nominal = load_nominal(args.nominal, args.face, args.object)
        surface, outward = nominal.surface, nominal.outward
        info = {"path": os.path.abspath(args.nominal), "sha256": sha256_file(args.nominal),
                "face": nominal.face_name, "object": nominal.object_name,
                "surface": nominal.converted or "BSplineSurface"}
        name = "%s (%s" % (args.nominal, nominal.face_name)
    info.update(poles=list(surface.shape), degree=[surface.degree_u, surface.degree_v],
                rational=surface.weights is not None, u_range=list(surface.u_range),
                v_range=list(surface.v_range))
    return surface, outward, info, "%s, %d x %d poles%s" % (
        name, surface.shape[0], surface.shape[1], ")" if args.nominal else "")


def check_memory(grid, between, replicas, methods, limit):
    """Refuse a loop whose estimated peak memory is above ``limit`` (bytes; None: the
    machine's memory), before the work (:mod:`surfcomp.core.budget`)."""
    n, m = grid
    evaluated = ((n - 1) * between + 1) * ((m - 1) * between + 1)
    budget.check(budget.simulate_bytes(evaluated, n * m, replicas, methods), limit,
                 "simulate --grid %dx%d --between %d --replicas %d (%d methods)"
                 % (n, m, between, replicas, methods),
                 "a coarser --grid, --between 1 or fewer --replicas need less")


def run(args):
    preset = presets_.get_preset(args.preset) if args.preset else None
    if args.nominal is None and preset is None:
        raise InputError("give NOMINAL (a face file) or --preset NAME (one of %s)"
                         % ", ".join(presets_.PRESETS))
    check_loop_options(args)
    check_unread(args)
    grid, replicas, between = (loop_value(args, preset, name)
                               for name in ("grid", "replicas", "between"))
    try:
        masks = [int(x) for x in args.mask.split(",")]
    except ValueError:
        raise InputError("--mask %r: expected odd whole numbers, e.g. 5 or 3,5,7"
                         % args.mask) from None
    methods = [x.strip() for x in args.methods.split(",") if x.strip()]
    if not methods:
        raise InputError("--methods %r: expected a comma-separated list of some of %s"
                         % (args.methods, ", ".join(sim.SIM_METHODS)))
    specs = sim.method_specs(methods, masks, None, args.mask_kind, args.edge, args.refine)
    check_memory(grid, between, replicas, len(specs), args.max_memory)
    report_label = _report_label(args, specs)
    simulate_plan.check(args)
    model = model_from_args(args, preset)
    check_outputs(*_declared(args))
    align = _align_options(args)
    progress = ProgressLine(args.quiet)
    surface, outward, info, name = _nominal(args, preset)
    aligner = None
    if align is not None:
        from ..core.simulation.sim_align import SimAligner

        aligner = SimAligner(surface, outward, align, args.face or "Face1")
    loop = dict(grid=grid, specs=specs, replicas=replicas, seed=args.seed, margin=args.margin,
                between=between)
    if args.compare_layouts is not None:
        print("Nominal:   %s" % name)
        return simulate_plan.run_compare(args, surface, outward, model, loop,
                                         {"nominal": info}, sub(progress, 0, 0.95))
    plan = simulate_plan.resolve(args, surface, outward)
    res = sim.simulate(surface, outward, model, keep=bool(args.html),
                       progress=sub(progress, 0, 0.95),
                       points=None if plan is None else plan.points, aligner=aligner, **loop)
    res.preset = preset
    inputs = {"nominal": info}
    if plan is not None:
        inputs["plan"] = plan.info
    data = res.as_dict()
    if preset is not None and args.nominal is not None:
        data["preset"]["surface_replaced_by"] = info["path"]
    data = dict({"command": "simulate", "inputs": inputs}, **data)
    if aligner is not None:
        data["alignment"] = aligner.as_dict()
    _write(args, res, data, inputs, report_label)
    _print(args, res, grid, name, preset, plan)
    for line in aligner.summary() if aligner is not None else ():
        print(line)
    for line in _align_warnings(aligner):
        print("warning: " + option_flags.shown(line), file=sys.stderr)
    return 0


def _align_options(args):
    """The :class:`AlignOptions` of ``--align``/``--transform``/``--rps`` (files read and
    checked before the work), or None without them."""
    if args.align == "none" and not (args.transform or args.rps or args.align_dof):
        return None
    if args.compare_layouts is not None:
        raise InputError("--align/--transform do not go with --compare-layouts (expected a "
                         "single loop: --grid, --plan or --layout)")
    from ..core.measurement.align_report import AlignOptions
    from ..io.align_files import read_rps, read_transform

    transform = read_transform(args.transform) if args.transform else None
    rps = read_rps(args.rps)[0] if args.rps else None
    return AlignOptions(args.align, (), args.align_dof or "all", rps, transform,
                        args.transform).validate()


def _align_warnings(aligner):
    """The first fit's warnings (every fit warns alike)."""
    return list(aligner.records[0][2].warnings) if aligner and aligner.records else []


def _declared(args):
    """(outputs, inputs) of the command, checked before any work and at the commit."""
    return registry.declared(args, "simulate")


def _write(args, res, data, inputs, report_label):
    with Transaction(*_declared(args)) as tx:
        if args.json:
            tx.stage_text(args.json, json.dumps(data, indent=1, allow_nan=False) + "\n")
        if args.html:
            from ..io import report as report_io
            from ..io.html_report import render_html, simulation_maps

            comp = res.compensations[report_label]
            meas = {"path": "<simulated: replica 1, %s>" % report_label,
                    "sha256": _array_sha256(comp.prepared.deviation), "units": "mm",
                    "kind": "simulated nominal+normal+deviation",
                    "points": int(comp.prepared.u.size),
                    "columns": {}, "ignored_columns": []}
            rep = report_io.build_report("simulate", dict(inputs, measurements=meas), comp,
                                         comp.prepared.warnings,
                                         {"html": shown(args.html)})
            rep["alignment"] = data.get("alignment")
            tx.stage_text(args.html, render_html(rep, dict(data, maps=simulation_maps(res))))
        tx.commit()


def _print(args, res, grid, name, preset, plan=None):
    print("Nominal:   %s" % name)
    if preset is not None:
        print("Preset:    %s (%s)%s" % (preset.name, preset.imitates,
                                        "; surface replaced by NOMINAL" if args.nominal else ""))
    if plan is not None:
        print("Measured:  %s ('grid' statistics: at these points); %d x %d evaluated; "
              "%d replica(s), seed %d" % ((plan.text,) + res.eval_shape
                                          + (res.replicas, res.seed)))
    else:
        print("Grid:      %d x %d measured, %d x %d evaluated (nodes and between); "
              "%d replica(s), seed %d"
              % (grid + res.eval_shape + (res.replicas, res.seed)))
    print("Methods:   %s" % ", ".join(res.labels))
    print("")
    print(res.table())
    print("")
    print(res.replica_table("std"))
    if preset is not None:
        print("")
        print(res.side_table())
    for out in (args.json, args.html):
        if out is not None:
            print(wrote(out))


def _array_sha256(a):
    import hashlib

    return hashlib.sha256(np.ascontiguousarray(np.asarray(a, dtype="<f8")).tobytes()).hexdigest()
