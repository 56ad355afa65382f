# SPDX-License-Identifier: LGPL-2.1-or-later
"""``python3 -m surfcomp gcode``: compensate a G-code program for machine-axis errors.

Dobariya et al. 2015: per-axis error measurements -> 1-D linear/quadratic error functions
-> 12-component error model (eq. 6-16) -> compensated NC program. See docs/axis_errors.md.
"""

import datetime
import json
import os
import sys

import numpy as np

from .. import __version__
from ..core import budget
from ..core.axis.axis_checks import volumetric_map
from ..core.axis.axis_errors import fit_axis_errors
from ..core.axis.moves import MIN_SEGMENT_LENGTH
from ..core.command_options import GCODE
from ..errors import GCodeError, InputError
from ..io.atomic import Transaction, check_outputs
from ..io.axis_csv import read_axis_errors
from ..io.gcode import ProgramFile, compensate_stream
from ..io.gcode.interpreter import MAX_POSITION
from ..io.hashing import sha256_file
from ..io.outpath import shown
from . import SUMMARIES, registry
from .common import wrote
from .options import add_arguments, check_range

SCHEMA = "surfcomp-gcode-report/1"


def add_parser(subparsers):
    p = subparsers.add_parser(
        "gcode", help=SUMMARIES["gcode"],
        description="Rewrite a 3-axis G-code program so that a machine with the measured "
                    "geometric axis errors (Dobariya 2015: scale, straightness, flatness, "
                    "squareness; linear or quadratic per axis) lands on the programmed "
                    "points. Lines that need no change are kept byte for byte.")
    registry.add_options(p, "gcode", flags=("program", "--axis-errors", "-o"))
    add_arguments(p, ("segment_length", "model"), GCODE)
    registry.add_options(p, "gcode", flags=("--report",))
    add_arguments(p, tuple(GCODE)[2:], GCODE)
    p.set_defaults(run=run)
    return p


def _triple(text, option):
    parts = [t for t in text.replace(";", ",").split(",")]
    try:
        vals = [float(t) for t in parts]
    except ValueError:
        vals = []
    if len(vals) != 3 or not all(np.isfinite(vals)):
        raise InputError("%s %r: expected three numbers X,Y,Z in mm" % (option, text))
    if not all(abs(v) <= MAX_POSITION for v in vals):
        raise InputError("%s %r: expected three numbers X,Y,Z in mm, each within %g mm (1 km, "
                         "as G-code positions)" % (option, text, MAX_POSITION))
    return np.array(vals)


def _positive(value, option, minimum=None):
    """``value`` when it is finite and > 0 (and >= ``minimum``); NaN is refused."""
    if minimum is not None and not (np.isfinite(value) and value >= minimum):
        raise InputError("%s %r: expected a positive length of at least %g mm"
                         % (option, value, minimum))
    if not (np.isfinite(value) and value > 0):
        raise InputError("%s %r: expected a positive length in mm" % (option, value))
    return value


def _um(v):
    return v * 1e3


class _Travel:
    """Program points outside the measured travel, block by block: count and largest
    distance (mm) of the points written whose axes are all known (move ends and the points
    along split moves and arcs turned into segments, as the --max-error check sees them)."""

    def __init__(self, model):
        lo, hi = model.travel[:, 0], model.travel[:, 1]
        self.ok = np.isfinite(lo) & np.isfinite(hi)
        self.lo, self.hi = lo, hi
        self.count, self.dist = 0, 0.0

    def add(self, nominal, known):
        points = nominal[known]
        if points.size == 0:
            return
        below = np.where(self.ok, self.lo - points, 0.0)
        above = np.where(self.ok, points - self.hi, 0.0)
        dist = np.maximum(np.maximum(below, above), 0.0).max(axis=1)
        self.count += int((dist > 1e-9).sum())
        self.dist = max(self.dist, float(dist.max()))


