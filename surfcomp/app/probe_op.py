# SPDX-License-Identifier: LGPL-2.1-or-later
"""The measurement plan as an operation of a CAM Job, so the Job's post-processor writes it.

``SurfComp_ProbeOperation`` (``Path::FeaturePython``) links a measurement plan
(:mod:`surfcomp.app.plan_feature`) and a probe tool controller; ``execute`` turns the
plan's points into the moves of :func:`surfcomp.io.probe_path.probe_path` (the moves the
``plan --program`` LinuxCNC program makes: one source of moves) and writes them to ``Path``:

- the work offset (``G54`` .. ``G59``) and the safe height;
- ``(PROBEOPEN file)`` ... ``(PROBECLOSE)`` as comments, which LinuxCNC's post-processor
  passes through (a post run with ``--no-comments`` drops them: :func:`post_probe_job`
  refuses such a program);
- per point the traverse to above the retract point, down to it, the fast approach to the
  stand-off, ``G38.2`` along the -normal to the overtravel past the nominal contact, the
  retract and the traverse up.

The tool change to the probe comes from the operation's tool controller, as for every CAM
operation (the post writes ``M6 T..`` and ``G43 H..``); its spindle stays off. Positions
are stylus tip centres (the probe's tool length set to the ball centre). One touch per
point: the second touch of ``plan --program`` backs off from ``#5061``-``#5063``, which a
CAM command cannot hold.

The operation depends on the plan through its link, so it recomputes when the plan does.
A plan without points, or one that cannot be probed, or a tool controller that is not the
plan's probe (spindle on, another ball), fails the recompute with the reason and leaves an
empty ``Path`` (never the moves of an older plan). :func:`post_probe_job` also refuses a
Job that machines in another work offset or several, an inch post and two operations
logging to one file. No FreeCADGui.
"""

import os

import Path

from ..core.option_tables import PROGRAM
from ..errors import GCodeError, InputError
from ..io.probe_path import WORK_OFFSETS, ProbeSettings, probe_path, travel_summary
from . import cam, cam_job, progress
from .features import _created, _restored
from .properties import option_row
from .proxies import Proxy

PROBE_OP_TYPE = "SurfComp_ProbeOperation"
PROBE_OP_VERSION = 1
#: the probe's tool bit shipped with every CAM version
PROBE_BIT = "probe.fctb"
_DEF = ProbeSettings()
_RO = 1
#: (type, name, group, tooltip, default, editor mode)
PROBE_OP_PROPERTIES = (
    ("App::PropertyInteger", "Version", "Base", "surfcomp object version", PROBE_OP_VERSION,
     1),
    ("App::PropertyBool", "Active", "Path", "post this operation", True, 0),
    ("App::PropertyLink", "ToolController", "Path", "the probe's tool controller", None, 0),
    ("App::PropertyLink", "Plan", "Probe", "the measurement plan to probe", None, 0),
    # the program's settings: the option registry's PROGRAM table
    option_row("App::PropertyEnumeration", "work_offset", "Probe", PROGRAM),
    *(option_row("App::PropertyFloat", name, "Probe", PROGRAM)
      for name in ("overtravel", "feed", "touch_feed")),
    option_row("App::PropertyString", "log_file", "Probe", PROGRAM),
    ("App::PropertyInteger", "Probes", "Result", "G38.2 probe moves in the Path", 0, _RO),
    ("App::PropertyFloat", "SafeHeight", "Result", "tip-centre Z of the traverses (mm)", 0.0,
     _RO),
    ("App::PropertyFloat", "Travel", "Result", "length of the tip centre's path (mm)", 0.0,
     _RO),
)


class ProbeOperation(Proxy):
    """Proxy of ``SurfComp_ProbeOperation`` (module docstring)."""

    Type = PROBE_OP_TYPE
    PROPERTIES = PROBE_OP_PROPERTIES
    VERSION = PROBE_OP_VERSION

    def onDocumentRestored(self, obj):
        super().onDocumentRestored(obj)
        _restored(obj)

    def execute(self, obj):
        compute_probe_operation(obj)


def is_probe_operation(obj):
    return getattr(getattr(obj, "Proxy", None), "Type", None) == PROBE_OP_TYPE


def probe_operations(job, active=True):
    """The probe operations of ``job`` (``active``: only those that are posted)."""
    return [o for o in cam_job.operations_of(job)
            if is_probe_operation(o) and (not active or getattr(o, "Active", True))]


