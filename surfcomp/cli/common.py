# SPDX-License-Identifier: LGPL-2.1-or-later
"""Options and printing shared by the CLI subcommands."""

import sys
import time

from ..core.choices import EDGE_MODES, METHODS
from ..core.choices import MEASUREMENT_FORMATS as FORMATS
from . import registry, runner


def add_job_parser(subparsers, name, summary, description):
    """The parser of a job command (``compensate``, ``inspect``) with its input options."""
    p = subparsers.add_parser(name, help=summary, description=description)
    add_input_options(p, name)
    return p


def add_input_options(p, command):
    """NOMINAL MEASUREMENTS, face choice, units, and the measurement checks."""
    registry.add_options(p, command, flags=("nominal", "measurements"))
    p.add_argument("--face", metavar="FaceN",
                   help="the nominal face (default: the only B-spline face)")
    p.add_argument("--object", metavar="NAME", help="object holding the face (FCStd only)")
    p.add_argument("--units", choices=("mm", "um", "in"), default=None,
                   help="units of values that carry no unit of their own (column suffix, "
                        "XYZIJK METRIC, QIF FileUnits); default mm")
    p.add_argument("--deviation-units", choices=("mm", "um", "in"), default=None,
                   help="unit of a deviation column without a unit of its own, when it is "
                        "not the coordinates' (--units): a CMM report in mm with deviations "
                        "in um; default the same as --units")
    p.add_argument("--format", dest="fmt", choices=FORMATS, default="auto",
                   help="measurement file format (default auto: detected from the content)")
    p.add_argument("--sample", metavar="N|ID",
                   help="which measured part of a QIF file holding several: 0-based index, "
                        "serial number or MeasurementResults id (default the first)")
    p.add_argument("--max-offset", type=float, default=1.0, metavar="MM",
                   help="largest accepted distance of a point from the face (default 1 mm)")
    p.add_argument("--flip-normals", action="store_true",
                   help="the file's normals point into the material: flip them (and the sign "
                        "of its deviations)")
    p.add_argument("--layout", choices=("auto", "grid", "scattered"), default="auto",
                   help="arrangement of the points: auto (a complete grid if they form one, "
                        "else scattered, with a warning), grid (refuse anything else) or "
                        "scattered")
    p.add_argument("--tip-radius", type=float, default=0.0, metavar="MM",
                   help="stylus ball radius when the measured points are tip centres (probe "
                        "logs): each contact point is the centre moved by it against the "
                        "outward normal (default 0)")
    registry.add_options(p, command, flags=("--plan",))
    registry.add_options(p, command, flags=("--report", "--transform"))
    p.add_argument("--quiet", action="store_true", help="print no progress lines")


def add_method_options(p):
    p.add_argument("--method", choices=METHODS, default="filtered",
                   help="raw (Werner eq. 2), filtered (eq. 3-5, default), mirror (needs --stock), "
                        "offset (uniform tool-radius baseline)")
    p.add_argument("--mask", type=int, default=5, metavar="N",
                   help="odd mask size of the filter (default 5, as in Werner 2022)")
    p.add_argument("--weights", metavar="W",
                   help="custom mask weights, rows separated by ';', e.g. \"1 2 1; 2 4 2; 1 2 1\"")
    p.add_argument("--mask-kind", choices=("box", "gaussian"), default="box",
                   help="mask shape when no --weights are given (default box)")
    p.add_argument("--sigma", type=float, metavar="STEPS",
                   help="Gaussian sigma in grid steps (default mask size / 4)")
    p.add_argument("--edge", choices=EDGE_MODES, default="renormalize",
                   help="filter edge handling (default renormalize: divide by the weights on "
                        "measured points)")
    p.add_argument("--stock", type=float, metavar="MM",
                   help="semi-finishing allowance for --method mirror (DH = stock / 2); a "
                        "stock that does not fit the measured mean deviation is refused")
    p.add_argument("--accept-stock", action="store_true",
                   help="use the --stock although the measured mean deviation does not fit it "
                        "(a part measured with stock s has its mean within max(s/2, 3 x the "
                        "spread) of s; see docs/method.md)")
    p.add_argument("--smoothing", type=float, metavar="MM",
                   help="scattered layouts: smoothing length of the fit that takes the mask "
                        "filter's place (the wavelength damped to half; default chosen by "
                        "generalized cross-validation)")
    p.add_argument("--refine", type=int, default=4, metavar="K",
                   help="knot spans of the corrected surface per measurement grid step at most "
                        "(default 4): a grid along the face's parameter lines first gets one "
                        "span per step, kept when it meets the 0.1 um / 1 um limits")