def run(args):
    check_outputs(*registry.declared(args, "gcode"))
    seg = _positive(args.segment_length, "--segment-length", MIN_SEGMENT_LENGTH)
    tol = _positive(args.tolerance, "--tolerance")
    arc_tol = _positive(args.arc_tolerance, "--arc-tolerance")
    max_error = _positive(args.max_error, "--max-error")
    check_range(GCODE["decimals"], args.decimals)
    reference = _triple(args.reference, "--reference")
    offset = None if args.work_offset is None else _triple(args.work_offset, "--work-offset")
    start = None if args.start is None else _triple(args.start, "--start")

    table = read_axis_errors(args.axis_errors, units=args.units, max_error=max_error)
    model = fit_axis_errors(table.data, model=args.model, reference=reference,
                            source=args.axis_errors)
    prog_model = model if offset is None else model.in_program_coordinates(offset)
    program = ProgramFile(args.program)
    lines = program.count_lines()
    budget.check(budget.gcode_bytes(lines), args.max_memory, "gcode on %d lines" % lines,
                 "split the program into parts")
    travel = _Travel(prog_model)
    outputs = {"program": shown(args.output)}
    with Transaction(*registry.declared(args, "gcode")) as tr:
        comp = []

        def put(tmp):
            with open(tmp, "wb") as fh:
                comp.append(compensate_stream(
                    program, lambda text: fh.write(text.encode("latin-1")), prog_model,
                    segment_length=seg, tolerance=tol, arc_tolerance=arc_tol,
                    decimals=args.decimals, start=start, source=args.program,
                    max_error=max_error, names=("--segment-length", "--arc-tolerance"),
                    visit=travel.add))

        tr.write(args.output, put)
        comp = comp[0]
        if not comp.words:
            raise GCodeError("the program is empty (no G-code words, only blank lines, "
                             "comments or % lines; expected G0/G1/G2/G3 moves)",
                             file=args.program)
        stats = comp.stats()
        pred = dict(comp.totals.predicted(), max_correction_mm=comp.totals.max_correction)
        warnings = comp.warnings()
        if travel.count:
            warnings.append("%d program point(s) lie outside the measured travel (up to %.3f "
                            "mm): the error functions are extrapolated there"
                            % (travel.count, travel.dist))
        warnings.extend(table.warnings + _model_warnings(model))
        vmap = volumetric_map(model)
        if args.report:
            outputs["report"] = shown(args.report)
            rep = build_report(args, table, model, prog_model, stats, pred, vmap, warnings,
                               outputs, seg, tol, arc_tol, reference, offset, start)
            tr.stage_text(args.report, json.dumps(rep, indent=1, allow_nan=False) + "\n")
        tr.commit()

    print_summary(args, table, model, stats, pred, vmap, warnings)
    for path in (args.output, args.report):
        if path is not None:
            print(wrote(path))
    return 0


def _model_warnings(model):
    """A warning when the axes disagree about the error at the reference point."""
    spread = model.offset_spread
    rms_fit = max([f.rms for f in model.fits] or [0.0])
    if spread.max() > max(1e-3, 3 * rms_fit):
        return ["the axes disagree about the error at the reference point by up to %.3f um: "
                "are the tables measured from the same reference (--reference)?"
                % _um(spread.max())]
    return []