def settings_of(op):
    """The :class:`ProbeSettings` of an operation and its plan (tip radius, clearance and
    stand-off are the plan's; the part's top is the plan's safe height less both)."""
    plan = op.Plan
    tc = op.ToolController
    return ProbeSettings(
        dialect="linuxcnc", tip_radius=float(plan.TipRadius),
        tool=int(tc.ToolNumber) if tc is not None else _DEF.tool,
        work_offset=op.WorkOffset,
        safe_z=float(plan.SafeZ) - float(plan.TipRadius) - float(plan.Clearance),
        clearance=float(plan.Clearance), stand_off=float(plan.StandOff),
        overtravel=float(op.Overtravel), feed=float(op.Feed), touch_feed=float(op.TouchFeed),
        log_file=op.LogFile)


def probe_moves(op):
    """The :class:`~surfcomp.io.probe_path.ProbePath` of an operation's plan.

    Raises
    ------
    InputError
        No plan, a plan without points, or settings or points that cannot be probed.
    """
    plan = op.Plan
    if plan is None:
        raise InputError("probe operation %s has no measurement plan (Plan)" % op.Label)
    check_probe_tool(op.ToolController, plan)
    if not len(plan.PlanPoints):
        raise InputError("measurement plan %s holds no point to probe (%d placed, %s)"
                         % (plan.Label, plan.Placed, "; ".join(plan.Dropped) or "none kept"))
    return probe_path(list(plan.PointIds), [tuple(p) for p in plan.PlanPoints],
                      [tuple(n) for n in plan.PlanNormals], settings_of(op))


def check_probe_tool(tc, plan):
    """Refuse a tool controller that is not the plan's probe: one that turns the spindle
    (the post would probe with it running) or whose tool is not the plan's ball (the
    program's tip centres are the plan's tip radius out along the normal)."""
    if tc is None:
        return
    if str(tc.SpindleDir) != "None" and float(tc.SpindleSpeed) > 0.0:
        raise InputError("tool controller %s turns the spindle (%s, %g rpm): the probe "
                         "moves would run with it turning (expected a probe's tool "
                         "controller, SpindleDir None)"
                         % (tc.Label, tc.SpindleDir, float(tc.SpindleSpeed)))
    want = 2.0 * float(plan.TipRadius)
    have = getattr(getattr(tc, "Tool", None), "Diameter", None)
    if have is not None and abs(float(have) - want) > 1e-6:
        raise InputError("tool controller %s's tool is %g mm across, but measurement plan %s "
                         "has TipRadius %g mm (expected a %g mm ball: the program's "
                         "positions are the tip centres of that ball)"
                         % (tc.Label, float(have), plan.Label, float(plan.TipRadius), want))


def path_commands(path, settings, label):
    """The CAM commands of a :class:`ProbePath` (feeds in mm/s, the CAM unit)."""
    C, V = Path.Command, _xyz
    feed, touch = settings.feed / 60.0, settings.touch_feed / 60.0
    out = [C("(surfcomp probe plan %s: %d points, tip radius %.4f mm, tip centres)"
             % (_safe(label), len(path.ids), settings.tip_radius)),
           C(settings.work_offset), C("G0", {"Z": path.safe}),
           C("(PROBEOPEN %s)" % settings.log_name())]
    for k, pid in enumerate(path.ids):
        r = path.retract[k]
        out += [C("(point %d %s)" % (k + 1, _safe(pid))),
                C("G0", {"X": float(r[0]), "Y": float(r[1])}), C("G0", {"Z": float(r[2])})]
        if path.approach:
            out.append(C("G1", dict(V(path.standoff[k]), F=feed)))
        out += [C("G38.2", dict(V(path.end[k]), F=touch)), C("G1", dict(V(r), F=feed)),
                C("G0", {"Z": path.safe})]
    out.append(C("(PROBECLOSE)"))
    return out


def _xyz(p):
    return {"X": float(p[0]), "Y": float(p[1]), "Z": float(p[2])}


def _safe(text):
    return str(text).replace("(", "[").replace(")", "]")


def compute_probe_operation(obj):
    """Write the probing moves of the linked plan to ``obj.Path`` (module docstring)."""
    obj.Path = Path.Path()
    obj.Probes = 0
    obj.Travel = 0.0
    check_in_job(obj)
    moves = probe_moves(obj)
    s = settings_of(obj)
    obj.Path = Path.Path(path_commands(moves, s, obj.Plan.Label))
    obj.Probes = len(moves.ids)
    obj.SafeHeight = float(moves.safe)
    obj.Travel = travel_summary(moves)["total"]
    return moves


