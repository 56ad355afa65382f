# SPDX-License-Identifier: LGPL-2.1-or-later
"""Options and printing shared by the CLI subcommands."""

import sys
import time

from ..core.memory import collector_paused
from ..core.option_tables import INPUTS
from . import registry
from .option_flags import shown
from .options import add_arguments


def add_job_parser(subparsers, name, summary, description):
    """The parser of a job command (``compensate``, ``inspect``) with its input options."""
    p = subparsers.add_parser(name, help=summary, description=description)
    add_input_options(p, name)
    return p


def add_input_options(p, command):
    """NOMINAL MEASUREMENTS, face choice, units, and the measurement checks."""
    registry.add_options(p, command, flags=("nominal", "measurements"))
    add_arguments(p, ("face", "object", "units", "deviation_units", "fmt", "sample"), INPUTS)
    add_arguments(p, ("max_offset", "flip_normals", "layout", "tip_radius"))
    registry.add_options(p, command, flags=("--plan",))
    registry.add_options(p, command, flags=("--report", "--transform"))
    p.add_argument("--quiet", action="store_true", help="print no progress lines")


def add_method_options(p):
    """The correction method and its filter, stock and surface options (registry order)."""
    add_arguments(p, ("method", "mask_size", "weights", "mask_kind", "sigma", "edge", "stock",
                      "accept_stock", "smoothing", "refine"))


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
        with collector_paused():
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
    """The core :class:`~surfcomp.core.compensation.pipeline.Options` of a command line: every
    option of the registry with a flag, its default where the command has no such flag."""
    from ..core.compensation.pipeline import Options
    from ..core.options import OPTIONS

    kw = {name: getattr(args, o.arg, o.default)
          for name, o in OPTIONS.items() if o.flag}
    return Options(**kw)


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
    from ..core.compensation import plausibility
    from ..core.compensation.deviations import format_table

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
        from ..core.measurement.align_report import summary_lines

        for line in summary_lines(rep["alignment"]):
            print(line, file=out)
    for w in p.warnings:
        print("warning: " + shown(w), file=sys.stderr)
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
    print("Correction:   method %s%s; applied along the normal: %.2f .. %.2f um (mean %.2f um; "
          "+ = material removed)"
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
        lines.append("  volume change %.4f mm^3; expected from the correction %.4f mm^3 "
                     "(-integral of delta dA)%s"
                     % (shape["volume_change_mm3"], -shape["correction_integral_mm3"],
                        "" if mismatch is None else ", %+.2f %%" % (100 * mismatch)))
    return lines