def job_from_args(args, command):
    """The :class:`surfcomp.app.file_route.Job` of a ``compensate``/``inspect`` command line."""
    from ..app.file_route import Job

    outputs = {k: getattr(args, k, None) for k in ("output", "report", "points", "curves", "html")}
    return Job(nominal=args.nominal, measurements=args.measurements, command=command,
               face=args.face, object=args.object, units=args.units,
               deviation_units=args.deviation_units, fmt=args.fmt,
               sample=args.sample, face_only=bool(getattr(args, "face_only", False)),
               plan=args.plan, touches=args.touches,
               align=args.align, align_faces=args.align_faces, align_dof=args.align_dof,
               rps=args.rps, transform=args.transform,
               options=options_from_args(args), **outputs)


def run_job_command(args, command):
    """Run a job command line: progress on stderr, the summary, the files written."""
    from ..app import cadread

    try:
        with runner.collector_paused():
            # the nominal's reader child starts first and runs beside the imports of the
            # numerics
            cadread.prefetch(args.nominal)
            from ..app.file_route import run_job

        job = job_from_args(args, command)
        comp, rep = run_job(job, progress=ProgressLine(args.quiet),
                            inputs=registry.declared(args, command)[1],
                            max_memory=args.max_memory)
    finally:
        cadread.discard()
    print_summary(comp, rep)
    print_written(job)
    return 0


def print_written(job, out=None):
    """The ``wrote ...`` lines of a job's outputs."""
    from ..app.file_route import OUTPUT_OPTIONS

    for attr, _option in OUTPUT_OPTIONS:
        if getattr(job, attr) is not None:
            print(wrote(getattr(job, attr)), file=out or sys.stdout)


def wrote(path):
    """``wrote PATH`` (``-``: standard output)."""
    return "wrote %s" % ("- (standard output)" if path == "-" else path)


def options_from_args(args):
    from ..core.pipeline import Options

    return Options(method=getattr(args, "method", "filtered"), mask_size=getattr(args, "mask", 5),
                   weights=getattr(args, "weights", None),
                   mask_kind=getattr(args, "mask_kind", "box"), sigma=getattr(args, "sigma", None),
                   edge=getattr(args, "edge", "renormalize"), stock=getattr(args, "stock", None),
                   max_offset=args.max_offset, flip_normals=args.flip_normals,
                   tip_radius=args.tip_radius, layout=args.layout,
                   smoothing=getattr(args, "smoothing", None),
                   refine=getattr(args, "refine", 4),
                   accept_stock=bool(getattr(args, "accept_stock", False)))


class ProgressLine:
    """Prints ``[ 42%] message`` lines to stderr, at most every half second."""

    def __init__(self, quiet=False, stream=None):
        self.quiet = quiet
        self.stream = stream or sys.stderr
        self._last = 0.0

    def __call__(self, fraction, message=""):
        now = time.monotonic()
        if self.quiet or (now - self._last < 0.5 and fraction < 1.0):
            return
        self._last = now
        print("[%3d%%] %s" % (round(100 * fraction), message), file=self.stream, flush=True)


