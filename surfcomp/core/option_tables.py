# SPDX-License-Identifier: LGPL-2.1-or-later
"""The option registry's other tables: the job's inputs, the alignment, the measurement
plan, its probing program and the simulation's machining model (importable without numpy).

Each option is an :class:`surfcomp.core.options.Option`, as the compensation's are
(:data:`surfcomp.core.options.OPTIONS`): its name (the job file's key, the dataclass field
and the name messages below the command line use), type, default, domain, command-line
flag, document property, GUI label and help. Who reads them:

- :data:`INPUTS` and :data:`ALIGN`: the command line's job commands
  (:mod:`surfcomp.cli.common`, :mod:`surfcomp.cli.registry`), the job file's value checks
  (:mod:`surfcomp.io.jobfile`), the measurement object's Align* properties
  (:mod:`surfcomp.app.properties`) and the Align measurements panel;
- :data:`PLAN`: ``plan`` (:mod:`surfcomp.cli.plan`), :class:`PlanSettings
  <surfcomp.core.measurement.planning.PlanSettings>`' defaults, the plan object's properties
  (:mod:`surfcomp.app.plan_feature`) and the Plan measurement panel;
- :data:`PROGRAM`: ``plan --program`` (:mod:`surfcomp.cli.plan_program`),
  :class:`ProbeSettings <surfcomp.io.probe_path.ProbeSettings>`' defaults and the probe
  operation's properties (:mod:`surfcomp.app.probe_op`);
- :data:`MODEL`: ``simulate``'s model options (:mod:`surfcomp.cli.simulate`) and
  :class:`MachiningModel <surfcomp.core.simulation.process_model.MachiningModel>`' defaults;
- :data:`SIM_PLAN`: ``simulate``'s plan options (:mod:`surfcomp.cli.simulate_plan`), the
  plan's layout, count and points under ``simulate``'s own attributes;
- the loop of ``simulate`` and the axis error file: the tables of
  :mod:`surfcomp.core.command_options`.

:func:`find` looks a name up in every table (the compensation's first): the command line
shows it as the flag (:mod:`surfcomp.cli.option_flags`), the GUI as the label
(:mod:`surfcomp.gui.option_labels`).
"""

from dataclasses import replace

from .choices import (
    ALIGN_METHODS,
    MEASUREMENT_FORMATS,
    PLAN_FORMATS,
    PLAN_LAYOUTS,
    PLAN_ORDERS,
    PROBE_DIALECTS,
    UNITS,
    WORK_OFFSETS,
)
from .command_options import AXIS_FILE, COMPENSATE, GCODE, PROGRAM_MOVE, SIMULATE
from .limits import MAX_PLAN_POINTS, MAX_TOUCHES
from .options import OPTIONS, Option


def _table(*options):
    return {o.name: o for o in options}


#: how a job reads its inputs (``compensate``, ``inspect``, job files)
INPUTS = _table(
    Option("face", str, None, "FaceName", label="Face", flag="--face", metavar="FaceN",
           unset="the only B-spline face", help="the nominal face (FaceN)", stored="Face1"),
    Option("object", str, None, None, flag="--object", metavar="NAME",
           help="object holding the face (FCStd only)"),
    Option("units", str, None, None, label="Coordinates (x, y, z) in", flag="--units",
           choices=UNITS, unset="mm",
           help="units of values that carry no unit of their own (column suffix, XYZIJK "
                "METRIC, QIF FileUnits)"),
    Option("deviation_units", str, None, None, label="Deviation column in",
           flag="--deviation-units", choices=UNITS,
           unset="the same as {units}",
           help="unit of a deviation column without a unit of its own, when it is not the "
                "coordinates' ({units}): a CMM report in mm with deviations in um"),
    Option("fmt", str, "auto", None, flag="--format", dest="fmt", choices=MEASUREMENT_FORMATS,
           note="detected from the content", help="measurement file format"),
    Option("sample", str, None, None, flag="--sample", metavar="N|ID", unset="the first",
           help="which measured part of a QIF file holding several: 0-based index, serial "
                "number or MeasurementResults id"),
    Option("touches", int, 1, None, flag="--touches", metavar="K", low=1,
           high=MAX_TOUCHES, what="a whole number", note="1 to %d" % MAX_TOUCHES,
           help="with --plan: probe moves per point in the log (2 for a LinuxCNC program "
                "written with {second_touch}; the last one of each point is used)"),
)

