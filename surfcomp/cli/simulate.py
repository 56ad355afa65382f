"""``python3 -m surfcomp simulate``: virtual machining loop before cutting metal.

For every method and replica: machine the nominal with the machining-error model,
measure it on the grid, compensate, machine the corrected face with the same model
and measure it against the nominal at the grid nodes and between them. Prints the
papers' table (max negative, max positive, mean, std, ISO 1101 profile; mean and
range over the replicas) and the per-replica standard deviations (mirror paper Tab. 2).

Machining-error model (``surfcomp.core.simulate``; lengths in mm, defaults in brackets),
error ``e`` along the outward normal, positive = material left::

    e = offset + slope_gain * s + abs_slope_gain * |s|
        + tilt_f * xi + tilt_c * eta + bow_f * xi^2 + bow_c * eta^2
        + waviness * sin(2 pi p_f / wavelength) + E_axis . n + random

--offset MM             constant error (tool radius / wear) [0]
--slope-gain MM         per unit slope along the feed, s = dz/dfeed (signed) [0.06]
--abs-slope-gain MM     per unit |slope| (deflection grows with steepness) [0.03]
--tilt F,C              linear error at the work-area border along / across the feed [0,0.02]
--bow F,C               quadratic error at the border along / across the feed [-0.02,0.02]
--waviness MM           amplitude of a periodic error along the feed [0]
--wavelength MM         its wavelength [10]
--feed X,Y,Z            feed direction [1,0,0]; --tool-axis X,Y,Z [0,0,1]
--sigma MM              random machining error, standard deviation [0.0015]
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
from dataclasses import fields

import numpy as np

from ..core import simulate as sim
from ..core.filters import EDGE_MODES
from ..core.progress import sub
from ..errors import InputError
from ..io.atomic import Transaction
from ..io.hashing import sha256_file
from .common import ProgressLine

_DEFAULTS = {f.name: f.default for f in fields(sim.MachiningModel)}


def _fmt(v):
    return ",".join("%g" % x for x in v) if isinstance(v, tuple) else "%g" % v


def add_parser(subparsers):
    p = subparsers.add_parser(
        "simulate", help="virtual machining: predict what each compensation method achieves",
        description="Virtual machining loop (Werner 2022, mirror paper): machine the nominal with "
                    "a machining-error model, measure, compensate with each method, machine the "
                    "corrected face, measure again; statistics per method over replicas.",
        epilog="Model: e = offset + slope_gain*s + abs_slope_gain*|s| + tilt_f*xi + tilt_c*eta "
               "+ bow_f*xi^2 + bow_c*eta^2 + waviness*sin(2 pi p_f/wavelength) + E_axis.n "
               "+ random (s = slope along the feed, xi/eta = position over the half extent "
               "along/across the feed). See README 'Virtual machining'.")
    p.add_argument("nominal", metavar="NOMINAL",
                   help="nominal face: STEP/IGES/BREP file or FreeCAD document (.FCStd)")
    p.add_argument("--face", metavar="FaceN",
                   help="the nominal face (default: the only B-spline face)")
    p.add_argument("--object", metavar="NAME", help="object holding the face (FCStd only)")
    g = p.add_argument_group("loop")
    g.add_argument("--grid", default="45x45", metavar="NxM",
                   help="measurement grid, uniform in the face parameters (default 45x45, "
                        "Werner 2022)")
    g.add_argument("--margin", type=float, default=0.02, metavar="FRACTION",
                   help="parameter range left free at each border (default 0.02)")
    g.add_argument("--between", type=int, default=2, metavar="K",
                   help="the corrected parts are measured on a grid K times denser (grid nodes "
                        "and points between them; default 2)")
    g.add_argument("--replicas", type=int, default=4, metavar="N",
                   help="parts machined per method (default 4, as the mirror paper)")
    g.add_argument("--methods", default="none,offset,raw,filtered,mirror", metavar="LIST",
                   help="comma-separated methods: none, offset, raw, filtered, mirror "
                        "(default all)")
    g.add_argument("--mask", default="5", metavar="N[,N...]",
                   help="odd mask size(s) of the filtered method; one column per size (default 5)")
    g.add_argument("--mask-kind", choices=("box", "gaussian"), default="box",
                   help="mask shape (default box)")
    g.add_argument("--edge", choices=EDGE_MODES, default="renormalize", help="filter edge handling")
    g.add_argument("--stock", type=float, default=0.3, metavar="MM",
                   help="semi-finishing allowance of the mirror method (default 0.3 mm)")
    g.add_argument("--refine", type=int, default=4, metavar="K",
                   help="knot spans of the corrected surface per grid step (default 4)")
    g.add_argument("--seed", type=int, default=0, metavar="N", help="random seed (default 0)")
    m = p.add_argument_group("machining-error model (mm)")
    for name, metavar, text in (
            ("offset", "MM", "constant error (tool radius/wear)"),
            ("slope-gain", "MM", "error per unit slope along the feed (signed)"),
            ("abs-slope-gain", "MM", "error per unit |slope| along the feed"),
            ("tilt", "F,C", "linear error at the work-area border along,across the feed"),
            ("bow", "F,C", "quadratic error at the border along,across the feed"),
            ("waviness", "MM", "amplitude of a periodic error along the feed"),
            ("wavelength", "MM", "wavelength of the waviness"),
            ("feed", "X,Y,Z", "feed direction"),
            ("tool-axis", "X,Y,Z", "tool axis"),
            ("sigma", "MM", "random machining error, standard deviation"),
            ("correlation-length", "MM", "correlation length of the random part (0: independent)"),
            ("probe-sigma", "MM", "measurement noise, standard deviation")):
        key = name.replace("-", "_")
        m.add_argument("--" + name, dest=key, metavar=metavar, default=None,
                       help="%s (default %s)" % (text, _fmt(_DEFAULTS[key])))
    m.add_argument("--axis-errors", metavar="ERR.csv",
                   help="per-axis error measurements (as for the gcode command); the fitted "
                        "Dobariya 2015 model adds its error along the normal")
    m.add_argument("--axis-units", choices=("mm", "um", "in"), default="mm",
                   help="units of the axis error file without unit suffixes (default mm)")
    m.add_argument("--reference", default="0,0,0", metavar="X,Y,Z",
                   help="reference point of the axis error measurements (default 0,0,0)")
    o = p.add_argument_group("output")
    o.add_argument("--json", metavar="OUT.json", help="write every replica's statistics (JSON)")
    o.add_argument("--html", metavar="OUT.html",
                   help="write the HTML report of the first replica's compensation with the "
                        "--report-method, and the before/after table")
    o.add_argument("--report-method", metavar="LABEL",
                   help="method of the HTML report (default filtered, else the first compensation)")
    o.add_argument("--quiet", action="store_true", help="print no progress lines")
    p.set_defaults(run=run)
    return p


def _numbers(text, count, option):
    parts = str(text).replace(";", ",").split(",")
    try:
        vals = [float(t) for t in parts]
    except ValueError:
        vals = []
    if len(vals) != count or not all(np.isfinite(vals)):
        raise InputError("%s %r: expected %d comma-separated numbers" % (option, text, count))
    return tuple(vals)


def parse_grid(text):
    """``'45x45'`` -> (45, 45)."""
    parts = str(text).lower().replace("*", "x").split("x")
    try:
        n, m = (int(t) for t in parts)
    except ValueError:
        raise InputError("--grid %r: expected NxM, e.g. 45x45" % (text,)) from None
    if n < 3 or m < 3:
        raise InputError("--grid %r: expected at least 3x3 points" % (text,))
    return n, m


def model_from_args(args):
    """The :class:`MachiningModel` of the command-line options (defaults: the dataclass')."""
    kw = {}
    for key in ("offset", "slope_gain", "abs_slope_gain", "waviness", "wavelength", "sigma",
                "correlation_length", "probe_sigma"):
        val = getattr(args, key)
        if val is not None:
            kw[key] = _numbers(val, 1, "--" + key.replace("_", "-"))[0]
    for key, count in (("tilt", 2), ("bow", 2), ("feed", 3), ("tool_axis", 3)):
        val = getattr(args, key)
        if val is not None:
            kw[key] = _numbers(val, count, "--" + key.replace("_", "-"))
    if args.axis_errors:
        from ..core.axis_errors import fit_axis_errors
        from ..io.axis_csv import read_axis_errors

        table = read_axis_errors(args.axis_errors, units=args.axis_units)
        kw["axis_errors"] = fit_axis_errors(table.data, model="auto",
                                            reference=_numbers(args.reference, 3, "--reference"),
                                            source=args.axis_errors)
    return sim.MachiningModel(**kw)


def run(args):
    from ..app.nominal import load_nominal

    grid = parse_grid(args.grid)
    if args.replicas < 1:
        raise InputError("--replicas %d: expected at least 1" % args.replicas)
    try:
        masks = [int(x) for x in args.mask.split(",")]
    except ValueError:
        raise InputError("--mask %r: expected odd whole numbers, e.g. 5 or 3,5,7"
                         % args.mask) from None
    methods = [x.strip() for x in args.methods.split(",") if x.strip()]
    specs = sim.method_specs(methods, masks, args.stock, args.mask_kind, args.edge, args.refine)
    labels = [s.label for s in specs]
    report_label = args.report_method
    if args.html:
        comp_labels = [s.label for s in specs if s.method != "none"]
        if not comp_labels:
            raise InputError("--html needs a compensating method in --methods (the report "
                             "shows a compensation)")
        if report_label is None:
            report_label = next((x for x in comp_labels if x.startswith("filtered")),
                                comp_labels[0])
        elif report_label not in comp_labels:
            raise InputError("--report-method %r: expected one of %s"
                             % (report_label, ", ".join(comp_labels)))
    model = model_from_args(args)
    for out in (args.json, args.html):
        if out and os.path.abspath(out) == os.path.abspath(args.nominal):
            raise InputError("an output would overwrite the nominal", file=out)
    progress = ProgressLine(args.quiet)
    nominal = load_nominal(args.nominal, args.face, args.object)
    res = sim.simulate(nominal.surface, nominal.outward, model, grid=grid, specs=specs,
                       replicas=args.replicas, seed=args.seed, margin=args.margin,
                       between=args.between, keep=bool(args.html), progress=sub(progress, 0, 0.95))
    inputs = {"nominal": {"path": os.path.abspath(args.nominal),
                          "sha256": sha256_file(args.nominal),
                          "face": nominal.face_name, "object": nominal.object_name,
                          "surface": nominal.converted or "BSplineSurface",
                          "poles": list(nominal.surface.shape),
                          "degree": [nominal.surface.degree_u, nominal.surface.degree_v],
                          "rational": nominal.surface.weights is not None,
                          "u_range": list(nominal.surface.u_range),
                          "v_range": list(nominal.surface.v_range)}}
    data = res.as_dict()
    data = dict({"command": "simulate", "inputs": inputs}, **data)
    with Transaction() as tx:
        if args.json:
            tx.stage_text(args.json, json.dumps(data, indent=1, allow_nan=False) + "\n")
        if args.html:
            from ..io import report as report_io
            from ..io.html_report import render_html

            comp = res.compensations[report_label]
            meas = {"path": "<simulated: replica 1, %s>" % report_label,
                    "sha256": _array_sha256(comp.prepared.deviation), "units": "mm",
                    "kind": "simulated nominal+normal+deviation",
                    "points": int(comp.prepared.u.size),
                    "columns": {}, "ignored_columns": []}
            rep = report_io.build_report("simulate", dict(inputs, measurements=meas), comp,
                                         comp.prepared.warnings,
                                         {"html": os.path.abspath(args.html)})
            tx.stage_text(args.html, render_html(rep, data))
        tx.commit()
    print("Nominal:   %s (%s, %d x %d poles)"
          % (args.nominal, nominal.face_name, *nominal.surface.shape))
    print("Grid:      %d x %d measured, %d x %d evaluated (nodes and between); "
          "%d replica(s), seed %d"
          % (grid + res.eval_shape + (res.replicas, res.seed)))
    print("Methods:   %s" % ", ".join(labels))
    print("")
    print(res.table())
    print("")
    print(res.replica_table("std"))
    for out in (args.json, args.html):
        if out:
            print("wrote %s" % out)
    return 0


def _array_sha256(a):
    import hashlib

    return hashlib.sha256(np.ascontiguousarray(np.asarray(a, dtype="<f8")).tobytes()).hexdigest()
