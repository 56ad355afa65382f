# SPDX-License-Identifier: LGPL-2.1-or-later
"""The option registry's tables of the commands that have no document object: the
simulation loop (``simulate``), the machine-axis error file (``simulate --axis-errors``,
``gcode``), ``gcode`` and the finishing program moved by ``compensate --program``;
importable without numpy.

Records of the same type as the compensation's (:class:`surfcomp.core.options.Option`),
listed in :data:`surfcomp.core.option_tables.TABLES` (``find`` looks them up there). Who
reads them:

- :data:`SIMULATE`: ``simulate``'s loop (:mod:`surfcomp.cli.simulate`: the parser, its
  checks and the values without a preset) and
  :data:`~surfcomp.core.simulation.process_model.DEFAULT_STOCK`; the options in
  :data:`PRESET_SET` are the preset's where not given, so the parser leaves them unset;
- :data:`AXIS_FILE`: how the axis error file is read, for ``simulate`` and ``gcode`` (whose
  flag of the units is ``--units``);
- :data:`GCODE`: ``gcode``'s options (:mod:`surfcomp.cli.gcode`), the axis file's among them;
- :data:`PROGRAM_MOVE`: ``compensate --program``'s (:mod:`surfcomp.cli.program`) and
  :class:`~surfcomp.app.program_route.ProgramJob`'s defaults;
- :data:`COMPENSATE`: ``compensate``'s region options (:mod:`surfcomp.cli.compensate`, the
  region object's properties in :mod:`surfcomp.app.region_doc`) and its post-processing.
"""

from dataclasses import replace

from .choices import AXIS_MODELS, METHODS, UNITS
from .limits import (
    FIELD_SHARE,
    FIELD_SPACINGS,
    MAX_GRID,
    MAX_REPLICAS,
    MAX_SEGMENTS,
    MIN_SEGMENT_LENGTH,
)
from .options import Option


def _table(*options):
    return {o.name: o for o in options}


#: the virtual machining loop of ``simulate`` (lengths in mm)
SIMULATE = _table(
    Option("grid", str, "45x45", None, flag="--grid", metavar="NxM",
           note="Werner 2022, or the preset's",
           help="measurement grid, uniform in the face parameters, at most %d x %d"
                % (MAX_GRID, MAX_GRID)),
    # (the one domain open at its top: a margin of 0.5 leaves nothing to measure)
    Option("margin", float, 0.02, None, flag="--margin", metavar="FRACTION", low=0.0,
           high=0.5, what="a fraction >= 0 and < 0.5",
           help="parameter range left free at each border"),
    Option("between", int, 2, None, flag="--between", metavar="K", low=1,
           note="or the preset's",
           help="the corrected parts are measured on a grid K times denser: its nodes and "
                "the points between them"),
    Option("replicas", int, 4, None, flag="--replicas", metavar="N", low=1,
           high=MAX_REPLICAS, note="as the mirror paper, or the preset's",
           help="parts machined per method, at most %d" % MAX_REPLICAS),
    Option("methods", str, "none,offset,raw,filtered,mirror", None, flag="--methods",
           metavar="LIST",
           help="comma-separated methods: %s" % ", ".join(("none",) + METHODS)),
    Option("stock", float, 0.3, None, flag="--stock", metavar="MM", low=0.0,
           note="or the preset's",
           help="allowance in mm the semi-finishing pass leaves, and the mirror method's "
                "stock"),
    Option("seed", int, 0, None, flag="--seed", metavar="N", low=0, help="random seed"),
)

#: the options of :data:`SIMULATE` a preset sets (the parser's default is None: not given)
PRESET_SET = ("grid", "between", "replicas", "stock")

#: the machine-axis error file (``simulate --axis-errors``, ``gcode --axis-errors``)
AXIS_FILE = _table(
    Option("axis_units", str, "mm", None, flag="--axis-units", choices=UNITS,
           help="units of the axis error file without unit suffixes"),
    Option("max_error", float, 1.0, None, flag="--max-error", metavar="MM",
           note="as for gcode",
           help="largest plausible error in mm in the axis error file: a larger one is "
                "refused as a likely unit mistake"),
    Option("reference", str, "0,0,0", None, flag="--reference", metavar="X,Y,Z",
           help="reference point of the axis error measurements"),
)