def print_summary(comp, rep, out=None):
    """The papers' table form, the correction applied and the corrected face's checks, on
    ``out`` (default: ``sys.stdout`` as it is at the call, so a redirection holds)."""
    from ..core import plausibility
    from ..core.deviations import format_table

    out = sys.stdout if out is None else out
    p = comp.prepared
    st = comp.statistics
    inputs = rep["inputs"]
    print("Nominal:      %s (%s, %s, %d x %d poles, degree %d x %d)"
          % (inputs["nominal"]["path"], inputs["nominal"]["face"], inputs["nominal"]["surface"],
             *inputs["nominal"]["poles"], *inputs["nominal"]["degree"]), file=out)
    print("Measurements: %s (%d points, %s, read in %s)"
          % (inputs["measurements"]["path"], inputs["measurements"]["points"],
             inputs["measurements"]["kind"], inputs["measurements"]["units"]), file=out)
    if "plan" in inputs:
        print("Plan:         %s (the log's lines joined to its points in order, %d per point)"
              % (inputs["plan"]["path"], inputs["plan"]["touches"]), file=out)
    if p.scattered:
        print("Layout:       %d scattered points (%s)" % (p.u.size, p.grid.rows_from), file=out)
    else:
        print("Grid:         %d x %d (%s)" % (p.grid.shape + (p.grid.rows_from,)), file=out)
    if rep.get("alignment"):        # (its module only then: the alignment's numerics)
        from ..core.align_report import summary_lines

        for line in summary_lines(rep["alignment"]):
            print(line, file=out)
    for w in p.warnings:
        print("warning: " + w, file=sys.stderr)
    o = comp.options
    c = comp.correction
    print("", file=out)
    if comp.fit is not None:
        f = comp.fit
        kind = "thin-plate spline" if f.method == "tps" else "penalised B-spline"
        how = ("%s smoothing fit, smoothing length %.3g mm (%s); fit residual RMS %.2f um, "
               "leave-one-out RMS %.2f um" % (kind, f.smoothing, f.chosen_by, f.fit_rms * 1e3,
                                              f.loo_rms * 1e3))
    else:
        how = "%dx%d %s filter, eq. 4-5" % (c.mask.shape[0], c.mask.shape[0],
                                            rep["method"]["mask_kind"])
    print(format_table([("Raw deviations", st["deviation"]),
                        ("Determined", st["determined"]),
                        ("Random", st["random"])], unit="um",
                       title="Deviations along the outward normal (Werner 2022 Tab. 1 and 3; "
                             "determined = %s)" % how), file=out)
    if comp.corrected is None:
        return
    extra = ""
    notes = []
    if o.method == "mirror":
        extra = ", stock %g mm (DH = %g mm)" % (o.stock, o.stock / 2)
        check = plausibility.stock_check(p.deviation, o.stock)
        notes = ["  stock check: %s: %s" % (check.describe(), "consistent" if check.consistent
                                            else "INCONSISTENT, used by --accept-stock"),
                 "  " + plausibility.residual_assumption(o.method, o.stock)]
    print("", file=out)
    print("Correction:   method %s%s; applied along the normal: %.2f .. %.2f um (mean %.2f um)"
          % (o.method, extra, st["correction"].min * 1e3,
             st["correction"].max * 1e3, st["correction"].mean * 1e3), file=out)
    for line in notes:
        print(line, file=out)
    ch = comp.checks
    print("Corrected face: %d x %d poles, degree %d x %d%s"
          % (ch.poles_shape + (comp.corrected.degree_u, comp.corrected.degree_v,
                               ", rational" if comp.corrected.weights is not None else "")),
          file=out)
    print("  realised - intended correction at the %d measured points: max %.4f um"
          % (p.u.size, ch.max_error_at_points * 1e3), file=out)
    print("  zero correction reproduces the nominal within %.4f um (on a %d x %d check grid)"
          % ((ch.max_zero_deviation * 1e3,) + tuple(ch.dense_shape)), file=out)
    print("  largest correction anywhere on the face %.3f um (largest intended %.3f um)"
          % (ch.max_realised * 1e3, ch.max_intended * 1e3), file=out)
    for line in output_lines(rep.get("output_shape")):
        print(line, file=out)


def output_lines(shape):
    """What the written shape is: the report's ``output_shape``, as summary lines."""
    if not shape:
        return []
    size = ["  file size %d bytes" % shape["file_bytes"]] if "file_bytes" in shape else []
    if shape["kind"] == "face":
        return ["Output:       the corrected face alone (largest edge tolerance %.2g mm)"
                % shape["max_edge_tolerance_mm"],
                "  the correction integrates to %.4f mm^3 over it (positive = material removed)"
                % shape["correction_integral_mm3"]] + size
    lines = ["Output:       the nominal's shape with the face replaced (%d faces, %d solids; "
             "re-trimmed neighbours: %s; largest edge tolerance of the face %.2g mm)"
             % (shape["faces"], shape["solids"], ", ".join(shape["retrimmed_faces"]) or "none",
                shape["max_edge_tolerance_mm"])] + size
    if shape["volume_change_mm3"] is not None:
        mismatch = shape["volume_change_vs_integral"]
        lines.append("  volume change %.4f mm^3; the correction integrates to %.4f mm^3 "
                     "(-integral of delta dA)%s"
                     % (shape["volume_change_mm3"], -shape["correction_integral_mm3"],
                        "" if mismatch is None else ", %+.2f %%" % (100 * mismatch)))
    return lines