#: how the measured points are aligned to the nominal (the measurement object's properties)
ALIGN = _table(
    Option("align", str, "none", "AlignMethod", label="Method", flag="--align",
           choices=ALIGN_METHODS,
           help="align the measured points to the nominal before the deviations: none (they "
                "are in the nominal's frame), bestfit (robust least squares on the exact "
                "distance to the reference faces) or rps (3-2-1 on the points of {rps}); "
                "README 'Alignment'"),
    Option("align_faces", str, None, "AlignFaces", label="Reference faces",
           flag="--align-faces", metavar="F1,F2",
           unset="the compensated face, which absorbs the error's mean and tilt (reported)",
           help="reference faces of the nominal shape for the alignment (datum faces), e.g. "
                "Face1,Face3"),
    Option("align_dof", str, None, "AlignDof", label="Degrees of freedom (best fit)",
           flag="--align-dof", metavar="DOF", unset="all", stored="all",
           help="degrees of freedom the best fit may move: all or a combination of x y z rx "
                "ry rz, e.g. xyz, z, rz, xy,rz"),
    Option("rps", str, None, "AlignRps", label="3-2-1 point ids", flag="--rps",
           metavar="FILE|IDS",
           help="3-2-1 point ids for {align} rps: a JSON file {{\"primary\": [3 ids], "
                "\"secondary\": [2], \"tertiary\": [1]}} or inline P1,P2,P3;P4,P5;P6",
           doc_help="3-2-1 point ids: P1,P2,P3;P4,P5;P6 (the file's ids, or 1-based point "
                    "numbers)"),
    Option("transform", str, None, "AlignTransform", label="Known transform",
           flag="--transform", metavar="FILE",
           help="known rigid transform applied to the measured points before anything "
                "else: a 4x4 matrix (text or JSON {{\"matrix\": ...}}) or a work offset "
                "(JSON {{\"translation\": [x,y,z], \"rotation_z_deg\": a}}); see README "
                "'Alignment'",
           doc_help="known rigid transform applied first: 16 numbers, the 4x4 matrix "
                    "row-major, measured -> nominal (empty: none)"),
)

#: the measurement plan (``plan``, the plan object)
PLAN = _table(
    Option("layout", str, "grid", "Layout", label="Layout", flag="--layout",
           choices=PLAN_LAYOUTS,
           help="grid: U x V along the parameter lines; xy: U x V in the machine's XY plane "
                "clipped to the face; adaptive: {points} N, denser where the slope changes "
                "fast; uniform: {points} N spread evenly"),
    Option("count", str, None, "Count", label="Points along u and v", flag="--count",
           metavar="UxV", unset="10x10", stored="10x10",
           help="grid and xy: points along u (x) and v (y), at most %d in all"
                % MAX_PLAN_POINTS),
    Option("points", int, None, "Points", label="Points", flag="--points", metavar="N",
           low=1, high=MAX_PLAN_POINTS, what="a whole number of points", unset="100",
           stored=100, help="adaptive and uniform: number of points"),
    Option("tip_radius", float, 1.0, "TipRadius", label="Tip radius", flag="--tip-radius",
           metavar="MM", help="stylus ball radius (mm)"),
    Option("edge_margin", float, 0.5, "EdgeMargin", label="Edge margin", flag="--edge-margin",
           metavar="MM",
           help="distance kept from the boundary and holes beyond the tip radius (mm)"),
    Option("max_tilt", float, 60.0, "MaxTilt", label="Max tilt", flag="--max-tilt",
           metavar="DEG", low=0.0, high=90.0, what="an angle in degrees",
           help="largest angle between the outward normal and the spindle axis +Z (degrees)"),
    Option("stand_off", float, 2.0, "StandOff", label="Stand-off", flag="--stand-off",
           metavar="MM",
           help="distance along the normal from which the probe starts its touch (mm)"),
    Option("clearance", float, 5.0, "Clearance", label="Clearance", flag="--clearance",
           metavar="MM",
           help="least distance (mm) the stylus ball keeps from the part on rapid moves: "
                "above the part's top at the safe height, and on the way down to the point"),
    Option("order", str, "auto", None, flag="--order", choices=PLAN_ORDERS,
           help="visiting order: serpentine rows, nearest neighbour, or auto (the shorter)"),
    Option("plan_format", str, "csv", None, flag="--format", dest="plan_format",
           choices=PLAN_FORMATS,
           help="csv: the measurement-file contract; xyzijk: PC-DMIS nominal points"),
)