def print_summary(args, table, model, stats, pred, vmap, warnings, out=None):
    """The fitted model, the predicted errors and what was rewritten (stdout)."""
    out = sys.stdout if out is None else out
    rows = table.rows()
    print("Axis errors:  %s (%s layout; %s)"
          % (args.axis_errors, table.layout,
             ", ".join("%s %d rows" % (a.upper(), n) for a, n in rows.items())), file=out)
    for line in model.summary_lines():
        print(line, file=out)
    env = vmap.as_dict()["envelope_mm"]
    print("Predicted volumetric error over the measured envelope X %.1f..%.1f Y %.1f..%.1f "
          "Z %.1f..%.1f mm: max %.3f um at (%.1f, %.1f, %.1f), RMS %.3f um"
          % (tuple(v for r in env for v in r) + (_um(vmap.stats["max_mm"]),)
             + tuple(vmap.stats["max_at_mm"]) + (_um(vmap.stats["rms_mm"]),)), file=out)
    st = stats
    print("", file=out)
    print("Program:      %s (%d lines, %d moves)" % (args.program, st["lines_in"], st["moves"]),
          file=out)
    print("Output:       %d lines changed, %d added; %d G1 moves split, %d arcs turned into G1 "
          "segments; largest correction %.3f um" % (st["lines_changed"], st["lines_added"],
                                                    st["moves_split"], st["arcs_converted"],
                                                    _um(pred["max_correction_mm"])), file=out)
    b, a = pred["before"], pred["after"]
    print("Predicted positional error at the program's %d points (model, |E|):" % b["n"],
          file=out)
    print("  before compensation: max %.3f um, mean %.3f um, RMS %.3f um"
          % (_um(b["max_mm"]), _um(b["mean_mm"]), _um(b["rms_mm"])), file=out)
    print("  after compensation:  max %.4f um, mean %.4f um, RMS %.4f um (output rounding)"
          % (_um(a["max_mm"]), _um(a["mean_mm"]), _um(a["rms_mm"])), file=out)
    if model.fits:
        worst = max(model.fits, key=lambda f: f.rms)
        print("  these figures are the error model's own: on the machine the compensation is "
              "as good as the model, whose error functions fit the measurements within RMS "
              "%.3f um (worst: %s) and know nothing beyond the measured travel"
              % (_um(worst.rms), worst.name), file=out)
    if pred["points_unknown_axes"]:
        print("  (%d point(s) with an axis the program had not set are not counted)"
              % pred["points_unknown_axes"], file=out)
    for w in warnings:
        print("warning: " + w, file=sys.stderr)


def build_report(args, table, model, prog_model, stats, pred, vmap, warnings, outputs, seg, tol,
                 arc_tol, reference, offset, start):
    """The JSON report of ``gcode`` (schema ``surfcomp-gcode-report/1``)."""
    return {
        "schema": SCHEMA,
        "surfcomp_version": __version__,
        "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "command": "gcode",
        "units": "mm",
        "inputs": {
            "program": {"path": os.path.abspath(args.program),
                        "sha256": sha256_file(args.program), "lines": stats["lines_in"]},
            "axis_errors": {"path": os.path.abspath(args.axis_errors),
                            "sha256": sha256_file(args.axis_errors), "layout": table.layout,
                            "rows": table.rows(), "units_without_suffix": args.units},
        },
        "options": {"model": args.model, "segment_length_mm": seg, "tolerance_mm": tol,
                    "arc_tolerance_mm": arc_tol, "max_error_mm": args.max_error,
                    "decimals": args.decimals,
                    "reference_mm": reference.tolist(),
                    "work_offset_mm": None if offset is None else offset.tolist(),
                    "start_mm": None if start is None else start.tolist()},
        "model": {**model.to_dict(), "components": model.components(),
                  "fits": [dict(f.as_dict(), lines=_fit_lines(table, f)) for f in model.fits],
                  "offset_spread_mm": model.offset_spread.tolist(),
                  "sign": "error = actual - commanded; command X' solves X' + E(X') = X",
                  "program_coordinates": prog_model.to_dict()},
        "volumetric_map": vmap.as_dict(include_grid=True),
        "program": stats,
        "predicted": pred,
        "warnings": list(warnings),
        "outputs": outputs,
    }


def _fit_lines(table, fit):
    """The file lines of the rows a fit used (a table that leaves its column out: none)."""
    measured = ~np.isnan(table.data[fit.axis][1][:, "xyz".index(fit.component)])
    return table.lines[fit.axis][measured].tolist()