#: ``gcode``'s options: the axis error file as it names and explains it (the units'
#: flag is ``--units``), the program's segments and tolerances (the defaults of
#: :func:`surfcomp.io.gcode.stream.compensate_gcode`)
GCODE = _table(
    Option("segment_length", float, 2.0, None, flag="--segment-length", metavar="MM",
           low=MIN_SEGMENT_LENGTH, what="a length in mm",
           help="longest piece in mm of a split G1 move or of an arc turned into G1 "
                "segments, at least %g mm, and at most %d segments in all"
                % (MIN_SEGMENT_LENGTH, MAX_SEGMENTS)),
    Option("model", str, "auto", None, flag="--model", choices=AXIS_MODELS,
           help="degree of every error function, or auto: quadratic where the F-test of the "
                "quadratic term is significant at alpha = 0.05"),
    replace(AXIS_FILE["axis_units"], name="units", flag="--units",
            help="units of error-file columns without a unit suffix"),
    replace(AXIS_FILE["max_error"], note=None,
            help="largest plausible machine error in mm: a larger value in the error file, "
                 "or a larger predicted error at a programmed point, is refused as a likely "
                 "unit mistake"),
    replace(AXIS_FILE["reference"],
            help="where the other slides stood while one slide was measured, in mm in "
                 "error-file coordinates"),
    Option("work_offset", str, None, None, flag="--work-offset", metavar="X,Y,Z",
           unset="the same coordinates",
           help="error-file (machine) coordinates in mm of the program zero, when they "
                "differ"),
    Option("start", str, None, None, flag="--start", metavar="X,Y,Z",
           unset="unknown: an axis is not written before the program sets it",
           help="machine position in mm at the program start, in program coordinates"),
    Option("tolerance", float, 1e-4, None, flag="--tolerance", metavar="MM", note="> 0",
           help="split a long G1 move only where the compensated path leaves its chord by "
                "more than this many mm"),
    Option("arc_tolerance", float, 1e-3, None, flag="--arc-tolerance", metavar="MM",
           note="> 0", help="largest chord-to-arc deviation in mm of converted arcs"),
    Option("decimals", int, None, None, flag="--decimals", metavar="N", low=0, high=9,
           what="a whole number", unset="4 in mm, 5 in inch", note="0 to 9",
           help="least decimals of rewritten numbers"),
)

#: ``compensate --program``'s options: the ball-end finishing program moved by the
#: correction (:class:`surfcomp.app.program_route.ProgramJob`'s defaults)
PROGRAM_MOVE = _table(
    Option("tool", str, None, None, flag="--tool", metavar="ball:R",
           help="the program's cutter: ball:R, a ball end mill of radius R mm (the program "
                "gives the tip, the ball's lowest point)"),
    Option("tolerance", float, 5e-4, None, flag="--tolerance", metavar="MM",
           help="largest distance in mm of the moved program from the exactly moved path: "
                "long moves are split until they stay within it"),
    Option("blend", float, 1.0, None, flag="--blend", metavar="MM", note="> 0",
           help="beyond the face (its edge plus the ball radius, or above it) the correction "
                "fades out over this clearance in mm"),
    replace(GCODE["segment_length"],
            help="long moves are first sampled at this spacing in mm, so that nothing near "
                 "the face between their ends is missed"),
    Option("decimals", int, None, None, flag="--decimals", metavar="N", unset="4", low=3,
           high=9, what="a whole number", note="3 to 9",
           help="least decimals of rewritten numbers"),
)

#: ``compensate``'s region of faces (the region object's Faces and MinCoverage) and the
#: post-processing of its document route
COMPENSATE = _table(
    Option("faces", str, None, "Faces", label="Faces", flag="--faces", metavar="F1,F2|auto",
           stored="auto",
           help="compensate a region of several faces at once, continuity kept (FaceN names, "
                "or auto: the faces the measurements cover); {smoothing} is then the radius "
                "in mm of the correction field (default the larger of %g point spacings and "
                "%g x the shape's diagonal), not a fit chosen by cross-validation "
                "(docs/regions.md)" % (FIELD_SPACINGS, FIELD_SHARE),
           doc_help="the region: FaceN names separated by commas, or auto (the faces the "
                    "measurements cover)"),
    Option("min_coverage", float, 0.5, "MinCoverage", label="Min coverage",
           flag="--min-coverage", metavar="SHARE", low=0.0, high=1.0, what="a share",
           help="with {faces}: least share of every face's area with measured points near",
           doc_help="least share of every face's area with measured points near"),
    Option("post", str, "linuxcnc", None, flag="--post", metavar="NAME",
           help="Path post-processor for --gcode"),
    Option("post_args", str, "--no-show-editor", None, flag="--post-args", metavar="ARGS",
           help="argument string for the post-processor"),
    Option("job", str, None, None, flag="--job", metavar="NAME",
           help="which Job to post when several use the face"),
)