#: the probing program of a plan (``plan --program``, the probe operation)
PROGRAM = _table(
    Option("dialect", str, "linuxcnc", None, flag="--dialect", choices=PROBE_DIALECTS,
           help="linuxcnc: G38.2 and a PROBEOPEN log; fanuc: G31 and macro B, #5061-#5063 "
                "written by DPRNT"),
    Option("tool", int, 99, None, flag="--tool", metavar="N",
           help="the probe's tool number"),
    Option("work_offset", str, "G54", "WorkOffset", label="Work offset", flag="--work-offset",
           choices=WORK_OFFSETS, help="the work offset the part was machined in"),
    Option("overtravel", float, 1.0, "Overtravel", label="Overtravel", flag="--overtravel",
           metavar="MM", help="how far past the nominal contact the probe move may go (mm)"),
    Option("feed", float, 1000.0, "Feed", label="Feed", flag="--feed", metavar="MM/MIN",
           help="fast approach and retract feed (mm/min)"),
    Option("touch_feed", float, 100.0, "TouchFeed", label="Touch feed", flag="--touch-feed",
           metavar="MM/MIN", help="probing feed (mm/min)"),
    Option("second_touch", bool, False, None, flag="--second-touch",
           help="back off and touch again slower (a LinuxCNC log then holds two lines per "
                "point: read it back with {touches} 2)"),
    Option("second_feed", float, None, None, flag="--second-feed", metavar="MM/MIN",
           unset="a fifth of {touch_feed}",
           help="feed of the second touch (mm/min; with {second_touch} only)"),
    Option("backoff", float, None, None, flag="--backoff", metavar="MM", unset="1",
           stored=1.0,
           help="back-off before the second touch (mm; with {second_touch} only)"),
    Option("log_file", str, None, "LogFile", label="Log file", flag="--probe-log",
           metavar="NAME", dest="probe_log", unset="probe.log", stored="probe.log",
           help="file LinuxCNC writes the probe log to (PROBEOPEN; linuxcnc dialect only)"),
)


def _model(name, default, metavar, text, low=None):
    return Option(name, tuple if isinstance(default, tuple) else float, default, None,
                  flag="--" + name.replace("_", "-"), metavar=metavar, low=low, help=text)


#: the simulation's machining-process model (``simulate``; lengths in mm): a tuple default
#: takes as many comma-separated numbers, ``low`` 0 refuses negative values
MODEL = _table(
    _model("offset", 0.0, "MM", "constant error (tool radius/wear)"),
    _model("slope_gain", 0.06, "MM", "error per unit slope along the feed (signed)"),
    _model("abs_slope_gain", 0.03, "MM", "error per unit |slope| along the feed"),
    _model("tilt", (0.0, 0.02), "F,C",
           "linear error at the work-area border along,across the feed"),
    _model("bow", (-0.02, 0.02), "F,C",
           "quadratic error at the border along,across the feed"),
    _model("deflection", (0.0, 0.0, 0.0), "K0,KS,KA",
           "deflection per mm of engagement: constant, per unit slope, per unit |slope| "
           "(mm/mm)"),
    _model("waviness", 0.0, "MM", "amplitude of a periodic error along the feed"),
    _model("wavelength", 10.0, "MM", "wavelength of the waviness", low=0.0),
    _model("feed", (1.0, 0.0, 0.0), "X,Y,Z", "feed direction"),
    _model("tool_axis", (0.0, 0.0, 1.0), "X,Y,Z", "tool axis"),
    _model("sigma", 0.0015, "MM", "random machining error of every pass, standard deviation",
           low=0.0),
    _model("correlation_length", 0.0, "MM",
           "correlation length of the random part (0: independent)", low=0.0),
    _model("probe_sigma", 0.0005, "MM", "measurement noise, standard deviation", low=0.0),
    _model("semi_engagement", None, "MM", "depth the semi-finishing pass removes", low=0.0),
)

#: ``simulate``'s measurement plan: :data:`PLAN`'s layout, count and points (unset: the
#: grid nodes; attributes ``plan_layout`` ... beside the compensation's ``layout``) and
#: the comparison of layouts
SIM_PLAN = _table(
    replace(PLAN["layout"], default=None, dest="plan_layout",
            help="measure at points planned on the face: grid or xy ({count} UxV), "
                 "adaptive or uniform ({points} N)"),
    replace(PLAN["count"], dest="plan_count", unset=None,
            help="grid and xy layouts: points along u (x) and v (y)"),
    replace(PLAN["points"], dest="plan_points", unset=None,
            help="adaptive and uniform layouts: number of points"),
    Option("compare_layouts", int, None, None, flag="--compare-layouts", metavar="N", low=1,
           high=MAX_PLAN_POINTS, what="a whole number of points",
           help="run the loop at N uniform and N adaptive points and say which predicts the "
                "lower residual after compensation (mirror paper 2.3)"),
)

#: every table by its name (the compensation's first)
TABLES = {"compensation": OPTIONS, "inputs": INPUTS, "align": ALIGN, "plan": PLAN,
          "program": PROGRAM, "model": MODEL, "simulate": SIMULATE, "sim_plan": SIM_PLAN,
          "axis_file": AXIS_FILE, "gcode": GCODE, "program_move": PROGRAM_MOVE,
          "compensate": COMPENSATE}


def find(name, tables=None):
    """The :class:`~surfcomp.core.options.Option` called ``name`` in ``tables`` (names of
    :data:`TABLES`; default every table, the compensation's first), or None."""
    for key in tables or TABLES:
        if name in TABLES[key]:
            return TABLES[key][name]
    return None