def probe_tool_controller(job, tool, tip_radius):
    """The job's tool controller of tool number ``tool``, or a new one with the probe bit
    (ball diameter ``2 * tip_radius``, spindle off). A tool controller found by its number
    is the caller's to check (:func:`check_probe_tool`)."""
    for tc in job.Tools.Group:
        if int(tc.ToolNumber) == int(tool):
            return tc
    bit = cam.create_tool_bit(job.Document, PROBE_BIT, "Probe")
    bit.Diameter = 2.0 * float(tip_radius)
    bit.Label = "Probe %g mm" % (2.0 * float(tip_radius))
    bit.Visibility = False          # as CAM keeps its tool bits: not drawn at the origin
    tc = cam.create_tool_controller("TC: Probe", bit, int(tool))
    tc.Label = "TC: Probe T%d" % int(tool)
    tc.SpindleSpeed = 0.0
    tc.SpindleDir = "None"
    job.Proxy.addToolController(tc)
    return tc


def add_probe_operation(job, plan, tool=_DEF.tool, name="ProbePlan", check=True, **values):
    """Add the probing of ``plan`` to ``job`` as an operation and recompute.

    ``values``: property values (``WorkOffset``, ``Overtravel``, ``Feed``, ``TouchFeed``,
    ``LogFile``). The work offset defaults to the Job's first fixture. ``check=False``
    leaves :func:`check_recomputed` to the caller (the GUI's undo step).

    Raises
    ------
    InputError
        ``tool`` out of range or the recompute failed (the reason, e.g. a plan without
        points); the operation then stays in the Job, marked in error.
    """
    ProbeSettings(tool=tool, safe_z=0.0).validate()
    doc = job.Document
    tc = probe_tool_controller(job, tool, plan.TipRadius)
    check_probe_tool(tc, plan)
    op = doc.addObject("Path::FeaturePython", name)
    ProbeOperation(op)
    op.ToolController = tc
    op.Plan = plan
    fixtures = [f for f in job.Fixtures if f in WORK_OFFSETS]
    if fixtures:
        op.WorkOffset = fixtures[0]
    for key, val in values.items():
        setattr(op, key, val)
    if "LogFile" not in values:
        op.LogFile = _free_log_name(job, op)
    cam.add_operation(job, op)
    _created(op)
    recompute_probing(op)
    if check:
        check_recomputed(op)
    return op


def _free_log_name(job, op):
    """``op``'s LogFile, or, where another probe operation of ``job`` logs to it already,
    the same name with ``op``'s name added (``probe-ProbeTwo.log``): each PROBEOPEN opens
    its file anew, so two operations must not share one (:func:`check_job`)."""
    taken = {o.LogFile for o in probe_operations(job, active=False)}
    if op.LogFile not in taken:
        return op.LogFile
    stem, ext = os.path.splitext(op.LogFile)
    return "%s-%s%s" % (stem, op.Name, ext or ".log")


def recompute_probing(op):
    """Recompute the plan and the tool controller (when they need it) and the operation, in
    this order, and nothing else: a document whose unrelated objects fail to recompute
    (FreeCAD 1.1 then leaves the objects after the failure touched) still gets the
    operation's moves."""
    mine = [o for o in (op.Plan, op.ToolController) if o is not None]
    for obj in progress.pending(op.Document):
        if any(obj is o for o in mine):
            progress.recompute_one(obj)
    progress.recompute_one(op)


def check_recomputed(op):
    """Raise InputError with the reason when ``op``, its plan or an object the plan depends
    on (its nominal) failed to recompute or is out of date (its moves would be those of an
    older plan), or when its tool controller is not the plan's probe
    (:func:`check_probe_tool`)."""
    if op.Plan is None:
        raise InputError("probe operation %s has no measurement plan (Plan)" % op.Label)
    for obj in (op.Plan, op):
        if "Invalid" in obj.State or "Error" in obj.State:
            raise InputError("%s did not recompute: %s" % (obj.Label, progress.state_text(obj)))
    for obj in (op.Plan, op, *op.Plan.OutListRecursive):
        if not {"Touched", "Invalid", "Error"}.isdisjoint(obj.State):
            what = "" if obj in (op.Plan, op) else ", the input of %s," % op.Plan.Label
            raise InputError("%s%s is out of date: recompute the document before posting "
                             "(the probe moves of %s would be those of an older plan)"
                             % (obj.Label, what, op.Label))
    check_probe_tool(op.ToolController, op.Plan)
    if op.Probes != len(op.Plan.PlanPoints):
        raise InputError("%s holds %d probe moves for %d plan points"
                         % (op.Label, op.Probes, len(op.Plan.PlanPoints)))


def check_job(job, ops):
    """Refuse probe operations ``ops`` of ``job`` that would probe in another work offset
    than the Job machines in, or whose logs would overwrite each other: LinuxCNC opens the
    ``PROBEOPEN`` file anew (truncated) each time."""
    fixtures = list(job.Fixtures)
    for op in ops:
        if fixtures != [op.WorkOffset]:
            raise InputError(
                "%s probes in %s (its WorkOffset) but Job %s machines in %s: the program "
                "would probe %s (expected the Job's one fixture to be %s; the probe log of "
                "several fixtures would be overwritten by each pass)"
                % (op.Label, op.WorkOffset, job.Label, ", ".join(fixtures) or "no fixture",
                   "another part's offset" if len(fixtures) < 2 else
                   "the %s part once per fixture" % op.WorkOffset, op.WorkOffset))
    seen = {}
    for op in ops:
        name = op.LogFile or "probe.log"
        if name in seen:
            raise InputError("%s and %s both log to %s: the second PROBEOPEN would overwrite "
                             "the first plan's log (expected a LogFile of its own for each "
                             "probe operation)" % (seen[name].Label, op.Label, name))
        seen[name] = op


def check_in_job(op):
    """:func:`check_job` of the Job ``op`` is in (its probe operations) and its post
    arguments in mm, on every recompute: FreeCAD's own Post Process posts what the
    operations hold and checks none of it (:func:`post_probe_job` checks again)."""
    job = cam.find_parent_job(op)
    if job is None:
        return
    ops = probe_operations(job)
    check_job(job, ops if op in ops else ops + [op])
    if "--inches" in str(getattr(job, "PostProcessorArgs", "") or "").split():
        raise InputError("Job %s posts in inches (--inches in its PostProcessorArgs): "
                         "LinuxCNC would log %s's trip points in inches, and the log is "
                         "joined to the plan's points in mm (expected a metric post)"
                         % (job.Label, op.Label))


def post_probe_job(job, post="linuxcnc", args="--no-show-editor", native=False):
    """Post ``job`` with its post-processor and check that every active probe operation's
    moves are in the program: ``G38.2`` lines and ``PROBEOPEN``/``PROBECLOSE`` comments, in
    the Job's one fixture, the operation's work offset (:func:`check_job`), in mm. Returns
    the program text. ``native``: through FreeCAD's own Post Process command
    (:func:`surfcomp.app.cam.native_post`) instead of :func:`surfcomp.app.cam_job.post_process`.

    Raises
    ------
    GCodeError
        The post failed, or the program lacks probe moves or log comments (e.g. posted
        with ``--no-comments``: LinuxCNC would probe and log nothing), or is in inches.
    InputError
        An operation or its inputs out of date, or :func:`check_job` refuses the Job.
    """
    ops = probe_operations(job)
    for op in ops:
        check_recomputed(op)
    check_job(job, ops)
    text = cam.native_post(job, post, args) if native else cam_job.post_process(job, post, args)
    words = [ln.split() for ln in text.splitlines()]
    words = [w[1:] if w and w[0].startswith("N") else w for w in words]
    want = {"G38.2": sum(op.Probes for op in ops),
            "(PROBEOPEN": len(ops), "(PROBECLOSE)": len(ops)}
    got = {key: sum(1 for w in words if w and w[0] == key) for key in want}
    if got != want:
        raise GCodeError("post-processor %r (arguments %r) wrote %s where the probe "
                         "operations need %s" % (post, args, _counts(got), _counts(want)))
    if ops and any("G20" in w for w in words):
        raise GCodeError("post-processor %r (arguments %r) wrote an inch program (G20): "
                         "LinuxCNC would log the probe's trip points in inches, and the log "
                         "is joined to the plan's points in mm (expected a metric post, "
                         "without --inches)" % (post, args))
    return text


def _counts(d):
    return ", ".join("%d %s" % (n, k.strip("()")) for k, n in d.items())

